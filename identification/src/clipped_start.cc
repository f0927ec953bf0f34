// Clipped swings carry no information on the motion beyond the rail, and a fit to their
// flattened peaks brings spurious modes with small standard deviations (clipping.h). The decay
// after the last clipped sample is a free decay like any other: it is analysed instead.
#include "clipped_start.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>

#include "mbid/common/clipping.h"

namespace mbid::identification {
namespace {

// The last sample of `values` held at a rail of `clipping` (within FindClipping's tolerance).
Eigen::Index LastClipped(const Eigen::Ref<const Eigen::VectorXd>& values,
                         const Clipping& clipping) {
  const double tolerance = 1e-9 * (clipping.maximum - clipping.minimum);
  for (Eigen::Index j = values.size() - 1; j >= 0; --j) {
    if ((clipping.at_maximum && std::abs(values[j] - clipping.maximum) <= tolerance) ||
        (clipping.at_minimum && std::abs(values[j] - clipping.minimum) <= tolerance)) {
      return j;
    }
  }
  return -1;
}

}  // namespace

void SkipClippedStart(const Measurement& measurement, IdentificationOptions* applied,
                      ModalResult* result) {
  const double tau = measurement.sample_interval_s;
  const Eigen::VectorXd time = measurement.CalcTime();
  // The window's samples as PrepareRecord keeps them (half a sample of slack on each side).
  Eigen::Index first = 0;
  while (first < time.size() && time[first] < applied->window_start_s - 0.5 * tau) ++first;
  Eigen::Index last = time.size() - 1;
  while (last >= first && time[last] > applied->window_end_s + 0.5 * tau) --last;
  const Eigen::Index count = last - first + 1;
  if (count < 16) return;  // PrepareRecord says what is wrong with so short a window

  Eigen::Index start = first;  // the first sample after every clipped one
  std::string clipped;         // the reason of the channel clipped last
  for (int c = 0; c < measurement.channel_count(); ++c) {
    const std::string& name = measurement.channels[static_cast<size_t>(c)];
    if (!applied->channels.empty() && std::find(applied->channels.begin(), applied->channels.end(),
                                                name) == applied->channels.end()) {
      continue;
    }
    const auto values = measurement.values.col(c).segment(first, count);
    const std::optional<Clipping> clipping = FindClipping(values);
    if (!clipping) continue;
    const Eigen::Index after = first + LastClipped(values, *clipping) + 1;
    if (after > start) {
      start = after;
      clipped = ClippingReason(name, measurement.units[static_cast<size_t>(c)], *clipping);
    }
  }
  if (start == first || 2 * (last - start + 1) < count) return;
  // The rest must be free of clipping too: a channel that sits on a rail to the end (a sensor
  // stuck there) is no decay that came back inside its range.
  for (int c = 0; c < measurement.channel_count(); ++c) {
    if (FindClipping(measurement.values.col(c).segment(start, last - start + 1))) return;
  }
  applied->window_start_s = time[start];
  result->warnings.push_back(fmt::format(
      "{}; the analysis starts after the last clipped sample, at {:.6g} s, on {:.0f} % of the "
      "record (identification.skip_clipped: false, or --keep-clipped, analyses from {:.6g} s)",
      clipped, time[start], 100.0 * static_cast<double>(last - start + 1) / count, time[first]));
}

}  // namespace mbid::identification
