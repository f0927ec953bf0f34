#include "mbid/identification/prony_svd.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <complex>

namespace mbid::identification {
namespace {

// One damped mode y_j = A r^j cos(theta j + phi) + c, sampled at tau. It satisfies
// y_(j+2) - 2 r cos(theta) y_(j+1) + r^2 y_j + (2 r cos(theta) - 1 - r^2) c = 0,
// so eq. 3 with p = 2 has B1 = -2 r cos(theta), B2 = r^2, B0 = -(1 + B1 + B2) c, and the roots
// of mu^2 + B1 mu + B2 are r e^(+-i theta): by hand, lambda = ln(r) / tau +- i theta / tau.
struct OneModeByHand {
  double tau = 0.1;        // s
  double decay = 0.5;      // 1/s
  double frequency = 1.0;  // Hz, damped
  double offset = 0.0;
  Eigen::MatrixXd Record(int samples) const {
    Eigen::MatrixXd y(samples, 1);
    for (int j = 0; j < samples; ++j) {
      const double t = j * tau;
      y(j, 0) = 2.0 * std::exp(-decay * t) * std::cos(2 * M_PI * frequency * t + 0.3) + offset;
    }
    return y;
  }
};

TEST(PronySvdTest, OneModeOrderTwoByHand) {
  const OneModeByHand mode;
  const double r = std::exp(-mode.decay * mode.tau);
  const double theta = 2 * M_PI * mode.frequency * mode.tau;
  const PronySvdSolution solution =
      SolvePronySvd(mode.Record(50), mode.tau, /*order=*/2, /*rank_tolerance=*/1e-12);
  // X = [y_(j+1) y_j 1] has full rank 3 (a decaying cosine is not constant).
  EXPECT_EQ(solution.effective_rank, 3);
  EXPECT_NEAR(solution.B(0, 0), -2 * r * std::cos(theta), 1e-12);  // B1
  EXPECT_NEAR(solution.B(0, 1), r * r, 1e-12);                     // B2
  EXPECT_NEAR(solution.B0(0), 0.0, 1e-12);                         // no offset
  ASSERT_EQ(solution.lambda.size(), 2u);
  const std::complex<double> expected(std::log(r) / mode.tau, theta / mode.tau);  // eq. 4
  const auto upper = std::max_element(
      solution.lambda.begin(), solution.lambda.end(),
      [](std::complex<double> a, std::complex<double> b) { return a.imag() < b.imag(); });
  EXPECT_NEAR(std::abs(*upper - expected), 0.0, 1e-10);
  EXPECT_NEAR(upper->real(), -0.5, 1e-10);      // -decay
  EXPECT_NEAR(upper->imag(), 2 * M_PI, 1e-10);  // 1 Hz

  // Eq. 5 for one channel and one mode (p = 2 n / m = 2): lambda^2 + A1 lambda + A2 = 0 with
  // roots -d +- i w, so A1 = 2 d = 1 and A2 = d^2 + w^2.
  const Eigen::MatrixXd a = CalcEq2Coefficients({*upper}, {Eigen::VectorXcd::Ones(1)});
  ASSERT_EQ(a.rows(), 1);
  ASSERT_EQ(a.cols(), 2);
  EXPECT_NEAR(a(0, 0), 2 * 0.5, 1e-9);
  EXPECT_NEAR(a(0, 1), 0.25 + 4 * M_PI * M_PI, 1e-8);
}

TEST(PronySvdTest, ConstantTermCarriesTheOffset) {
  OneModeByHand mode;
  mode.offset = 0.7;
  const PronySvdSolution solution = SolvePronySvd(mode.Record(50), mode.tau, 2, 1e-12);
  // B0 = -(1 + B1 + B2) c (see OneModeByHand).
  const double b1 = solution.B(0, 0);
  const double b2 = solution.B(0, 1);
  EXPECT_NEAR(solution.B0(0), -(1 + b1 + b2) * 0.7, 1e-10);
  EXPECT_NEAR(b2, std::exp(-2 * mode.decay * mode.tau), 1e-10);  // the poles ignore the offset
}

TEST(PronySvdTest, TruncatedRankGivesTheMinimumNormSolution) {
  // Two modes in one channel, p = 10: the 11 columns of X span only 2 x 2 + 1 = 5 directions
  // (each mode's two, the constant). Step 3 keeps those 5, and the signal roots are exact.
  const double tau = 0.05;
  Eigen::MatrixXd y(400, 1);
  for (int j = 0; j < 400; ++j) {
    const double t = j * tau;
    y(j, 0) = std::exp(-0.3 * t) * std::cos(2 * M_PI * 1.2 * t) +
              0.4 * std::exp(-1.1 * t) * std::sin(2 * M_PI * 3.1 * t);
  }
  const PronySvdSolution solution = SolvePronySvd(y, tau, 10, 1e-9);
  EXPECT_EQ(solution.effective_rank, 5);
  for (const std::complex<double> expected :
       {std::complex<double>(-0.3, 2 * M_PI * 1.2), std::complex<double>(-1.1, 2 * M_PI * 3.1)}) {
    double nearest = 1e9;
    for (const auto& lambda : solution.lambda)
      nearest = std::min(nearest, std::abs(lambda - expected));
    EXPECT_LT(nearest / std::abs(expected), 1e-7) << expected;  // measured ~1e-10
  }
  // Kumaresan-Tufts: the other roots of the minimum-norm predictor lie inside the unit circle.
  for (const auto& mu : solution.mu) EXPECT_LE(std::abs(mu), 1.0 + 1e-9);
}

TEST(PronySvdTest, Eq5RecoversTheMatricesOfAFullyObservedSystem) {
  // With every coordinate observed (m = n = 2, H = I), eq. 2 is M^-1 of eq. 1:
  // A1 = M^-1 D and A2 = M^-1 C. Eq. 5 must recover them from the poles and mode shapes alone.
  Eigen::Matrix2d m, d, c;
  m << 2.0, 0.3, 0.3, 1.0;
  d << 0.4, -0.1, -0.1, 0.2;
  c << 50.0, -10.0, -10.0, 30.0;
  Eigen::Matrix4d state = Eigen::Matrix4d::Zero();
  state.topRightCorner<2, 2>().setIdentity();
  state.bottomLeftCorner<2, 2>() = -m.inverse() * c;
  state.bottomRightCorner<2, 2>() = -m.inverse() * d;
  Eigen::EigenSolver<Eigen::Matrix4d> eigen(state);
  std::vector<std::complex<double>> lambda;
  std::vector<Eigen::VectorXcd> w;
  for (int i = 0; i < 4; ++i) {
    if (eigen.eigenvalues()(i).imag() > 0) {
      lambda.push_back(eigen.eigenvalues()(i));
      w.push_back(eigen.eigenvectors().col(i).head(2) * std::complex<double>(0.3, -1.7));
    }
  }
  ASSERT_EQ(lambda.size(), 2u);                              // underdamped: two pairs
  const Eigen::MatrixXd a = CalcEq2Coefficients(lambda, w);  // the scaling of w is irrelevant
  ASSERT_EQ(a.rows(), 2);
  ASSERT_EQ(a.cols(), 4);  // p = 2 n / m = 2
  EXPECT_LT((a.leftCols(2) - m.inverse() * d).norm(), 1e-10);
  EXPECT_LT((a.rightCols(2) - m.inverse() * c).norm(), 1e-9);
}

}  // namespace
}  // namespace mbid::identification
