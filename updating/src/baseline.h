#pragma once

#include <Eigen/Core>

namespace mbid::updating {

// The nuisance baseline of one record's channels: a constant offset o (sensor zero error) and,
// optionally, a drift g, so that record = simulation + o + g t, t from the excitation's t = 0
// (the release). Both enter linearly, so the fit eliminates them exactly (variable projection):
// each channel's residual and Jacobian are projected orthogonal to the columns [1] or [1, t]
// over the record's samples. With one weight per channel that projection is the weighted one,
// the projected residual is the residual at the best offsets for any parameters, and its
// Jacobian is the projected Jacobian exactly (the basis does not depend on the parameters).
class Baseline {
 public:
  // terms: 0 (nothing), 1 (offset) or 2 (offset and drift); time_s: the record's sample times.
  Baseline(const Eigen::VectorXd& time_s, int terms);

  int terms() const { return terms_; }
  int samples() const { return static_cast<int>(time_s_.size()); }

  // Removes from the `samples()` values data[j * stride] their least-squares fit by the basis.
  void Project(double* data, int stride) const;

  // The least-squares coefficients [o, g] (terms() of them) of `difference` (record minus
  // simulation, samples() values at data[j * stride]).
  Eigen::VectorXd Fit(const double* data, int stride) const;
  // The baseline o + g t_j with `coefficients` from Fit().
  Eigen::VectorXd Evaluate(const Eigen::VectorXd& coefficients) const;

  // (B^T B)^-1 of the basis B = [1, t] (terms() square): the coefficients' covariance per unit
  // noise variance when the simulation is known.
  Eigen::MatrixXd CalcInverseGram() const;
  // (B^T B)^-1 B^T S for a matrix S of `columns` columns whose rows j sit at
  // data[j * row_stride + column * column_stride]: how the coefficients of a difference move
  // when the simulation moves by S.
  Eigen::MatrixXd CalcRegression(const double* data, int row_stride, int column_stride,
                                 int columns) const;

 private:
  Eigen::VectorXd time_s_;
  int terms_ = 0;
  double mean_time_s_ = 0;
  double centered_norm_ = 0;  // |t - mean t|: the orthonormal basis is 1/sqrt(N), (t - mean) / it
};

}  // namespace mbid::updating
