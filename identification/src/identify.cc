// Identify: the free decay prepared (free_decay.h, record.h), the poles from the chosen method
// (methods/method.h), the results (mode_results.h) and whether the data support them
// (reliability.h).
#include "mbid/identification/identify.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <vector>

#include "clipped_start.h"
#include "combination_tones.h"
#include "dead_channels.h"
#include "estimate.h"
#include "free_decay.h"
#include "internal.h"
#include "mbid/common/error.h"
#include "mbid/identification/drift_removal.h"
#include "mbid/identification/release.h"
#include "mbid/identification/spectrum.h"
#include "methods/method.h"
#include "mode_results.h"
#include "mode_selection.h"
#include "out_of_band.h"
#include "record.h"
#include "reliability.h"
#include "residual_windows.h"

namespace mbid::identification {
namespace {

// Values far from 1 leave a double's range in the analysis' sums of squares and products: records
// of 1e80 and 1e-200 found "no modes", one reason saying "-nan times what white noise gives"
// (1e-95 to 1e70 identify as at 1). No structure moves so in SI units: a unit stated wrongly.
void CheckMagnitudes(const Measurement& measurement, const std::string& origin) {
  constexpr double kLargest = 1e60, kSmallest = 1e-60;
  for (Eigen::Index c = 0; c < measurement.values.cols(); ++c) {
    if (!measurement.values.col(c).allFinite()) continue;  // named where the record is checked
    const double largest = measurement.values.col(c).cwiseAbs().maxCoeff();
    if (!(largest > kLargest) && !(largest > 0 && largest < kSmallest)) continue;
    const auto k = static_cast<size_t>(c);
    throw InputError(
        origin, "channel " + measurement.channels[k],
        fmt::format("values up to {:.3g} {}", largest,
                    k < measurement.units.size() ? measurement.units[k] : std::string()),
        "values between 1e-60 and 1e60 in magnitude, whose powers the analysis forms within a "
        "double's range (a unit stated wrongly, --unit, is the likely cause)");
  }
}

// The most samples a record is analysed again at its full rate for a start the decimation
// filter hides (the full-rate analysis grows with the samples; longer records keep the flag).
constexpr Eigen::Index kLongestFullRateReanalysis = 200000;

// Later starts of the analysis, in fractions of the analysed duration, when no mode is found
// from the first one.
constexpr double kLaterStarts[] = {0.02, 0.05, 0.1, 0.2};

// Set while Identify analyses from a later start: that analysis does not look further itself.
thread_local bool later_start = false;

// After "no modes found" from `start_s` (the analysed record's first time, `duration_s` long):
// the analysis from later starts, the first that finds modes, with a warning; nullopt if none.
// A strong non-oscillating part at the start (an overdamped joint's real poles: -138 and -3.4
// 1/s beside a 4.59 Hz mode, a trial's machine) pulled every refined pole out of the band.
std::optional<ModalResult> IdentifyFromLaterStart(const Measurement& measurement,
                                                  const IdentificationOptions& options,
                                                  const std::string& origin, double start_s,
                                                  double duration_s, const std::string& reason) {
  if (later_start || options.window_end_s < std::numeric_limits<double>::infinity()) {
    return std::nullopt;
  }
  later_start = true;
  std::optional<ModalResult> found;
  for (const double fraction : kLaterStarts) {
    IdentificationOptions later = options;
    later.window_start_s = start_s + fraction * duration_s;
    try {
      found = Identify(measurement, later, origin);
    } catch (const NumericalError&) {
      continue;
    }
    found->warnings.insert(
        found->warnings.begin(),
        fmt::format("no modes found from {:.6g} s ({}): a strong part of the start that is no "
                    "mode (an overdamped joint's decay, a sensor settling) can hide them; "
                    "analysed from {:.6g} s",
                    start_s, reason, later.window_start_s));
    break;
  }
  later_start = false;
  return found;
}

// A sample interval known to +-u (relative) scales every frequency and decay rate by up to
// 1 -+ u, the same for all: added to each std as a uniform error's u / sqrt(3). The damping ratio
// does not depend on the time scale.
void AddTimeBaseUncertainty(double u, ModalResult* result) {
  if (!(u > 0)) return;
  for (IdentifiedMode& mode : result->modes) {
    mode.std_frequency_hz =
        std::hypot(mode.std_frequency_hz, u * mode.frequency_hz / std::sqrt(3.0));
    mode.std_decay_rate_per_s =
        std::hypot(mode.std_decay_rate_per_s, u * mode.decay_rate_per_s / std::sqrt(3.0));
  }
  result->warnings.push_back(fmt::format(
      "the record's sample interval is known to +-{:.2g} % only (its file prints it to few "
      "digits, or its time stamps' own rate is not quite the stated one): every frequency and "
      "decay rate may be off by as much, which their standard "
      "deviations now include; the logger's exact rate (sample_rate_hz, --sample-rate-hz) "
      "removes it",
      100 * u));
}

}  // namespace

ModalResult Identify(const Measurement& measurement, const IdentificationOptions& options,
                     const std::string& origin) {
  CheckMagnitudes(measurement, origin);
  if (options.remove_drift) return IdentifyRemovingDrift(measurement, options, origin);
  ModalResult result;
  options.Validate("identification options");
  ReleaseDetection detection;
  IdentificationOptions applied = ApplyRelease(measurement, options, &result, &detection);
  if (options.skip_clipped) SkipClippedStart(measurement, &applied, &result);
  LeaveOutDeadChannels(measurement, &applied, &result);
  const AnalysisRecord record = PrepareRecord(measurement, applied, origin);
  result.channels = record.channels;
  result.units = record.units;
  result.sample_interval_s = record.sample_interval_s;
  result.samples = static_cast<int>(record.values.rows());
  result.start_time_s = record.start_time_s;
  result.decimation = record.decimation;
  result.max_frequency_hz = record.max_frequency_hz;
  result.min_correlation = options.min_correlation;
  result.method = MethodName(options.method);
  result.significance_threshold = SignificanceThreshold(record, options);
  if (options.compute_spectrum) {
    result.spectrum = CalcSpectrum(record.centered, record.sample_interval_s, options.spectrum);
    result.has_spectrum = true;
  }

  // FindOptionProblem has checked that the method is registered.
  Estimate estimate;
  try {
    estimate = FindMethod(options.method.name())->estimate(record, options);
    AddEstimate(record, options, &estimate, &result);
  } catch (const NumericalError& e) {
    if (e.reason().rfind("no modes found", 0) == 0) {
      const double duration_s =
          static_cast<double>(record.values.rows() - 1) * record.sample_interval_s;
      std::optional<ModalResult> later = IdentifyFromLaterStart(
          measurement, options, origin, record.start_time_s, duration_s, e.reason());
      if (later) return *later;
    }
    // A clipped or glitched record is the likelier cause than the method: say so.
    std::string reason = e.reason();
    for (const std::string& fault : RecordFaults(record)) reason += "; " + fault;
    throw NumericalError(e.stage(), reason);
  }
  if (detection.detected && detection.from_rest) {
    // The whole decay knows the release better than its first samples (release.h).
    const double onset_s = result.release_time_s;
    // Each analysed channel's level at rest, as the detection found it.
    std::vector<double> rest_level;
    for (const std::string& channel : result.channels) {
      const auto column =
          std::find(measurement.channels.begin(), measurement.channels.end(), channel) -
          measurement.channels.begin();
      rest_level.push_back(detection.rest_level[static_cast<size_t>(column)]);
    }
    const double refined_s = RefineReleaseFromModes(result, onset_s, rest_level);
    if (refined_s > result.start_time_s && options.window_start_s <= refined_s) {
      // The onset came early (noise at rest crossing its threshold at a high rate): samples at
      // rest before the release were fitted as free decay, biasing the heavily damped modes
      // (the crane at 5 kHz, an onset 16 samples early: a decay rate 11 std off). Analysed again
      // from the first sample after the refined release.
      IdentificationOptions given = options;
      given.release = ReleaseMode::kGiven;
      given.release_time_s = refined_s;
      ModalResult again = Identify(measurement, given, origin);
      again.release = "detected";
      again.warnings.insert(
          again.warnings.begin(),
          fmt::format("free decay starts at {:.6g} s, where the identified modes' velocities "
                      "vanish together (the onset after {} samples at rest: {:.6g} s, early); the "
                      "analysis starts at the first sample after it, {:.6g} s (--release none to "
                      "analyse the whole record)",
                      refined_s, detection.rest_samples, onset_s, again.start_time_s));
      return again;
    }
    result.release_time_s = refined_s;
    if (result.release_time_s != onset_s) {
      // One release for the user: ApplyRelease's line (the first warning) names the refined
      // instant, the onset and where the analysis starts (the first sample after the onset).
      result.warnings.front() = fmt::format(
          "free decay starts at {:.6g} s, where the identified modes' velocities vanish "
          "together (the onset after {} samples at rest: {:.6g} s); the analysis starts at the "
          "first sample after the onset, {:.6g} s (--release none to analyse the whole record)",
          result.release_time_s, detection.rest_samples, onset_s, result.start_time_s);
    }
  }
  if (options.decimation == 0 && record.decimation > 1) {
    // What the band chosen from the spectrum left out: a decaying mode above it is a burst at
    // the start of what the modes' full-rate fit leaves (out_of_band.h), a mode at its top is
    // half in the filter's edge (a Hann window hides a short record's fast decay). Analysed
    // again with a band that holds it.
    const Eigen::MatrixXd residual = record.values - result.reconstruction;
    const double burst_hz =
        FindDecayingContentTop(record.centered, residual, record.sample_interval_s);
    double edge_hz = 0;
    if (options.max_frequency_hz <= 0) {
      for (const IdentifiedMode& mode : result.modes) {
        if (mode.frequency_hz > 0.95 * record.flat_frequency_hz) {
          edge_hz = std::max(edge_hz, mode.frequency_hz);
        }
      }
    }
    const double top_hz = std::max(burst_hz > record.flat_frequency_hz ? burst_hz : 0, edge_hz);
    IdentificationOptions wider = options;
    wider.decimation =
        DecimationForBand(1.25 * top_hz, record.sample_interval_s, record.values.rows());
    // The decimated record starts half the filter's length in (20 samples per factor): a mode
    // gone by then (5 Hz at 45 % damping, 200 Hz: 14 1/s) is in the full-rate residual's first
    // window only. Analysed at the full rate, up to a size where that stays cheap.
    const std::optional<ResidualWindows::Excess> start = FindExcessAtTheStart(
        record.values, residual, record.sample_interval_s,
        std::max(record.flat_frequency_hz, burst_hz), options.significance_false_alarm);
    // Said only where it, not a band above the spectrum's, asks for the full rate.
    const bool hidden_start = start && start->power_ratio >= 3 &&
                              record.values.rows() <= kLongestFullRateReanalysis &&
                              (top_hz <= 0 || wider.decimation > 1);
    if (hidden_start) wider.decimation = 1;
    if ((top_hz > 0 || hidden_start) && wider.decimation < record.decimation) {
      // The analysis again must not lose what this one found: a 2 kHz record of 0.5-3 Hz modes
      // has no oscillation the full-rate Hankel matrix resolves, and failed with "no modes".
      std::optional<ModalResult> again;
      std::string failure;
      try {
        again = Identify(measurement, wider, origin);
      } catch (const NumericalError& error) {
        failure = error.what();
      }
      const std::string what =
          hidden_start
              ? fmt::format(
                    "the full-rate residual's first {:.4g} s hold {:.3g} times its power "
                    "elsewhere, before the decimation filter's first output at the {:.4g} "
                    "Hz its spectrum showed (decimation {})",
                    start->samples * record.sample_interval_s, start->power_ratio,
                    record.flat_frequency_hz, record.decimation)
              : fmt::format("{} the {:.4g} Hz its spectrum showed (decimation {})",
                            top_hz == edge_hz
                                ? fmt::format("a mode at {:.4g} Hz is at the top of", edge_hz)
                                : fmt::format("the record's start holds a decaying component up "
                                              "to {:.4g} Hz, above",
                                              burst_hz),
                            record.flat_frequency_hz, record.decimation);
      if (again) {
        again->warnings.insert(
            again->warnings.begin(),
            fmt::format("{}: analysed with decimation {}", what, wider.decimation));
        return *again;
      }
      result.warnings.push_back(
          fmt::format("{}: analysed again with decimation {}, which failed ({}); the analysis with "
                      "decimation {} stands",
                      what, wider.decimation, failure, record.decimation));
    }
  }
  AddTimeBaseUncertainty(measurement.sample_interval_uncertainty, &result);
  MarkCombinationTones(record, options, &result);
  AssessReliability(record, options, estimate, &result);
  return result;
}

}  // namespace mbid::identification
