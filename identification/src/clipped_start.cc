// Clipped swings carry no information on the motion beyond the rail, and a fit to their
// flattened peaks brings spurious modes with small standard deviations (clipping.h). The decay
// after the last clipped sample is a free decay like any other: it is analysed instead.
#include "clipped_start.h"

#include <fmt/format.h>

#include <optional>

#include "mbid/common/clipping.h"
#include "record.h"

namespace mbid::identification {

void SkipClippedStart(const Measurement& measurement, IdentificationOptions* applied,
                      ModalResult* result) {
  const Eigen::VectorXd time = measurement.CalcTime();
  const WindowRows window = FindWindowRows(measurement, *applied);
  const Eigen::Index first = window.first;
  const Eigen::Index last = window.last;
  const std::optional<ClippedStart> clipped =
      FindClippedStart(measurement, first, last, applied->channels);
  if (!clipped) return;
  applied->window_start_s = time[clipped->first_whole];
  result->warnings.push_back(fmt::format(
      "{}; the analysis starts after the last clipped sample, at {:.6g} s, on {:.0f} % of the "
      "record (identification.skip_clipped: false, or --keep-clipped, analyses from {:.6g} s)",
      clipped->reason, time[clipped->first_whole],
      100.0 * static_cast<double>(last - clipped->first_whole + 1) /
          static_cast<double>(last - first + 1),
      time[first]));
}

}  // namespace mbid::identification
