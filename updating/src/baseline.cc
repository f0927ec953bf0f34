#include "baseline.h"

#include <Eigen/Dense>
#include <cmath>
#include <stdexcept>

namespace mbid::updating {

Baseline::Baseline(const Eigen::VectorXd& time_s, int terms) : time_s_(time_s), terms_(terms) {
  if (terms < 0 || terms > 2 || time_s.size() < terms + 1) {
    throw std::invalid_argument("Baseline: 0 to 2 terms and more samples than terms");
  }
  mean_time_s_ = time_s.mean();
  centered_norm_ = (time_s.array() - mean_time_s_).matrix().norm();
}

void Baseline::Project(double* data, int stride) const {
  if (terms_ == 0) return;
  Eigen::Map<Eigen::VectorXd, 0, Eigen::InnerStride<>> v(data, samples(),
                                                         Eigen::InnerStride<>(stride));
  // Orthonormal columns: projections subtract independently (centred t is orthogonal to 1).
  v.array() -= v.mean();
  if (terms_ == 2) {
    const Eigen::VectorXd q = (time_s_.array() - mean_time_s_) / centered_norm_;
    v -= q * q.dot(v);
  }
}

Eigen::VectorXd Baseline::Fit(const double* data, int stride) const {
  const Eigen::Map<const Eigen::VectorXd, 0, Eigen::InnerStride<>> v(data, samples(),
                                                                     Eigen::InnerStride<>(stride));
  Eigen::VectorXd coefficients(terms_);
  if (terms_ == 0) return coefficients;
  const double mean = v.mean();
  if (terms_ == 1) {
    coefficients[0] = mean;
    return coefficients;
  }
  const double slope =
      (time_s_.array() - mean_time_s_).matrix().dot(v) / (centered_norm_ * centered_norm_);
  coefficients << mean - slope * mean_time_s_, slope;
  return coefficients;
}

Eigen::VectorXd Baseline::Evaluate(const Eigen::VectorXd& coefficients) const {
  Eigen::VectorXd baseline = Eigen::VectorXd::Zero(samples());
  if (terms_ >= 1) baseline.array() += coefficients[0];
  if (terms_ == 2) baseline += coefficients[1] * time_s_;
  return baseline;
}

Eigen::MatrixXd Baseline::CalcInverseGram() const {
  Eigen::MatrixXd basis(samples(), terms_);
  if (terms_ >= 1) basis.col(0).setOnes();
  if (terms_ == 2) basis.col(1) = time_s_;
  return (basis.transpose() * basis).inverse();
}

Eigen::MatrixXd Baseline::CalcRegression(const double* data, int row_stride, int column_stride,
                                         int columns) const {
  Eigen::MatrixXd regression(terms_, columns);
  for (int k = 0; k < columns; ++k) {
    regression.col(k) = Fit(data + static_cast<std::ptrdiff_t>(k) * column_stride, row_stride);
  }
  return regression;
}

}  // namespace mbid::updating
