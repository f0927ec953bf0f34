// Parameters whose linear modes the records' channels do not see (credibility.h).
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "mbid/model/linear_model.h"
#include "mbid/updating/credibility.h"

namespace mbid::updating {
namespace {

// A mode whose largest response in every recorded channel is below this fraction of the
// channel's largest modal response is invisible: exact decoupling (symmetry) gives roundoff.
constexpr double kVisible = 1e-6;
// Relative step of a parameter for its modes' derivatives; a parameter moves the visible modes
// when they change by more than this fraction of its largest modal change.
constexpr double kStep = 1e-4;
constexpr double kSeenShare = 1e-3;

// Per mode of `modes`, the largest response over `channels`, each relative to that channel's
// largest modal response; NaN for a channel the linearization does not have.
std::vector<double> Visibility(const model::LinearModel& linear,
                               const std::vector<model::Mode>& modes,
                               const std::set<std::string>& channels) {
  std::vector<double> visibility(modes.size(), 0.0);
  for (const std::string& channel : channels) {
    std::vector<double> response(modes.size(), 0.0);
    const auto output = std::find(linear.outputs.begin(), linear.outputs.end(), channel);
    const auto coordinate =
        std::find(linear.coordinates.begin(), linear.coordinates.end(), channel);
    for (size_t k = 0; k < modes.size(); ++k) {
      if (output != linear.outputs.end()) {
        response[k] = std::abs(modes[k].output_shape[output - linear.outputs.begin()]);
      } else if (coordinate != linear.coordinates.end()) {
        response[k] = std::abs(modes[k].shape[coordinate - linear.coordinates.begin()]);
      }
    }
    const double largest = *std::max_element(response.begin(), response.end());
    if (!(largest > 0)) continue;
    for (size_t k = 0; k < modes.size(); ++k) {
      visibility[k] = std::max(visibility[k], response[k] / largest);
    }
  }
  return visibility;
}

}  // namespace

std::vector<UnseenParameter> FindUnseenParameters(const model::MechanicalModel& model,
                                                  const std::set<std::string>& channels,
                                                  const std::vector<std::string>& parameters) {
  std::vector<UnseenParameter> unseen;
  const model::LinearModel linear = model.Linearize();
  const std::vector<model::Mode> modes = model::CalcModes(linear);
  if (modes.empty()) return unseen;
  const std::vector<double> visibility = Visibility(linear, modes, channels);
  if (std::all_of(visibility.begin(), visibility.end(), [](double v) { return v > kVisible; })) {
    return unseen;  // every mode is seen: nothing to check
  }
  for (const std::string& name : parameters) {
    const double value = model.GetParameter(name);
    if (!std::isfinite(value) || value == 0) continue;
    std::unique_ptr<model::MechanicalModel> moved = model.Clone();
    moved->SetParameter(name, value * (1 + kStep));
    const std::vector<model::Mode> after = model::CalcModes(moved->Linearize());
    if (after.size() != modes.size()) continue;
    // Each mode's relative change, matched to the nearest pole after the step.
    double largest = 0, seen = 0;
    std::vector<double> change(modes.size(), 0.0);
    for (size_t k = 0; k < modes.size(); ++k) {
      if (!(std::abs(modes[k].lambda) > 0)) continue;  // a free motion's zero pole: no scale
      double nearest = std::numeric_limits<double>::infinity();
      for (const model::Mode& mode : after) {
        nearest = std::min(nearest, std::abs(mode.lambda - modes[k].lambda));
      }
      change[k] = nearest / std::abs(modes[k].lambda);
      largest = std::max(largest, change[k]);
      if (visibility[k] > kVisible) seen = std::max(seen, change[k]);
    }
    if (!(largest > 0) || seen > kSeenShare * largest) continue;
    UnseenParameter found{name, {}};
    for (size_t k = 0; k < modes.size(); ++k) {
      if (visibility[k] <= kVisible && change[k] > kSeenShare * largest) {
        found.modes_hz.push_back(modes[k].frequency_hz());
      }
    }
    unseen.push_back(std::move(found));
  }
  return unseen;
}

std::vector<std::string> MarkUnseenParameters(const model::MechanicalModel& model,
                                              const std::vector<TestRecord>& tests,
                                              UpdateResult& result) {
  std::vector<std::string> unseen;
  std::set<std::string> channels;
  for (const TestRecord& test : tests) {
    channels.insert(test.record.channels.begin(), test.record.channels.end());
  }
  std::unique_ptr<model::MechanicalModel> tuned = model.Clone();
  ApplyEstimates(result, *tuned);
  std::vector<std::string> candidates;
  for (const ParameterEstimate& p : result.parameters) {
    if (p.test.empty()) candidates.push_back(p.name);
  }
  for (const UnseenParameter& found : FindUnseenParameters(*tuned, channels, candidates)) {
    ParameterEstimate& p =
        *std::find_if(result.parameters.begin(), result.parameters.end(),
                      [&](const ParameterEstimate& e) { return e.name == found.name; });
    std::vector<std::string> acted_on;  // the unseen modes it moves
    for (double hz : found.modes_hz) acted_on.push_back(fmt::format("{:.3g} Hz", hz));
    // Said first where another rule already left it undetermined (alternative minima that
    // differ in it): this one is why no test of these channels can settle it.
    const std::string why = fmt::format(
        "the records' channels ({}) do not see the modes it acts on in the linearized model "
        "({}): only the model's nonlinear coupling carries it, and its standard deviation does "
        "not hold",
        fmt::join(channels, ", "), fmt::join(acted_on, ", "));
    p.why_undetermined =
        p.determined || p.why_undetermined.empty() ? why : why + "; and " + p.why_undetermined;
    p.determined = false;
    if (std::find(result.undetermined.begin(), result.undetermined.end(), p.name) ==
        result.undetermined.end()) {
      result.undetermined.push_back(p.name);
    }
    unseen.push_back(p.name);
  }
  if (!unseen.empty()) {
    result.warnings.push_back(fmt::format(
        "{}: the records' channels do not see the modes {} on (the linearized model); left "
        "undetermined",
        fmt::join(unseen, ", "), unseen.size() == 1 ? "it acts" : "they act"));
  }
  return unseen;
}

}  // namespace mbid::updating
