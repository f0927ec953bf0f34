#pragma once

#include <Eigen/Core>
#include <complex>
#include <memory>
#include <vector>

namespace mbid::identification {

class SymmetricEigen;

// The multichannel matrix pencil (Kumaresan-Tufts / Hua-Sarkar style) behind the default
// method's initialization. Each channel c gives a Hankel matrix with L + 1 columns,
// Y_c[i][j] = y_c[i + j] (i = 0..N-L-1), whose rows lie in the span of the vectors
// [1, mu_k, ..., mu_k^L] of the signal's discrete poles. The channels are stacked, each
// divided by its own noise level, and the right singular vectors V of the stack give the
// poles at order M: the eigenvalues of V1^+ V2, where V1 and V2 are the first and last L rows
// of the M leading singular vectors (shift invariance).
//
// The SVD is taken through the (L+1) x (L+1) Gram matrix sum_c Y_c^T Y_c / floor_c, built in
// O(N L) per channel by a diagonal recurrence: the eigenvalues are the squared singular
// values. Squaring costs accuracy only in the smallest singular values, which the refinement
// does not need. floor_c is the median of the channel's trailing eigenvalues (one Sturm
// bisection); only the leading singular vectors that CalcPoles uses are computed.
class HankelSvd {
 public:
  // values: samples x channels, offset already removed. columns = L + 1 (>= 2,
  // < samples). `max_signal_order` bounds the signal subspace: the noise floor is the median of
  // the squared singular values beyond it.
  HankelSvd(const Eigen::MatrixXd& values, int columns, int max_signal_order);
  ~HankelSvd();
  HankelSvd(const HankelSvd&) = delete;
  HankelSvd& operator=(const HankelSvd&) = delete;

  int columns() const { return static_cast<int>(singular_values_.size()); }
  // Of the stacked, noise-normalized Hankel matrix, descending; noise gives about
  // sqrt(noise_floor()) each.
  const Eigen::VectorXd& singular_values() const { return singular_values_; }
  // The median of the squared singular values beyond max_signal_order.
  double noise_floor() const { return noise_floor_; }
  // Noise standard deviation per channel, from the median eigenvalue of the channel's own
  // Gram matrix: sqrt(median / rows). Biased by a few percent, by the same factor for every
  // channel, so good as relative weights.
  const Eigen::VectorXd& channel_noise_std() const { return channel_noise_std_; }

  // (1 + sqrt(c))^2 for the aspect ratio c = columns / (channels * rows): the largest squared
  // singular value of white noise relative to the typical one (Marchenko-Pastur).
  double noise_edge() const { return noise_edge_; }

  // The number of squared singular values above noise_floor_factor * noise_edge() *
  // noise_floor() and above (min_relative * largest singular value)^2, at most max_order.
  int CountSignal(double noise_floor_factor, double min_relative, int max_order) const;

  // The discrete poles mu at order M (1 <= M < columns()). The singular vectors are computed
  // on first use, as many as the highest order asked so far (not thread-safe).
  std::vector<std::complex<double>> CalcPoles(int order) const;

 private:
  // V1^T V1 and V1^T V2 of the leading singular vectors, extended to `order` columns.
  void ExtendShiftProducts(const Eigen::Ref<const Eigen::MatrixXd>& v, int order) const;

  Eigen::VectorXd singular_values_;
  std::unique_ptr<SymmetricEigen> eigen_;  // of the Gram matrix
  // The leading M x M blocks are the normal equations of every order M (ExtendShiftProducts).
  mutable Eigen::MatrixXd shift_gram_, shift_cross_;
  Eigen::VectorXd channel_noise_std_;
  double noise_floor_ = 0;
  double noise_edge_ = 1;
};

}  // namespace mbid::identification
