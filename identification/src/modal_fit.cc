#include "mbid/identification/modal_fit.h"

#include <Eigen/QR>
#include <algorithm>
#include <cmath>

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
  AmplitudeFit fit;
  fit.coefficients = basis.colPivHouseholderQr().solve(values);
  fit.reconstruction = basis * fit.coefficients;
  const double dof = std::max<double>(1.0, static_cast<double>(values.rows() - basis.cols()));
  fit.residual_variance = (values - fit.reconstruction).colwise().squaredNorm().transpose() / dof;
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
