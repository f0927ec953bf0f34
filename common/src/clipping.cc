#include "mbid/common/clipping.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace mbid {
namespace {

// The smallest positive step between the channel's distinct values: its quantization step when
// it was recorded on a grid (an ADC's counts, a logger's printed digits), else about roundoff.
double SmallestStep(const Eigen::Ref<const Eigen::VectorXd>& values) {
  std::vector<double> sorted(values.data(), values.data() + values.size());
  std::sort(sorted.begin(), sorted.end());
  double step = 0;
  for (size_t i = 1; i < sorted.size(); ++i) {
    const double d = sorted[i] - sorted[i - 1];
    if (d > 0 && (step == 0 || d < step)) step = d;
  }
  return step;
}

// Runs of samples at `level`: how many samples, how many runs of 2 or more, and whether a run of
// 3 or more lies before the series' end (the channel leaves the value again; a run at the end
// may be the machine come to rest).
struct Runs {
  int samples = 0;
  int long_runs = 0;
  bool interior_plateau = false;
};

Runs RunsAt(const Eigen::Ref<const Eigen::VectorXd>& values, double level, double tolerance) {
  Runs runs;
  const Eigen::Index n = values.size();
  Eigen::Index j = 0;
  while (j < n) {
    if (std::abs(values[j] - level) > tolerance) {
      ++j;
      continue;
    }
    const Eigen::Index begin = j;
    while (j < n && std::abs(values[j] - level) <= tolerance) ++j;
    const Eigen::Index length = j - begin;
    runs.samples += static_cast<int>(length);
    if (length >= 2) ++runs.long_runs;
    if (length >= 3 && j < n) runs.interior_plateau = true;
  }
  return runs;
}

}  // namespace

std::optional<Clipping> FindClipping(const Eigen::Ref<const Eigen::VectorXd>& values) {
  if (values.size() < 8 || !values.allFinite()) return std::nullopt;
  const double high = values.maxCoeff(), low = values.minCoeff();
  const double range = high - low;
  if (!(range > 0) || SmallestStep(values) > 1e-3 * range) return std::nullopt;
  const double tolerance = 1e-9 * range;
  const Runs top = RunsAt(values, high, tolerance);
  const Runs bottom = RunsAt(values, low, tolerance);
  const bool clipped =
      top.interior_plateau || bottom.interior_plateau || top.long_runs + bottom.long_runs >= 2;
  if (!clipped) return std::nullopt;
  Clipping clipping;
  clipping.at_maximum = top.long_runs > 0 || top.interior_plateau;
  clipping.at_minimum = bottom.long_runs > 0 || bottom.interior_plateau;
  clipping.maximum = high;
  clipping.minimum = low;
  clipping.samples =
      (clipping.at_maximum ? top.samples : 0) + (clipping.at_minimum ? bottom.samples : 0);
  return clipping;
}

std::string ClippingReason(const std::string& channel, const std::string& unit,
                           const Clipping& clipping) {
  const std::string space = unit.empty() ? "" : " ";
  const std::string where =
      clipping.at_maximum && clipping.at_minimum
          ? fmt::format("its largest and smallest values, {:.6g} and {:.6g}{}{},", clipping.maximum,
                        clipping.minimum, space, unit)
      : clipping.at_maximum
          ? fmt::format("its largest value, {:.6g}{}{},", clipping.maximum, space, unit)
          : fmt::format("its smallest value, {:.6g}{}{},", clipping.minimum, space, unit);
  return fmt::format(
      "channel {} stays at {} for {} samples: the sensor or logger was at the end of its range "
      "(clipped)",
      channel, where, clipping.samples);
}

}  // namespace mbid
