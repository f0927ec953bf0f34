#include "mbid/identification/significance.h"

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <limits>

#include "mbid/common/eigen_decompositions.h"

namespace mbid::identification {
namespace {

// log P(chi-square(2 m) > x) = -x/2 + log(sum_(i<m) (x/2)^i / i!), the sum in logarithms about
// its largest term (at i = x/2, or m - 1): the terms themselves overflow a double from x of about
// 1400 (the residual windows' 800 degrees of freedom met x = 5000 in the bisection below, and
// their threshold stuck at its upper end, 12 times the noise's power).
double LogChiSquareSurvival(double x, int m) {
  const double log_half_x = std::log(std::max(0.5 * x, std::numeric_limits<double>::min()));
  const int peak = std::clamp(static_cast<int>(0.5 * x), 0, m - 1);
  const double largest = peak * log_half_x - std::lgamma(peak + 1.0);
  double sum = 0;
  double log_term = 0;  // log of (x/2)^i / i!
  for (int i = 0; i < m; ++i) {
    if (i > 0) log_term += log_half_x - std::log(static_cast<double>(i));
    sum += std::exp(log_term - largest);
  }
  return -0.5 * x + largest + std::log(sum);
}

}  // namespace

Eigen::VectorXd CalcSignificance(const AmplitudeFit& fit) {
  // (Phi^T Phi)^-1 through the Jacobi-scaled Gram matrix; pseudo-inverse for exact collinearity.
  const Eigen::MatrixXd& gram = fit.gram;
  const Eigen::VectorXd scale =
      gram.diagonal().cwiseMax(std::numeric_limits<double>::min()).cwiseSqrt().cwiseInverse();
  const Eigen::MatrixXd scaled = scale.asDiagonal() * gram * scale.asDiagonal();
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(scaled);
  const Eigen::VectorXd& d = eigen.eigenvalues();
  const Eigen::VectorXd inverse_d =
      (d.array() > 1e-14 * d.maxCoeff()).select(d.cwiseInverse(), 0.0);
  const Eigen::MatrixXd inverse = scale.asDiagonal() * eigen.eigenvectors() *
                                  inverse_d.asDiagonal() * eigen.eigenvectors().transpose() *
                                  scale.asDiagonal();
  const Eigen::Index modes = fit.coefficients.rows() / 2;
  Eigen::VectorXd significance = Eigen::VectorXd::Zero(modes);
  for (Eigen::Index k = 0; k < modes; ++k) {
    const Eigen::Matrix2d block = inverse.block<2, 2>(2 * k, 2 * k);
    const Eigen::Matrix2d information = block.completeOrthogonalDecomposition().pseudoInverse();
    for (Eigen::Index c = 0; c < fit.coefficients.cols(); ++c) {
      const Eigen::Vector2d beta = fit.coefficients.block(2 * k, c, 2, 1);
      significance(k) += beta.dot(information * beta) / fit.residual_variance(c);
    }
  }
  return significance;
}

double CalcChiSquareThreshold(int m, double probability) {
  const double target = std::log(probability);
  // The survival function decreases in x: bisection.
  double low = 0;
  // Far above the mean 2 m: 50 standard deviations sqrt(4 m) beyond it.
  double high = std::max(1e4, 2.0 * m + 100 * std::sqrt(static_cast<double>(m)));
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (low + high);
    (LogChiSquareSurvival(mid, m) > target ? low : high) = mid;
  }
  return 0.5 * (low + high);
}

double CalcSignificanceThreshold(int samples, int channels, double false_alarm) {
  return CalcChiSquareThreshold(channels, false_alarm / (10.0 * std::max(samples, 1)));
}

}  // namespace mbid::identification
