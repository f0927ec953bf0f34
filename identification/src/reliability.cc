#include "reliability.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <complex>

#include "coloured_noise.h"
#include "internal.h"
#include "mbid/common/channel_fault.h"
#include "residual_windows.h"

namespace mbid::identification {

bool IsDetermined(double frequency_hz, double std_frequency_hz, double decay_rate_per_s,
                  double std_decay_rate_per_s) {
  // A negative decay within its std is no more determined than a positive one: its sign is not.
  return !(std_frequency_hz > 0.1 * frequency_hz ||
           (decay_rate_per_s != 0 && std_decay_rate_per_s > std::abs(decay_rate_per_s)));
}

std::vector<std::string> RecordFaults(const AnalysisRecord& record) {
  std::vector<std::string> faults;
  for (Eigen::Index c = 0; c < record.values.cols(); ++c) {
    const std::optional<ChannelFault> fault = FindChannelFault(
        record.values.col(c), record.channels[static_cast<size_t>(c)],
        record.units[static_cast<size_t>(c)], record.sample_interval_s, record.start_time_s);
    if (!fault) continue;
    faults.push_back(fault->reason +
                     (fault->kind == ChannelFault::Kind::kClipped
                          ? ", and no mode fitted to the flattened peaks is to be trusted"
                          : "; the modes do not describe it (blank such samples and fill them: "
                            "fill_gaps: linear; a second test starting there: end this one before "
                            "it, end_time_s or --end-time-s)"));
  }
  return faults;
}

// Reasons the data do not support the result (ModalResult::reliable).
void AssessReliability(const AnalysisRecord& record, const IdentificationOptions& options,
                       const Estimate& estimate, ModalResult* result) {
  std::vector<std::string>& reasons = result->reasons;
  const std::vector<std::string> faults = RecordFaults(record);
  reasons.insert(reasons.end(), faults.begin(), faults.end());
  reasons.insert(reasons.end(), estimate.doubts.begin(), estimate.doubts.end());
  // The fit's residual against the record's own noise level: a record the modes explain leaves
  // noise (ratio about 1; coloured noise a little more). 3 x the noise, or a residual above a
  // millionth of the signal when the record is noiseless, means something in the record is not
  // in the modes (a start before the free decay, a nonlinearity, a missed mode).
  const Eigen::VectorXd& residual = estimate.fit.residual_variance;
  Eigen::VectorXd ratios = Eigen::VectorXd::Constant(result->correlation.size(), 0.0);
  for (Eigen::Index c = 0; c < residual.size() && c < estimate.noise_std.size(); ++c) {
    const double level = std::max(estimate.noise_std(c), RoundOffNoiseStd(record.decimated, c));
    const double ratio = std::sqrt(residual(c)) / level;
    if (c < ratios.size()) ratios(c) = ratio;
    if (ratio > 3) {
      reasons.push_back(fmt::format(
          "the residual in channel {} is {:.3g} times the record's noise level: the modes do not "
          "explain the record",
          result->channels[static_cast<size_t>(c)], ratio));
    }
  }
  // A residual at the noise level over the record may still stand out in a few tenths of a
  // second: a heavily damped mode the others absorbed, a transient, a start before the free
  // decay. 3 times the power elsewhere makes the result unreliable. From 2 times it is said as a
  // warning only: weak combination tones of an accelerometer's centripetal terms leave 2.1 times
  // (a drill mast's record), as does a pair of boom modes at 10 times the noise that a stronger
  // mode absorbed (2.2-2.4).
  const Eigen::MatrixXd decimated_residual = DecimatedResidual(record, estimate);
  ResidualWindows windows =
      AnalyseResidualWindows(record.decimated, decimated_residual, options.significance_false_alarm,
                             record.decimation == 1 ? 1 : 0);
  double tau = record.decimated_interval_s;
  double start_s = record.decimated_start_time_s;
  // The decimation filter's output starts half its length in (20 samples per factor): a mode
  // gone by then (110 Hz at 10-40 % damping on a 1 kHz record) leaves no trace in the decimated
  // residual, only in the full-rate one's start. Without a band of the user's (which may leave
  // such modes out on purpose), that start is judged too, in the analysed band (what lies above
  // it, harmonics of a nonlinear machine at a high rate, is not the modes' to explain).
  if (record.decimation > 1 && options.max_frequency_hz <= 0 &&
      result->reconstruction.rows() == record.values.rows()) {
    const std::optional<ResidualWindows::Excess> start = FindExcessAtTheStart(
        record.values, record.values - result->reconstruction, record.sample_interval_s,
        record.flat_frequency_hz, options.significance_false_alarm);
    if (start && (!windows.excess || start->power_ratio > windows.excess->power_ratio)) {
      windows.excess = start;
      tau = record.sample_interval_s;
      start_s = record.start_time_s;
    }
  }
  if (windows.excess) {
    const double from_s = start_s + windows.excess->first_sample * tau;
    const std::string what = fmt::format(
        "the residual from {:.4g} to {:.4g} s has {:.3g} times the power it has elsewhere: "
        "something there is not in the modes (a missed, heavily damped mode, a transient, a "
        "start before the free decay, a second excitation before this decay came to rest: "
        "end the analysis before it: --window-end-s, or end_time_s in a record entry)",
        from_s, from_s + windows.excess->samples * tau, windows.excess->power_ratio);
    (windows.excess->power_ratio >= 3 ? reasons : result->warnings).push_back(what);
  }
  // Noise shared by channels (one sensor logged twice, a logger's common ground): the standard
  // deviations and the significance take the channels' noise as independent, and are too small
  // by up to the square root of the channels sharing it (a trial's 8 copies of one sensor: z up
  // to 10, spurious modes "reliable"). Correlated residuals say so: independent noise keeps
  // their correlation within a few 1 / sqrt(samples).
  {
    const Eigen::Index n = decimated_residual.rows();
    const Eigen::RowVectorXd norm = decimated_residual.colwise().norm();
    // A noiseless record's round-off (AssessReliability's floor) is shared by construction.
    const auto noise = [&](Eigen::Index c) {
      return norm(c) >
             10 * std::sqrt(static_cast<double>(n)) * RoundOffNoiseStd(record.decimated, c);
    };
    const double limit =
        std::max(0.3, 5 / std::sqrt(static_cast<double>(std::max<Eigen::Index>(n, 1))));
    Eigen::Index worst_a = -1, worst_b = -1;
    double worst = limit;
    for (Eigen::Index a = 0; a < decimated_residual.cols(); ++a) {
      if (!noise(a)) continue;
      for (Eigen::Index b = a + 1; b < decimated_residual.cols(); ++b) {
        if (!noise(b)) continue;
        const double rho =
            decimated_residual.col(a).dot(decimated_residual.col(b)) / (norm(a) * norm(b));
        if (std::abs(rho) > worst) {
          worst = std::abs(rho);
          worst_a = a;
          worst_b = b;
        }
      }
    }
    if (worst_a >= 0) {
      reasons.push_back(fmt::format(
          "the residuals of channels {} and {} are correlated ({:.2f}): noise they share (one "
          "sensor logged twice, a common ground) makes the standard deviations and the "
          "significance, which take the channels' noise as independent, too small",
          result->channels[static_cast<size_t>(worst_a)],
          result->channels[static_cast<size_t>(worst_b)], worst));
    }
  }
  // Coloured noise (coloured_noise.h): a mode significant against the variance but not against
  // the residual's level near its frequency may be the noise's; and the noise there, not the
  // variance, sets how well the record knows the mode (AR(1) noise of coefficient 0.8 put a
  // 3 Hz mode's decay 2 of its standard deviations off, rms over 24 records).
  const std::vector<double> noise_ratio =
      CalcLocalNoiseRatio(decimated_residual, record.decimated_interval_s,
                          estimate.fit.residual_variance, result->modes);
  std::vector<std::string> widened;
  for (size_t k = 0; k < result->modes.size(); ++k) {
    IdentifiedMode& mode = result->modes[k];
    const double local = mode.significance / noise_ratio[k];
    if (mode.significant && mode.combination.empty() && local < result->significance_threshold) {
      reasons.push_back(fmt::format(
          "the mode at {:.4g} Hz stands out from the record's noise (significance {:.3g}) but not "
          "from the residual's own level near its frequency ({:.3g}, threshold {:.3g}): noise "
          "that is not white there (ambient vibration, a sensor's low-frequency noise) may make "
          "it",
          mode.frequency_hz, mode.significance, local, result->significance_threshold));
    }
    if (noise_ratio[k] > 1) {
      const double factor = std::sqrt(noise_ratio[k]);
      mode.std_frequency_hz *= factor;
      mode.std_decay_rate_per_s *= factor;
      widened.push_back(fmt::format("{:.4g} Hz x{:.2g}", mode.frequency_hz, factor));
    }
  }
  if (!widened.empty()) {
    result->warnings.push_back(fmt::format(
        "standard deviations widened where the residual's noise is not white, by the square root "
        "of its power near the mode over its mean: {}",
        fmt::join(widened, ", ")));
  }
  result->residual_to_noise = ratios;
  result->residual_window_ratio = windows.channel_ratio;
  const bool any_correlates = (result->correlation.array() >= options.min_correlation).any();
  for (Eigen::Index c = 0; c < result->correlation.size(); ++c) {
    if (!(result->correlation(c) >= options.min_correlation)) {
      // A residual at the noise level is the noise: then the channel's signal is too weak for
      // a higher K, not the modes wrong (the check above names a residual above it).
      const std::string why =
          ratios(c) > 0 && ratios(c) <= 3
              ? fmt::format(
                    "its residual is at the record's noise level ({:.3g} times): the "
                    "channel has too little signal above its noise for a higher K",
                    ratios(c))
              : "the modes do not explain the record in the analysed band";
      // Beside a channel that correlates, one whose residual is its noise (within the 1.2-1.4 an
      // exact fit shows) carries too little of the modes to doubt them: said, not a reason (a
      // channel of pure noise beside good ones made every record unreliable). When no channel
      // correlates, the record as a whole is too weak: a reason.
      const bool noise_only = ratios(c) > 0 && ratios(c) <= 1.5 && any_correlates;
      (noise_only ? result->warnings : reasons)
          .push_back(fmt::format("K = {:.3f} in channel {} is below min_correlation {}: {}",
                                 result->correlation(c), result->channels[static_cast<size_t>(c)],
                                 options.min_correlation, why));
    }
  }
  const double top_hz = std::min(record.max_frequency_hz, record.flat_frequency_hz);
  const double duration_s =
      static_cast<double>(record.decimated.rows()) * record.decimated_interval_s;
  for (const IdentifiedMode& mode : result->modes) {
    if (mode.frequency_hz > 0.95 * top_hz) {
      reasons.push_back(fmt::format(
          "the mode at {:.4g} Hz is at the top of the analysed band ({:.4g} Hz{}): it may be "
          "cut by the band or the decimation filter",
          mode.frequency_hz, top_hz,
          record.decimation > 1 ? fmt::format(", decimation {}", record.decimation) : ""));
    }
    // Less than a cycle in the analysed record: a slow trend or drift fits as well as a mode (a
    // 0.02 Hz sine over 20 s, 0.4 of a cycle, came out as a "reliable" 0.021 Hz mode). One marked
    // as a combination tone is no mode of the structure either way: the slowly decaying mean
    // shift of a linkage's quadratic terms (a difference tone near 0 Hz) made every multi-link
    // free decay unreliable, mbid's own simulated test at 0.2 deg too.
    if (mode.frequency_hz * duration_s < 1) {
      (mode.combination.empty() ? reasons : result->warnings)
          .push_back(fmt::format(
              "the mode at {:.4g} Hz completes {:.2g} of a cycle in the analysed {:.4g} s: a trend "
              "or drift cannot be told from it (remove_drift, or a longer record){}",
              mode.frequency_hz, mode.frequency_hz * duration_s, duration_s,
              mode.combination.empty() ? ""
                                       : "; it is marked as a combination tone (" +
                                             mode.combination + "), no mode of the structure"));
    }
    // The refinement admits growth by e over the record at most (decay -1 / its duration,
    // refinement.cc): a mode that ends there was pushed to the bound, where its standard
    // deviation means nothing (a numerically differentiated channel's end gave a 31 Hz "mode" at
    // exactly that growth, "reliable", in trial records).
    if (mode.decay_rate_per_s <= -0.99 / duration_s) {
      reasons.push_back(fmt::format(
          "the mode at {:.4g} Hz grows at the fit's limit ({:.3g} 1/s: by e over the analysed "
          "{:.4g} s): the fit pushed it to its bound, and no free decay's mode grows (an edge "
          "effect of the record, noise)",
          mode.frequency_hz, mode.decay_rate_per_s, duration_s));
    }
    if (options.min_frequency_hz > 0 && mode.frequency_hz < 1.05 * options.min_frequency_hz) {
      reasons.push_back(fmt::format("the mode at {:.4g} Hz is at the bottom of the band ({} Hz)",
                                    mode.frequency_hz, options.min_frequency_hz));
    }
    // A mode that grows beyond its std is no free decay of a passive machine: a self-excited
    // vibration (which a damper sizing must know of), or a record that is not a free decay.
    if (mode.decay_rate_per_s < -3 * mode.std_decay_rate_per_s) {
      result->warnings.push_back(fmt::format(
          "the mode at {:.4g} Hz grows (decay rate {:.3g} +- {:.2g} 1/s): no free decay of a "
          "passive machine does; a self-excited vibration, or a record that is not a free decay",
          mode.frequency_hz, mode.decay_rate_per_s, mode.std_decay_rate_per_s));
    }
    if (!IsDetermined(mode.frequency_hz, mode.std_frequency_hz, mode.decay_rate_per_s,
                      mode.std_decay_rate_per_s)) {
      // Its frequency determined, its decay not: say which, and what such a mode may be.
      const bool decay_only = !(mode.std_frequency_hz > 0.1 * mode.frequency_hz);
      const std::string what =
          decay_only
              ? fmt::format(
                    "the decay rate of the mode at {:.4g} Hz is undetermined ({:.3g} +- {:.2g} "
                    "1/s): too short a record for its damping, or a tone that does not decay "
                    "(mains hum, a rotating part)",
                    mode.frequency_hz, mode.decay_rate_per_s, mode.std_decay_rate_per_s)
              : fmt::format(
                    "the mode at {:.4g} Hz is undetermined (std of frequency {:.3g} Hz, of decay "
                    "{:.3g} 1/s)",
                    mode.frequency_hz, mode.std_frequency_hz, mode.std_decay_rate_per_s);
      // A combination tone is no mode of the structure: its spread says nothing of theirs.
      if (mode.combination.empty()) {
        reasons.push_back(what);
      } else {
        result->warnings.push_back(what + ", a combination tone");
      }
    }
  }
  for (const IdentifiedMode& mode : result->modes) {
    if (mode.backbone && mode.backbone->amplitude_dependent) {
      reasons.push_back(fmt::format(
          "the mode at {:.4g} Hz is amplitude dependent ({}, {:.2g} times the scatter its "
          "windows' standard deviations allow): its constant frequency and damping hold at no "
          "amplitude; use its backbone",
          mode.frequency_hz, DescribeDrift(*mode.backbone),
          std::sqrt(mode.backbone->spread_chi_square_per_dof)));
    }
  }
  // Modes within 3 % of each other: one mode whose frequency drifts with amplitude, or two the
  // record cannot tell apart; either way not two modes to size dampers on. Unless the record
  // does tell them apart: their frequencies 10 combined standard deviations apart and their
  // shapes over two or more channels unalike (MAC below 0.5; a drifting mode split in two keeps
  // one shape). Two modes 1.00 and 1.02 Hz of 0.2 % damping over 60 s on four channels came
  // back within their standard deviations of 4e-6 Hz, and were called inseparable.
  const auto told_apart = [&](const IdentifiedMode& a, const IdentifiedMode& b) {
    if (a.amplitude.size() < 2 || a.amplitude.size() != b.amplitude.size()) return false;
    const double spread = std::hypot(a.std_frequency_hz, b.std_frequency_hz);
    if (!(std::abs(b.frequency_hz - a.frequency_hz) > 10 * spread)) return false;
    const auto shape = [](const IdentifiedMode& mode) {
      Eigen::VectorXcd z(mode.amplitude.size());
      for (Eigen::Index c = 0; c < z.size(); ++c) {
        z[c] = std::polar(mode.amplitude(c), mode.phase_rad(c));
      }
      return z;
    };
    // (A zero shape counts as alike: not told apart.)
    return ShapeCorrelation(shape(a), shape(b)) < 0.5;
  };
  for (size_t k = 1; k < result->modes.size(); ++k) {
    const double low = result->modes[k - 1].frequency_hz;
    const double high = result->modes[k].frequency_hz;
    // A combination tone beside a mode is no second mode of the structure (a trial's turntable
    // at 0.31 Hz beside a 19.86 Hz slider: f3 -+ f1 at 1.5-1.8 % called the run inconclusive).
    const bool tone =
        !result->modes[k - 1].combination.empty() || !result->modes[k].combination.empty();
    if (!tone && high - low < 0.03 * high && !told_apart(result->modes[k - 1], result->modes[k])) {
      reasons.push_back(fmt::format(
          "modes at {:.4g} and {:.4g} Hz are {:.2g} % apart: one mode drifting with amplitude "
          "or two the record cannot separate",
          low, high, 100 * (high - low) / high));
    }
  }
  if (result->termination != "converged") {
    reasons.push_back("the refinement did not converge (" + result->termination + ")");
  }
  result->reliable = reasons.empty();
}

}  // namespace mbid::identification
