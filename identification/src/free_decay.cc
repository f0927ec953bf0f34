#include "free_decay.h"

#include <fmt/format.h>

#include <algorithm>

#include "mbid/identification/release.h"

namespace mbid::identification {

// Where the free decay starts, and the options with the analysis window starting there.
IdentificationOptions ApplyRelease(const Measurement& measurement,
                                   const IdentificationOptions& options, ModalResult* result,
                                   ReleaseDetection* detection) {
  *detection = ReleaseDetection();
  IdentificationOptions applied = options;
  result->release_time_s = measurement.start_time_s;
  switch (options.release) {
    case ReleaseMode::kNone:
      result->release = "none";
      return applied;
    case ReleaseMode::kGiven:
    case ReleaseMode::kForcingEnd:
      result->release = options.release == ReleaseMode::kGiven ? "given" : "forcing end";
      result->release_time_s = options.release_time_s;
      break;
    case ReleaseMode::kDetect: {
      *detection = DetectRelease(measurement);
      result->release = detection->detected ? "detected" : "record start";
      result->release_time_s = detection->release_time_s;
      if (detection->detected) {
        result->warnings.push_back(fmt::format(
            "{}; the analysis starts there (--release none to analyse the whole record)",
            detection->description));
      }
      break;
    }
  }
  // Samples at or after the release: PrepareRecord keeps t >= window_start_s - tau / 2.
  const double tau = measurement.sample_interval_s;
  applied.window_start_s =
      std::max(options.window_start_s, result->release_time_s + 0.5 * tau * (1 - 1e-9));
  // A second test in the same record (a reload and a second drop, a knock) is no part of this
  // decay: fitted with it, it made ten modes of two, each unreliable, none saying why.
  const std::optional<NextExcitation> next =
      FindNextExcitation(measurement, std::max(result->release_time_s, options.window_start_s));
  if (next && next->time_s < options.window_end_s) {
    result->next_excitation_s = next->time_s;
    applied.window_end_s = next->time_s - tau * (1 + 1e-9);  // its last sample before
    result->warnings.push_back(
        fmt::format("{}; the analysis ends before it (--release none to analyse the whole record)",
                    next->description));
  }
  return applied;
}

}  // namespace mbid::identification
