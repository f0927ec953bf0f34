#pragma once

#include <Eigen/Core>
#include <complex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "mbid/common/hdf5_io.h"
#include "mbid/identification/backbone.h"
#include "mbid/identification/spectrum.h"

namespace mbid::identification {

// One identified oscillatory mode (docs/notation: sign conventions of modal quantities).
struct IdentifiedMode {
  std::complex<double> lambda;       // continuous pole, 1/s, Im > 0 (eq. 4)
  double frequency_hz = 0;           // Im(lambda) / (2 pi), damped
  double decay_rate_per_s = 0;       // -Re(lambda); the paper's beta is its negative
  double damping_ratio = 0;          // -Re(lambda) / |lambda|
  double undamped_frequency_hz = 0;  // |lambda| / (2 pi)
  double log_decrement = 0;          // 2 pi decay / omega_d
  double half_life_s = 0;            // ln 2 / decay (+inf if not decaying)
  // Per channel (in ModalResult::channels order): y_c(t) contains
  // amplitude_c exp(-decay t) cos(omega t + phase_c), t from the first analysed sample
  // (modal_fit.h), so amplitude is the peak amplitude at t = 0 as in the paper's Table 1.
  Eigen::VectorXd amplitude;  // channel units
  Eigen::VectorXd phase_rad;  // (-pi, pi]
  // One standard deviation from the Fisher information at the estimate (refinement.h); NaN
  // when not computed.
  double std_frequency_hz = 0;
  double std_decay_rate_per_s = 0;
  // A chi-square statistic of "the mode is absent" (significance.h) and whether it reaches
  // ModalResult::significance_threshold.
  double significance = 0;
  bool significant = true;
  // For a mode whose frequency drifts with amplitude (close poles merged into it): its
  // frequency and damping ratio against amplitude (backbone.h).
  std::optional<Backbone> backbone;
  // Non-empty for a combination tone of other modes ("f1 + f3", "2 f1", "f3 - f1", 1-based
  // in `modes`): their poles' sum (combination_tones.cc), no mode of the structure. A weak mode
  // the record cannot tell from the products up to third order is named by the nearest one
  // ("3 f2", "2 f1 + f3", "f2 + f3 - f1").
  std::string combination;

  // Fills the derived quantities from lambda.
  void SetPole(std::complex<double> pole);
};

// The poles a method finds at one model order (for a stabilization diagram).
struct StabilizationOrder {
  int order = 0;
  std::vector<std::complex<double>> lambda;  // Im >= 0 members only, 1/s
  std::vector<bool> stable;                  // reappears at the next higher orders
};

// What `mbid identify` reports (docs/interfaces: JSON `identify`; HDF5 /identification).
struct ModalResult {
  std::vector<std::string> channels;  // analysed channels, in order
  std::vector<std::string> units;     // of each channel
  double sample_interval_s = 0;       // of the record (before decimation)
  int samples = 0;                    // analysed (in the time window, full rate)
  double start_time_s = 0;            // time of the first analysed sample: t = 0 of the modes
  // Where the free decay starts (release.h), in the record's time; `release` says how it was
  // found: "detected", "record start" (nothing at rest before the decay), "given" or "none".
  double release_time_s = 0;
  std::string release = "record start";
  // Where a second excitation sets the structure off again after this free decay came to rest
  // (release.h: FindNextExcitation), in the record's time: the analysis ends before it.
  std::optional<double> next_excitation_s;
  int decimation = 1;
  double max_frequency_hz = 0;  // top of the analysed band
  std::string method;           // "hankel-nls" | "prony-svd"
  // prony-svd: p of eq. 3 and the effective rank k of step 3. hankel-nls: the largest order the
  // Hankel matrix can represent (columns - 1) and the number of singular values above the
  // noise floor.
  int model_order = 0;
  int effective_rank = 0;
  std::vector<IdentifiedMode> modes;  // ascending frequency
  double significance_threshold = 0;  // IdentificationOptions::significance_false_alarm
  // Per channel: Pearson's K of record and reconstruction in the analysed band (the record low-
  // pass filtered and decimated as the poles were estimated; the full record when decimation 1).
  Eigen::VectorXd correlation;
  // false when the data do not support the result; `reasons` says why (K below
  // min_correlation, a mode at the band's edge, modes too close to tell apart, a refinement that
  // did not converge, an undetermined mode).
  bool reliable = true;
  std::vector<std::string> reasons;
  double min_correlation = 0.9;
  Eigen::VectorXd offset;  // per channel constant (0 unless fitted or removed)
  // Per channel: the linear drift removed (remove_drift), channel units per second; the record's
  // baseline is then offset + drift (t - start_time_s). Empty when not asked.
  Eigen::VectorXd drift_per_s;
  Eigen::VectorXd noise_std;  // per channel: residual standard deviation
  // Per channel, the margins of the residual checks of `reliable`: the residual's standard
  // deviation over the record's noise level (a reason above 3), and its largest window power
  // over its median window's (residual_windows.h; 0 on records too short for the windows).
  // Empty when not assessed.
  Eigen::VectorXd residual_to_noise;
  Eigen::VectorXd residual_window_ratio;
  Eigen::MatrixXd reconstruction;  // samples x channels, offset included
  // eq. 5: [A1 ... Ap] of eq. 2 (m x m p) from the modes' poles and output vectors; empty if
  // not computed.
  Eigen::MatrixXd eq2_coefficients;
  std::vector<StabilizationOrder> stabilization;
  bool has_spectrum = false;
  Spectrum spectrum;
  // Solver and selection notes: refinement termination, dropped or insignificant modes.
  std::string termination = "converged";  // as RefinementSummary; "converged" for prony-svd
  int iterations = 0;
  std::vector<std::string> warnings;
};

// The `identify` JSON of docs/interfaces, field for field, plus optional fields:
// per mode std_frequency_hz, std_decay_rate_per_s, significance, significant; top level
// start_time_s, decimation, significance_threshold, offset, noise_std, termination, iterations,
// spectrum_peaks, stabilization, eq2_coefficients, warnings. Non-finite numbers (a non-decaying
// mode's half life, an uncomputed std) become null.
nlohmann::json ModalResultToJson(const ModalResult& result);

// The /identification group: attributes method, channels; scalars sample_interval_s,
// samples, model_order, effective_rank, start_time_s, decimation; /identification/modes with
// one vector per quantity (names as in the JSON, units attributes) and amplitude/<channel>,
// phase_rad/<channel>; correlation/<channel>, offset/<channel>, noise_std/<channel>;
// reconstruction/time and reconstruction/<channel>; spectrum/frequency_hz,
// spectrum/<channel>, spectrum/peaks_*; stabilization/order, frequency_hz, decay_rate_per_s,
// damping_ratio, stable (one row per pole); eq2_coefficients.
// `group` other than /identification: a further test's result in the same layout.
void WriteModalResult(H5Writer& writer, const ModalResult& result,
                      const std::string& group = "/identification");

}  // namespace mbid::identification
