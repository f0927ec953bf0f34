#include "mbid/common/outliers.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace mbid {
namespace {

constexpr double kRatio = 30;       // see the header
constexpr Eigen::Index kHalf = 16;  // half the window of the local spread

// The step of a quantized channel (an ADC's least significant bit): the least non-zero change
// between neighbouring samples, when at least 90 % of the changes are whole multiples of it;
// else 0.
double QuantizationStep(const Eigen::Ref<const Eigen::VectorXd>& values) {
  double step = std::numeric_limits<double>::infinity();
  for (Eigen::Index j = 1; j < values.size(); ++j) {
    const double change = std::abs(values[j] - values[j - 1]);
    if (change > 0) step = std::min(step, change);
  }
  if (!std::isfinite(step)) return 0;
  Eigen::Index changes = 0, multiples = 0;
  for (Eigen::Index j = 1; j < values.size(); ++j) {
    const double ratio = std::abs(values[j] - values[j - 1]) / step;
    if (ratio == 0) continue;
    ++changes;
    if (std::abs(ratio - std::round(ratio)) < 1e-3 * std::max(1.0, ratio)) ++multiples;
  }
  return multiples >= 0.9 * static_cast<double>(changes) ? step : 0;
}

}  // namespace

std::vector<Outlier> FindOutliers(const Eigen::Ref<const Eigen::VectorXd>& values) {
  std::vector<Outlier> outliers;
  const Eigen::Index n = values.size();
  if (n < 16 || !values.allFinite()) return outliers;
  const double range = values.maxCoeff() - values.minCoeff();
  if (!(range > 0)) return outliers;
  Eigen::VectorXd bend(n);  // |second difference|, 0 at the ends
  bend.setZero();
  for (Eigen::Index j = 1; j + 1 < n; ++j) {
    bend[j] = std::abs(values[j + 1] - 2 * values[j] + values[j - 1]);
  }
  // A noiseless, flat stretch has no spread; a quantized channel's spread is at least its step:
  // a 12-bit logger with the noise under one step moves by 0 or 1 step, and its median second
  // difference is 0 (one step was called 8e5 times the local spread).
  const double floor = std::max(1e-9 * range, QuantizationStep(values));
  std::vector<double> window;
  for (Eigen::Index j = 1; j + 1 < n; ++j) {
    if (bend[j] <= kRatio * floor) continue;
    window.clear();
    for (Eigen::Index i = std::max<Eigen::Index>(1, j - kHalf);
         i <= std::min<Eigen::Index>(n - 2, j + kHalf); ++i) {
      if (std::abs(i - j) > 1) window.push_back(bend[i]);
    }
    if (window.size() < 8) continue;
    const auto middle = window.begin() + static_cast<std::ptrdiff_t>(window.size() / 2);
    std::nth_element(window.begin(), middle, window.end());
    const double ratio = bend[j] / std::max(*middle, floor);
    if (ratio <= kRatio) continue;
    // A glitch of one or two samples bends the course at most two samples away; three and four
    // away it is back (bends there no more than a tenth). A heavily damped mode near the sampling
    // rate bends it for several samples, decaying: a 40 Hz mode at 30 % damping sampled at 200 Hz
    // was called a glitch at its start.
    double further = 0;
    for (const Eigen::Index k : {j - 4, j - 3, j + 3, j + 4}) {
      if (k >= 1 && k + 1 < n) further = std::max(further, bend[k]);
    }
    if (further > 0.1 * bend[j]) continue;
    if (!outliers.empty() && j - outliers.back().sample <= 2) {
      if (ratio > outliers.back().ratio) outliers.back() = {j, ratio};  // the same jump
    } else {
      outliers.push_back({j, ratio});
    }
  }
  return outliers;
}

std::string OutlierReason(const std::string& channel, const std::vector<Outlier>& outliers,
                          double sample_interval_s, double start_time_s) {
  const auto worst =
      std::max_element(outliers.begin(), outliers.end(),
                       [](const Outlier& a, const Outlier& b) { return a.ratio < b.ratio; });
  const std::string more = outliers.size() > 1
                               ? fmt::format(", and at {} more sample{}", outliers.size() - 1,
                                             outliers.size() == 2 ? "" : "s")
                               : "";
  return fmt::format(
      "channel {} jumps off its course at {:.6g} s ({:.3g} times its local spread){}: a "
      "glitch of the sensor or logger, or a knock",
      channel, start_time_s + static_cast<double>(worst->sample) * sample_interval_s, worst->ratio,
      more);
}

}  // namespace mbid
