#include "mbid/validation/release_profile.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

namespace mbid::validation {
namespace {

// A local fit of `tests` from `start` (shared parameters at its values, the same weights).
updating::UpdateResult FitFrom(const model::MechanicalModel& model,
                               const std::vector<updating::TestRecord>& tests,
                               const updating::UpdateOptions& base,
                               const updating::UpdateResult& start) {
  std::unique_ptr<model::MechanicalModel> clone = model.Clone();
  updating::ApplyEstimates(start, *clone);
  updating::UpdateOptions options = base;
  options.quiet = true;
  options.continuation_fractions.clear();
  options.refit_after_noise_estimate = false;
  options.parameters.clear();
  for (const updating::ParameterEstimate& p : start.parameters) {
    if (!p.test.empty()) continue;  // nuisance parameters start where the tests say
    options.parameters.push_back(
        {p.name, std::clamp(p.value, p.lower, p.upper), p.lower, p.upper, p.log_scale});
  }
  return updating::UpdateModel(*clone, tests, options);
}

// The fit at the placed release, with the judgments made of `judged` kept: parameters the
// global search or Route 1 left undetermined (alternative minima, ambiguous sets) stay so, and
// neither credibility nor warnings are lost.
updating::UpdateResult Merge(const updating::UpdateResult& judged,
                             const updating::UpdateResult& placed) {
  updating::UpdateResult merged = placed;
  for (updating::ParameterEstimate& p : merged.parameters) {
    for (const updating::ParameterEstimate& q : judged.parameters) {
      if (q.name != p.name || q.determined) continue;
      p.determined = false;
      if (p.why_undetermined.empty()) p.why_undetermined = q.why_undetermined;
    }
  }
  for (const std::string& name : judged.undetermined) {
    if (std::find(merged.undetermined.begin(), merged.undetermined.end(), name) ==
        merged.undetermined.end()) {
      merged.undetermined.push_back(name);
    }
  }
  merged.credible = judged.credible && placed.credible;
  for (const std::string& line : judged.credibility) {
    if (std::find(merged.credibility.begin(), merged.credibility.end(), line) ==
        merged.credibility.end()) {
      merged.credibility.push_back(line);
    }
  }
  merged.warnings = judged.warnings;
  for (const std::string& line : placed.warnings) {
    if (std::find(merged.warnings.begin(), merged.warnings.end(), line) == merged.warnings.end()) {
      merged.warnings.push_back(line);
    }
  }
  // The path from the start is the global search's (the convergence figure).
  merged.initial_cost = judged.initial_cost;
  merged.iterations = judged.iterations;
  merged.history = judged.history;
  return merged;
}

bool Usable(const updating::UpdateResult& fit) {
  return fit.termination != updating::UpdateResult::Termination::kFailure &&
         std::isfinite(fit.final_cost);
}

}  // namespace

Measurement MoveRelease(const Measurement& record, double delta_s) {
  Measurement moved = record;
  moved.start_time_s = record.start_time_s - delta_s;
  const double tau = record.sample_interval_s;
  Eigen::Index skip = 0;
  while (moved.start_time_s < -1e-9 * tau && skip + 2 < record.values.rows()) {
    moved.start_time_s += tau;
    ++skip;
  }
  if (skip > 0) moved.values = record.values.bottomRows(record.values.rows() - skip).eval();
  return moved;
}

std::vector<std::string> PlaceDetectedReleases(const model::MechanicalModel& model,
                                               std::vector<updating::TestRecord>* records,
                                               const updating::UpdateOptions& options,
                                               updating::UpdateResult* best) {
  std::vector<std::string> lines;
  if (best->termination == updating::UpdateResult::Termination::kFailure) return lines;
  // The weights the best fit used, kept for every fit of the profile: costs must compare.
  for (size_t t = 0; t < records->size() && t < best->tests.size(); ++t) {
    const updating::TestFit& fit = best->tests[t];
    for (size_t c = 0; c < fit.channels.size(); ++c) {
      (*records)[t].noise_std[fit.channels[c]] = fit.noise_std[static_cast<Eigen::Index>(c)];
    }
  }
  for (size_t t = 0; t < records->size(); ++t) {
    if (!(*records)[t].release_detected) continue;
    const Measurement original = (*records)[t].record;
    const double h = 0.5 * original.sample_interval_s;
    const auto cost_at = [&](double shift, updating::UpdateResult* fit) {
      std::vector<updating::TestRecord> moved = *records;
      moved[t].record = MoveRelease(original, shift);
      *fit = FitFrom(model, moved, options, *best);
      return Usable(*fit) ? fit->final_cost : std::numeric_limits<double>::quiet_NaN();
    };
    double centre = 0, sigma = std::numeric_limits<double>::quiet_NaN();
    updating::UpdateResult at_centre = *best, before, after;
    double c0 = cost_at(0, &at_centre);
    bool placed = std::isfinite(c0);
    for (int round = 0; placed && round < 2; ++round) {
      const double cm = cost_at(centre - h, &before), cp = cost_at(centre + h, &after);
      const double curvature = (cm - 2 * c0 + cp) / (h * h);
      if (!(std::isfinite(curvature) && curvature > 0)) {
        placed = false;
        break;
      }
      sigma = 1 / std::sqrt(curvature);  // cost = chi^2 / 2: one std raises it by 1/2
      const double step = std::clamp(-(cp - cm) / (2 * h) / curvature, -4 * h, 4 * h);
      if (std::abs(step) < 0.1 * h) break;
      centre += step;
      c0 = cost_at(centre, &at_centre);
      placed = std::isfinite(c0);
    }
    if (!placed) {
      lines.push_back(
          fmt::format("{}: the fit does not place the release (its cost has no "
                      "least point near the detected instant); kept as detected",
                      (*records)[t].name));
      continue;
    }
    (*records)[t].record = MoveRelease(original, centre);
    // What the release's uncertainty moves each shared parameter by: the slope between the two
    // fits half a sample either way, times its standard deviation.
    updating::UpdateResult placed_fit = at_centre;
    for (updating::ParameterEstimate& p : placed_fit.parameters) {
      if (!p.test.empty()) continue;
      double low = NAN, high = NAN;
      for (const auto& q : before.parameters) {
        if (q.name == p.name) low = q.value;
      }
      for (const auto& q : after.parameters) {
        if (q.name == p.name) high = q.value;
      }
      const double moved = (high - low) / (2 * h) * sigma;
      if (std::isfinite(moved) && std::isfinite(p.std)) {
        p.std = std::hypot(p.std, moved);
        if (p.value != 0) p.relative_std = p.std / std::abs(p.value);
        // The intervals as output_error.h defines them, from the widened std.
        if (p.log_scale) {
          const double factor = std::exp(2 * p.relative_std * placed_fit.std_inflation);
          p.interval_lower = p.value / factor;
          p.interval_upper = p.value * factor;
        } else {
          p.interval_lower = p.value - 2 * p.std * placed_fit.std_inflation;
          p.interval_upper = p.value + 2 * p.std * placed_fit.std_inflation;
        }
      }
    }
    *best = Merge(*best, placed_fit);
    lines.push_back(fmt::format(
        "{}: the fit places the release {:.3g} ms {} the detected instant (+- {:.2g} ms, {:.2g} "
        "samples); the standard deviations include what that uncertainty moves",
        (*records)[t].name, 1e3 * std::abs(centre), centre < 0 ? "before" : "after", 1e3 * sigma,
        sigma / original.sample_interval_s));
  }
  for (const std::string& line : lines) best->warnings.push_back(line);
  return lines;
}

}  // namespace mbid::validation
