#pragma once

#include <Eigen/Core>
#include <complex>
#include <vector>

namespace mbid::identification {

// The signal model of every estimator: a sum of damped sinusoids per channel c,
//
//   y_c(t_j) = o_c + sum_k exp(-d_k t_j) (C_ck cos(w_k t_j) - S_ck sin(w_k t_j)),  t_j = j tau,
//
// with lambda_k = -d_k + i w_k (w_k > 0) the continuous poles (eq. 4). In complex form the
// mode is a_ck mu_k^j + conj(a_ck mu_k^j) with mu_k = exp(lambda_k tau) and
// a_ck = (C_ck + i S_ck) / 2, i.e.
//
//   y_c(t) = o_c + sum_k A_ck exp(-d_k t) cos(w_k t + phi_ck),  A_ck = 2|a_ck|, phi_ck = arg a_ck,
//
// so the amplitude is the peak amplitude at t = 0 (the paper's Table 1) and t = 0 is the first
// analysed sample. This is eq. 8 of method.md with an unconstrained complex amplitude per mode
// and channel instead of a mode shape times one amplitude.

// The columns exp(-d_k t_j) cos(w_k t_j), -exp(-d_k t_j) sin(w_k t_j) for each pole k (in this
// order), then a column of ones if `with_offset`: samples x (2 K [+1]).
Eigen::MatrixXd CalcDampedSinusoidBasis(const std::vector<std::complex<double>>& lambda,
                                        double sample_interval_s, int samples, bool with_offset);

// The linear least-squares part: amplitudes for given poles.
struct AmplitudeFit {
  // (2 K [+1]) x channels: rows C_1, S_1, ..., C_K, S_K [, o] as in CalcDampedSinusoidBasis.
  Eigen::MatrixXd coefficients;
  Eigen::MatrixXd reconstruction;  // samples x channels
  // Per channel: residual sum of squares / (samples - P), at least 1e-30 of the channel's mean
  // square (a noiseless record has a tiny, not a zero, noise level).
  Eigen::VectorXd residual_variance;
  Eigen::MatrixXd gram;  // Phi^T Phi (P x P), from the QR's R

  // Peak amplitude A_ck and phase phi_ck (rad, in (-pi, pi]) of mode k in channel c.
  double Amplitude(int mode, int channel) const;
  double Phase(int mode, int channel) const;
};

// Least squares of `values` (samples x channels) on the basis of `lambda`: Householder QR, or
// column-pivoting QR if the basis is numerically rank deficient (two poles merged).
AmplitudeFit FitAmplitudes(const Eigen::MatrixXd& values, double sample_interval_s,
                           const std::vector<std::complex<double>>& lambda, bool with_offset);

// Pearson correlation per channel of a record and its reconstruction (the paper's K). A
// channel of zero variance in either gives 0.
Eigen::VectorXd CalcCorrelation(const Eigen::MatrixXd& record,
                                const Eigen::MatrixXd& reconstruction);

}  // namespace mbid::identification
