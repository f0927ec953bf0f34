// WidenToTheIntervalEnds (credibility.h): the Fisher standard deviation where the interval ends.

#include <fmt/format.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "fit_unknowns.h"
#include "mbid/updating/credibility.h"
#include "nan.h"
#include "output_error_fit.h"

namespace mbid::updating {
namespace {

// Below this relative std the interval spans a few percent of the parameter: the information
// does not change across it (the paper's records, 1e-5 rad noise: 0.1-3 %).
constexpr double kCheckedRelativeStd = 0.05;
// A std at an end up to this ratio of the estimate's is the quadratic cost the std assumes.
constexpr double kWidening = 1.1;
// The interval's end moves out with the widened std; a second look there approaches the end
// where the estimate is 2 of that end's own standard deviations away.
constexpr int kRounds = 2;

// The larger ratio of the std at an end to the estimate's, and which end.
struct Checked {
  double ratio = 1;
  const char* end = "";
};

}  // namespace

std::vector<std::string> WidenToTheIntervalEnds(const model::MechanicalModel& model,
                                                const std::vector<TestRecord>& tests,
                                                const UpdateOptions& options,
                                                UpdateResult& result) {
  std::vector<std::string> widened;
  const int count = static_cast<int>(result.parameters.size());
  if (result.termination != UpdateResult::Termination::kConverged ||
      result.covariance.rows() != count) {
    return widened;
  }
  std::vector<TestRecord> weighted = tests;
  internal::WeighAs(result, weighted);
  internal::StartNuisanceAt(result, weighted);
  Eigen::VectorXd x(count), lower(count), upper(count);
  for (int k = 0; k < count; ++k) {
    const ParameterEstimate& p = result.parameters[static_cast<size_t>(k)];
    x[k] = internal::ToInternal(p, p.value);
    lower[k] = internal::ToInternal(p, p.lower);
    upper[k] = internal::ToInternal(p, p.upper);
  }
  const double inflation = std::max(1.0, result.std_inflation);
  std::vector<int> active;
  for (int k = 0; k < count; ++k) {
    const ParameterEstimate& p = result.parameters[static_cast<size_t>(k)];
    if (p.test.empty() && p.determined && p.relative_std * inflation > kCheckedRelativeStd) {
      active.push_back(k);
    }
  }
  std::vector<bool> flat(static_cast<size_t>(count), false);
  for (int round = 0; round < kRounds && !active.empty(); ++round) {
    // Each end of the linearized profile: the parameter 2 inflated stds out, the others moved
    // along with it by their correlation (the fit's conditional optimum to first order).
    std::vector<Eigen::VectorXd> points;
    for (int k : active) {
      const Eigen::VectorXd step =
          2 * inflation * result.covariance.col(k) / std::sqrt(result.covariance(k, k));
      for (double sign : {1.0, -1.0}) {
        points.push_back((x + sign * step).cwiseMax(lower).cwiseMin(upper));
      }
    }
    const std::vector<Eigen::MatrixXd> at =
        internal::CalcCovarianceAt(model, weighted, options, points);
    if (at.empty() || at.front().rows() != count) break;  // other unknowns: nothing to compare
    std::vector<int> next;
    for (size_t a = 0; a < active.size(); ++a) {
      const int k = active[a];
      ParameterEstimate& p = result.parameters[static_cast<size_t>(k)];
      const double here = std::sqrt(result.covariance(k, k));
      Checked worst;
      for (int side = 0; side < 2; ++side) {
        const double there = at[2 * a + static_cast<size_t>(side)](k, k);
        const double ratio = there >= 0 && std::isfinite(there) ? std::sqrt(there) / here : kNaN;
        if (!(ratio <= worst.ratio)) worst = {ratio, side == 0 ? "upper" : "lower"};
      }
      if (!std::isfinite(worst.ratio)) {
        flat[static_cast<size_t>(k)] = true;
        p.determined = false;
        p.why_undetermined = fmt::format(
            "at its interval's {} end the records leave it in a flat direction: the cost is not "
            "the quadratic its standard deviation assumes",
            worst.end);
      } else if (worst.ratio > kWidening) {
        p.std_widening *= worst.ratio;
        p.std *= worst.ratio;
        p.relative_std *= worst.ratio;
        result.covariance.row(k) *= worst.ratio;
        result.covariance.col(k) *= worst.ratio;
        SetInterval(p, result.std_inflation);
        // Once undetermined, a look farther out cannot make it determined again.
        if (!MarkIfSpreadUndetermined(p, result.std_inflation, options.undetermined_relative_std,
                                      &result)) {
          next.push_back(k);
        }
      }
    }
    active = next;
  }
  for (int k = 0; k < count; ++k) {
    ParameterEstimate& p = result.parameters[static_cast<size_t>(k)];
    if (p.std_widening == 1.0 && !flat[static_cast<size_t>(k)]) continue;
    widened.push_back(p.name);
    result.warnings.push_back(fmt::format(
        "{}: the records' information on it changes across its interval (little signal for "
        "it): its standard deviation at the interval's end is {:.3g} times the one at the "
        "estimate, and the larger is reported{}",
        p.name, p.std_widening, p.determined ? "" : "; " + p.why_undetermined));
    if (!p.determined && std::find(result.undetermined.begin(), result.undetermined.end(),
                                   p.name) == result.undetermined.end()) {
      result.undetermined.push_back(p.name);
    }
  }
  return widened;
}

}  // namespace mbid::updating
