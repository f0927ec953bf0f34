#include "mbid/common/clipping.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace mbid {
namespace {

// A sample is at a rail when within this fraction of the channel's range of its extreme.
constexpr double kRailTolerance = 1e-9;

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

// The last sample of `values` held at a rail of `clipping` (within FindClipping's tolerance).
Eigen::Index LastClipped(const Eigen::Ref<const Eigen::VectorXd>& values,
                         const Clipping& clipping) {
  const double tolerance = kRailTolerance * (clipping.maximum - clipping.minimum);
  for (Eigen::Index j = values.size() - 1; j >= 0; --j) {
    if ((clipping.at_maximum && std::abs(values[j] - clipping.maximum) <= tolerance) ||
        (clipping.at_minimum && std::abs(values[j] - clipping.minimum) <= tolerance)) {
      return j;
    }
  }
  return -1;
}

}  // namespace

std::optional<ClippedStart> FindClippedStart(const Measurement& record, Eigen::Index first,
                                             Eigen::Index last,
                                             const std::vector<std::string>& channels) {
  const Eigen::Index count = last - first + 1;
  if (first < 0 || last >= record.values.rows() || count < 16) return std::nullopt;
  // Channels left out of the analysis neither set the start nor, stuck on a rail, prevent it.
  const auto analysed = [&](int c) {
    const std::string& name = record.channels[static_cast<size_t>(c)];
    return channels.empty() || std::find(channels.begin(), channels.end(), name) != channels.end();
  };
  ClippedStart found{first, ""};
  for (int c = 0; c < record.channel_count(); ++c) {
    if (!analysed(c)) continue;
    const std::string& name = record.channels[static_cast<size_t>(c)];
    const auto values = record.values.col(c).segment(first, count);
    const std::optional<Clipping> clipping = FindClipping(values);
    if (!clipping) continue;
    const Eigen::Index after = first + LastClipped(values, *clipping) + 1;
    if (after > found.first_whole) {
      found.first_whole = after;
      found.reason = ClippingReason(name, record.units[static_cast<size_t>(c)], *clipping);
    }
  }
  if (found.first_whole == first || 2 * (last - found.first_whole + 1) < count) {
    return std::nullopt;
  }
  for (int c = 0; c < record.channel_count(); ++c) {
    if (analysed(c) && FindClipping(record.values.col(c).segment(found.first_whole,
                                                                 last - found.first_whole + 1))) {
      return std::nullopt;
    }
  }
  return found;
}

std::optional<Clipping> FindClipping(const Eigen::Ref<const Eigen::VectorXd>& values) {
  if (values.size() < 8 || !values.allFinite()) return std::nullopt;
  const double high = values.maxCoeff(), low = values.minCoeff();
  const double range = high - low;
  if (!(range > 0) || SmallestStep(values) > 1e-3 * range) return std::nullopt;
  const double tolerance = kRailTolerance * range;
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
