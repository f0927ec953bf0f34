#include "mbid/identification/modal_fit.h"

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <limits>

#include "internal.h"

namespace mbid::identification {

void FillDampedSinusoidBasis(const std::vector<std::complex<double>>& lambda,
                             double sample_interval_s, bool with_offset, int samples,
                             Eigen::MatrixXd* basis) {
  const int modes = static_cast<int>(lambda.size());
  basis->resize(samples, 2 * modes + (with_offset ? 1 : 0));
  for (int k = 0; k < modes; ++k) {
    double* cos_column = basis->col(2 * k).data();
    double* sin_column = basis->col(2 * k + 1).data();
    ForEachModeSample(lambda[k], sample_interval_s, 0, samples, [&](int j, std::complex<double> z) {
      cos_column[j] = z.real();
      sin_column[j] = -z.imag();
    });
  }
  if (with_offset) basis->col(2 * modes).setOnes();
}

Eigen::MatrixXd CalcDampedSinusoidBasis(const std::vector<std::complex<double>>& lambda,
                                        double sample_interval_s, int samples, bool with_offset) {
  Eigen::MatrixXd basis;
  FillDampedSinusoidBasis(lambda, sample_interval_s, with_offset, samples, &basis);
  return basis;
}

double AmplitudeFit::Amplitude(int mode, int channel) const {
  return std::hypot(coefficients(2 * mode, channel), coefficients(2 * mode + 1, channel));
}

double AmplitudeFit::Phase(int mode, int channel) const {
  return std::atan2(coefficients(2 * mode + 1, channel), coefficients(2 * mode, channel));
}

AmplitudeFit FitAmplitudes(const Eigen::MatrixXd& values, double sample_interval_s,
                           const std::vector<std::complex<double>>& lambda, bool with_offset) {
  const Eigen::MatrixXd basis = CalcDampedSinusoidBasis(
      lambda, sample_interval_s, static_cast<int>(values.rows()), with_offset);
  const Eigen::Index p = basis.cols();
  AmplitudeFit fit;
  // The blocked Householder QR is several times faster on long records; it needs full rank.
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(basis);
  const Eigen::VectorXd diagonal = qr.matrixQR().diagonal().head(p).cwiseAbs();
  if (p == 0 || diagonal.minCoeff() > 1e-12 * diagonal.maxCoeff()) {
    fit.coefficients = qr.solve(values);
    const Eigen::MatrixXd r = qr.matrixQR().topLeftCorner(p, p).triangularView<Eigen::Upper>();
    fit.gram = r.transpose() * r;
  } else {
    const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> pivoting(basis);
    fit.coefficients = pivoting.solve(values);
    const Eigen::MatrixXd r = pivoting.matrixR().topLeftCorner(p, p).triangularView<Eigen::Upper>();
    const auto permutation = pivoting.colsPermutation();
    fit.gram = permutation * (r.transpose() * r) * permutation.transpose();
  }
  fit.reconstruction = basis * fit.coefficients;
  const double dof = std::max<double>(1.0, static_cast<double>(values.rows() - p));
  const Eigen::VectorXd mean_square = values.colwise().squaredNorm().transpose() / values.rows();
  fit.residual_variance = ((values - fit.reconstruction).colwise().squaredNorm().transpose() / dof)
                              .cwiseMax(1e-30 * mean_square)
                              .cwiseMax(std::numeric_limits<double>::min());
  return fit;
}

Eigen::VectorXd CalcCorrelation(const Eigen::MatrixXd& record,
                                const Eigen::MatrixXd& reconstruction) {
  Eigen::VectorXd correlation(record.cols());
  for (Eigen::Index c = 0; c < record.cols(); ++c) {
    const Eigen::VectorXd a = record.col(c).array() - record.col(c).mean();
    const Eigen::VectorXd b = reconstruction.col(c).array() - reconstruction.col(c).mean();
    const double denominator = a.norm() * b.norm();
    correlation(c) = denominator > 0 ? a.dot(b) / denominator : 0.0;
  }
  return correlation;
}

}  // namespace mbid::identification
