#include "mbid/common/outliers.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace mbid {
namespace {

constexpr double kRatio = 30;       // see the header
constexpr Eigen::Index kHalf = 16;  // half the window of the local spread

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
  const double floor = 1e-9 * range;  // a noiseless, flat stretch has no spread
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
