#pragma once

// Synthetic free-decay records for the identification tests and benchmark: sums of damped
// sinusoids written directly as A exp(-d t) cos(omega t + phi) (not through the library), white
// Gaussian noise at a given SNR per channel, and the Cramer-Rao bound of the poles computed
// from the Fisher matrix of that signal model.

#include <Eigen/Dense>
#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "mbid/common/measurement.h"

namespace mbid::testing {

struct TrueMode {
  double frequency_hz;  // damped
  double decay_per_s;
  std::vector<double> amplitude;  // per channel, peak at t = 0
  std::vector<double> phase_rad;  // per channel
};

struct SignalSpec {
  std::vector<TrueMode> modes;
  std::vector<std::string> channels;
  double sample_interval_s;
  int samples;
  std::vector<double> offset;  // per channel; empty: none
};

inline Eigen::MatrixXd Synthesize(const SignalSpec& spec) {
  const int m = static_cast<int>(spec.channels.size());
  Eigen::MatrixXd y = Eigen::MatrixXd::Zero(spec.samples, m);
  for (int j = 0; j < spec.samples; ++j) {
    const double t = j * spec.sample_interval_s;
    for (int c = 0; c < m; ++c) {
      double value = spec.offset.empty() ? 0.0 : spec.offset[c];
      for (const TrueMode& mode : spec.modes) {
        value += mode.amplitude[c] * std::exp(-mode.decay_per_s * t) *
                 std::cos(2 * M_PI * mode.frequency_hz * t + mode.phase_rad[c]);
      }
      y(j, c) = value;
    }
  }
  return y;
}

// Noise standard deviation per channel for a signal-to-noise ratio in dB, with the signal
// power the mean square of the noiseless channel over the record.
inline Eigen::VectorXd NoiseStd(const Eigen::MatrixXd& clean, double snr_db) {
  Eigen::VectorXd std(clean.cols());
  for (Eigen::Index c = 0; c < clean.cols(); ++c) {
    std(c) = std::sqrt(clean.col(c).squaredNorm() / clean.rows()) / std::pow(10.0, snr_db / 20);
  }
  return std;
}

inline Eigen::MatrixXd AddNoise(const Eigen::MatrixXd& clean, const Eigen::VectorXd& noise_std,
                                std::mt19937_64* rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::MatrixXd noisy = clean;
  for (Eigen::Index c = 0; c < clean.cols(); ++c) {
    for (Eigen::Index j = 0; j < clean.rows(); ++j) noisy(j, c) += noise_std(c) * normal(*rng);
  }
  return noisy;
}

// `spec` synthesized with white Gaussian noise of `noise_std` per channel, drawn from `seed`.
inline Eigen::MatrixXd SynthesizeNoisy(const SignalSpec& spec, const Eigen::VectorXd& noise_std,
                                       std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  return AddNoise(Synthesize(spec), noise_std, &rng);
}

// An aerial platform's load drop (200 Hz, 6 s, an inclinometer, two accelerometers and a gyro):
// its 0.96 Hz luffing and 6.7 Hz modes and its boom's two bending modes 7.83 and 8.46 Hz at 11
// and 15 % damping (0.63 Hz apart against half-power bandwidths of 1.8 and 2.5 Hz) with
// different shapes, their largest amplitude `boom_amplitude`.
inline SignalSpec PlatformWithCloseModes(double boom_amplitude) {
  const double b = boom_amplitude;
  SignalSpec spec;
  spec.channels = {"incl", "acc_y", "acc_z", "gyro"};
  spec.sample_interval_s = 0.005;
  spec.samples = 1201;
  spec.modes = {{0.9595, 0.109, {1.0, 1.0, 1.0, 1.0}, {0.0, 0.1, 0.2, 0.3}},
                {6.697, 4.43, {0.1, 0.3, 0.3, 0.05}, {0.0, 0.5, 1.0, 0.2}},
                {7.826, 5.57, {b / 8, b, b / 4, b / 2}, {0.0, 0.3, 2.0, 1.0}},
                {8.464, 7.94, {b / 8, b / 4, b, b / 2}, {1.5, 0.0, 0.4, -2.0}}};
  return spec;
}

inline Measurement MakeRecord(const SignalSpec& spec, const Eigen::MatrixXd& values) {
  Measurement m;
  m.channels = spec.channels;
  m.units.assign(spec.channels.size(), "rad");
  m.sample_interval_s = spec.sample_interval_s;
  m.values = values;
  m.source = "test";
  return m;
}

// Cramer-Rao bound of (decay, omega) of every mode for white Gaussian noise of std
// noise_std(c) per channel: the diagonal of the inverse Fisher matrix
// F = sum_c J_c^T J_c / sigma_c^2, J_c the derivative of channel c with respect to all
// parameters (per mode: d, omega, then amplitude and phase per channel), by central
// differences of Synthesize (step 1e-6 relative: the truncation error of a central difference
// of these smooth functions is ~1e-12, far below what the 1.3x comparison needs).
// Returns per mode {std of decay (1/s), std of frequency (Hz)}.
inline std::vector<std::pair<double, double>> CramerRaoBound(const SignalSpec& spec,
                                                             const Eigen::VectorXd& noise_std) {
  const int m = static_cast<int>(spec.channels.size());
  const int k_modes = static_cast<int>(spec.modes.size());
  const int per_mode = 2 + 2 * m;
  const int parameters = k_modes * per_mode;
  Eigen::MatrixXd fisher = Eigen::MatrixXd::Zero(parameters, parameters);
  // Column p of the stacked, noise-weighted Jacobian.
  std::vector<Eigen::MatrixXd> columns;
  for (int p = 0; p < parameters; ++p) {
    const int k = p / per_mode;
    const int which = p % per_mode;
    auto perturbed = [&](double sign) {
      SignalSpec s = spec;
      TrueMode& mode = s.modes[k];
      double* value = nullptr;
      if (which == 0) value = &mode.decay_per_s;
      if (which == 1) value = &mode.frequency_hz;
      if (which >= 2 && which < 2 + m) value = &mode.amplitude[which - 2];
      if (which >= 2 + m) value = &mode.phase_rad[which - 2 - m];
      const double h = 1e-6 * std::max(1.0, std::abs(*value));
      *value += sign * h;
      return std::make_pair(Synthesize(s), h);
    };
    const auto [plus, h] = perturbed(+1);
    const auto [minus, h2] = perturbed(-1);
    Eigen::MatrixXd column = (plus - minus) / (2 * h);
    for (int c = 0; c < m; ++c) column.col(c) /= noise_std(c);
    columns.push_back(column);
  }
  for (int a = 0; a < parameters; ++a) {
    for (int b = 0; b <= a; ++b) {
      fisher(a, b) = fisher(b, a) = (columns[a].array() * columns[b].array()).sum();
    }
  }
  const Eigen::MatrixXd covariance = fisher.inverse();
  std::vector<std::pair<double, double>> bound;
  for (int k = 0; k < k_modes; ++k) {
    bound.emplace_back(std::sqrt(covariance(k * per_mode, k * per_mode)),
                       std::sqrt(covariance(k * per_mode + 1, k * per_mode + 1)));
  }
  return bound;
}

// The paper's Table 1 (method.md): four modes in psi and phi, sampled at 100 Hz for 10 s as in
// issue 4. The paper gives no phases; these are arbitrary, distinct and not multiples of pi/2.
inline SignalSpec PaperSignal() {
  SignalSpec spec;
  spec.channels = {"psi", "phi"};
  spec.sample_interval_s = 0.01;
  spec.samples = 1000;
  spec.modes = {{1.155, 6.77, {0.0112, 0.0055}, {0.3, -0.5}},
                {2.169, 1.52, {0.0046, 0.0008}, {1.1, 2.0}},
                {3.179, 3.67, {0.0010, 0.0062}, {-2.2, 0.7}},
                {3.766, 1.98, {0.0035, 0.0069}, {2.6, -1.3}}};
  return spec;
}

// Whether one of `lines` (warnings, reasons) contains `what`.
inline bool Mentions(const std::vector<std::string>& lines, const std::string& what) {
  for (const std::string& line : lines) {
    if (line.find(what) != std::string::npos) return true;
  }
  return false;
}

// A trial's decay: 2 Hz at 1 % and 7 Hz at 2 % damping (half the amplitude), one channel, 30 s
// at 100 Hz.
inline SignalSpec TwoAndSevenHertzDecay() {
  SignalSpec spec;
  spec.channels = {"x"};
  spec.sample_interval_s = 0.01;
  spec.samples = 3000;
  spec.modes = {{2.0 * std::sqrt(1 - 0.01 * 0.01), 0.01 * 2 * M_PI * 2, {1.0}, {0.4}},
                {7.0 * std::sqrt(1 - 0.02 * 0.02), 0.02 * 2 * M_PI * 7, {0.5}, {1.3}}};
  return spec;
}

// Two channels: a light mode (`light_hz`, `light_decay_per_s`; amplitudes 1 and `light_b`) and
// a heavily damped one (natural `heavy_hz`, damping ratio `heavy_zeta`; amplitudes 1 and -1),
// as a machine's ring-down with a fast-decaying part.
inline SignalSpec LightBesideHeavy(double light_hz, double light_decay_per_s, double light_b,
                                   double heavy_hz, double heavy_zeta, double interval_s,
                                   int samples) {
  SignalSpec spec;
  spec.channels = {"a", "b"};
  spec.sample_interval_s = interval_s;
  spec.samples = samples;
  const double omega = 2 * M_PI * heavy_hz;
  spec.modes = {{light_hz, light_decay_per_s, {1.0, light_b}, {0.0, 0.0}},
                {omega * std::sqrt(1 - heavy_zeta * heavy_zeta) / (2 * M_PI),
                 heavy_zeta * omega,
                 {1.0, 1.0},
                 {0.0, M_PI}}};
  return spec;
}

}  // namespace mbid::testing
