#include "mbid/identification/hankel_svd.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <complex>
#include <random>
#include <vector>

#include "mbid/common/eigen_decompositions.h"
#include "signals.h"

namespace mbid::identification {
namespace {

// The stacked, noise-normalized Hankel matrix built directly (the Gram-matrix route of
// HankelSvd must give its SVD): channel c's block divided by sqrt(rows) * noise_std(c), the
// floor HankelSvd normalizes with.
Eigen::MatrixXd StackedHankel(const Eigen::MatrixXd& y, int columns,
                              const Eigen::VectorXd& noise_std) {
  const int rows = static_cast<int>(y.rows()) - columns + 1;
  Eigen::MatrixXd stacked(rows * y.cols(), columns);
  for (Eigen::Index c = 0; c < y.cols(); ++c) {
    const double scale = 1.0 / (std::sqrt(static_cast<double>(rows)) * noise_std(c));
    for (int i = 0; i < rows; ++i) {
      stacked.row(c * rows + i) = y.col(c).segment(i, columns).transpose() * scale;
    }
  }
  return stacked;
}

// Poles at `order` from the dense SVD, as HankelSvd computes them from its vectors.
std::vector<std::complex<double>> DensePoles(const Eigen::MatrixXd& stacked, int order) {
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(stacked, Eigen::ComputeThinV);
  const Eigen::MatrixXd v = svd.matrixV().leftCols(order);
  const Eigen::Index l = v.rows() - 1;
  const Eigen::MatrixXd z = v.topRows(l).colPivHouseholderQr().solve(v.bottomRows(l));
  Eigen::EigenSolver<Eigen::MatrixXd> eigen(z, false);
  return {eigen.eigenvalues().data(), eigen.eigenvalues().data() + order};
}

double Distance(const std::vector<std::complex<double>>& a,
                const std::vector<std::complex<double>>& b) {
  double worst = 0;
  for (const auto& x : a) {
    double nearest = 1e300;
    for (const auto& y : b) nearest = std::min(nearest, std::abs(x - y));
    worst = std::max(worst, nearest);
  }
  return worst;
}

TEST(HankelSvdTest, MatchesTheDenseSvdWithNoise) {
  const testing::SignalSpec spec = testing::PaperSignal();
  const Eigen::MatrixXd clean = testing::Synthesize(spec);
  std::mt19937_64 rng(8);  // seeded: deterministic
  const Eigen::VectorXd noise_std = testing::NoiseStd(clean, 30);
  const Eigen::MatrixXd y = testing::AddNoise(clean, noise_std, &rng);
  constexpr int kColumns = 60;  // small enough for a dense Jacobi SVD in a unit test
  const HankelSvd hankel(y, kColumns, /*max_signal_order=*/20);
  // The median-of-the-tail noise estimate is close to the true level (the median of the
  // Marchenko-Pastur law is a few percent below its mean; 15 % covers that and the draw).
  for (int c = 0; c < 2; ++c) EXPECT_NEAR(hankel.channel_noise_std()(c) / noise_std(c), 1.0, 0.15);

  const Eigen::MatrixXd stacked = StackedHankel(y, kColumns, hankel.channel_noise_std());
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(stacked);
  const Eigen::VectorXd& dense = svd.singularValues();
  // Squared through the Gram matrix: the relative error of s_i is about eps s_1^2 / s_i^2.
  for (int i = 0; i < 20; ++i) {
    EXPECT_NEAR(hankel.singular_values()(i) / dense(i), 1.0, 1e-9) << i;
  }
  // Four modes: eight singular values above the noise.
  EXPECT_EQ(hankel.CountSignal(1.5, 1e-7, 41), 8);
  // Poles at the signal order and at orders well into the noise (their vectors come from
  // inverse iteration on clustered eigenvalues) agree with the dense SVD's.
  for (int order : {8, 12, 20}) {
    EXPECT_LT(Distance(hankel.CalcPoles(order), DensePoles(stacked, order)), 1e-6) << order;
  }
}

TEST(HankelSvdTest, PolesOfEveryOrderInAnyOrderOfAsking) {
  // The normal equations of every order are leading blocks of products extended as orders are
  // asked for: asking from the highest down, or out of order, must give the dense SVD's poles.
  // With 8 columns the last row of V carries most of its norm at orders 6 and 7
  // (|w|^2 ~ order / 8 > 1/2): those orders take the QR of V1 instead.
  const testing::SignalSpec spec = testing::PaperSignal();
  const Eigen::MatrixXd clean = testing::Synthesize(spec);
  std::mt19937_64 rng(9);  // seeded: deterministic
  const Eigen::MatrixXd y = testing::AddNoise(clean, testing::NoiseStd(clean, 30), &rng);
  for (int columns : {60, 8}) {
    const HankelSvd hankel(y, columns, /*max_signal_order=*/std::min(20, columns / 2));
    const Eigen::MatrixXd stacked = StackedHankel(y, columns, hankel.channel_noise_std());
    const std::vector<int> orders =
        columns == 60 ? std::vector<int>{20, 8, 13, 3, 20} : std::vector<int>{7, 2, 6, 5};
    for (int order : orders) {
      // 1e-6: as above (vectors of clustered noise eigenvalues by inverse iteration).
      EXPECT_LT(Distance(hankel.CalcPoles(order), DensePoles(stacked, order)), 1e-6)
          << columns << " columns, order " << order;
    }
  }
}

TEST(HankelSvdTest, NoiselessPolesAreExact) {
  const testing::SignalSpec spec = testing::PaperSignal();
  const HankelSvd hankel(testing::Synthesize(spec), 100, 41);
  EXPECT_EQ(hankel.CountSignal(1.5, 1e-7, 41), 8);  // the floor is round-off
  const auto mu = hankel.CalcPoles(8);
  for (const auto& mode : spec.modes) {
    const std::complex<double> expected =
        std::exp(std::complex<double>(-mode.decay_per_s, 2 * M_PI * mode.frequency_hz) *
                 spec.sample_interval_s);
    double nearest = 1e300;
    for (const auto& z : mu) nearest = std::min(nearest, std::abs(z - expected));
    EXPECT_LT(nearest, 1e-9) << mode.frequency_hz;  // initialization only; measured ~1e-12
  }
}

}  // namespace
}  // namespace mbid::identification
