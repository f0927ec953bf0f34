// The rows a simulation evaluates and those it interpolates (sample_rows.h): a free decay
// sampled far faster than its dynamics is evaluated at every stride-th sample, the rest from a
// 6-point Lagrange interpolation, against the function itself at every sample.
#include "sample_rows.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace mbid::simulation::internal {
namespace {

// The first-order matrix of one joint of undamped angular frequency w (rad/s), damping ratio
// zeta: eigenvalues of modulus w.
Eigen::MatrixXd Joint(double w, double zeta) {
  Eigen::MatrixXd jacobian(2, 2);
  jacobian << 0, 1, -w * w, -2 * zeta * w;
  return jacobian;
}

// A decaying swing of 1.5 Hz with a harmonic a tenth as large: what a nonlinear arm gives.
double Swing(double t) {
  const double w = 2 * M_PI * 1.5;
  return std::exp(-0.2 * t) * (std::cos(w * t + 0.3) + 0.1 * std::sin(2 * w * t));
}

struct Visits {
  std::vector<double> times;
  int evaluated = 0;
};

Eigen::MatrixXd SampleSwing(const SampleGrid& grid, int first_free, int stride, Visits* visits) {
  return SampleRows(grid, first_free, stride, 2, [&](double t, double* row) {
    visits->times.push_back(t);
    if (row == nullptr) return;
    ++visits->evaluated;
    row[0] = Swing(t);
    row[1] = -3 * Swing(t);
  });
}

TEST(SampleRowsTest, AFastRecordOfASlowDecayIsEvaluatedEveryStrideAndInterpolatedExactly) {
  // 20 s at 5 kHz of a 1.5 Hz swing: nodes every floor(5000 / (120 * 1.5)) = 27 samples.
  SampleGrid grid;
  grid.tau = 1.0 / 5000;
  grid.count = 100001;
  const int stride = ChooseOutputStride(grid.tau, Joint(2 * M_PI * 1.5, 0.02), true);
  EXPECT_EQ(stride, 27);
  Visits visits;
  const Eigen::MatrixXd rows = SampleSwing(grid, 0, stride, &visits);
  ASSERT_EQ(rows.rows(), grid.count);
  double error = 0;
  for (int j = 0; j < grid.count; ++j) {
    error = std::max(error, std::abs(rows(j, 0) - Swing(j * grid.tau)));
    ASSERT_NEAR(rows(j, 1), -3 * rows(j, 0), 1e-14) << j;  // the same weights in every column
  }
  // 0.0049 (w h)^6 = 1e-10 of the swing's amplitude 1.1 at w h = 2 pi / 120; its harmonic at
  // twice w errs 64 times as much at a tenth of the amplitude: 8e-10 in all.
  EXPECT_LT(error, 1e-9);
  EXPECT_GT(error, 0);  // the interpolated rows were not evaluated
  // The first two strides at every sample, then one row in 27 (and 3 nodes past the end).
  EXPECT_LE(visits.evaluated, 2 * stride + (grid.count - 2 * stride) / stride + 4);
  for (size_t k = 1; k < visits.times.size(); ++k) ASSERT_GT(visits.times[k], visits.times[k - 1]);
}

TEST(SampleRowsTest, AForcedStretchAndRowsBeforeTheRecordAreEvaluatedAtEverySample) {
  // Forced until row 500, the record from row 3000 (skipped rows are visited, not evaluated,
  // where no interpolated row needs them).
  SampleGrid grid;
  grid.tau = 1.0 / 5000;
  grid.skipped = 3000;
  grid.count = 20000;
  const int stride = 27;
  Visits visits;
  const Eigen::MatrixXd rows = SampleSwing(grid, 500, stride, &visits);
  double error = 0;
  for (int j = 0; j < grid.count; ++j) {
    error = std::max(error, std::abs(rows(j, 0) - Swing((grid.skipped + j) * grid.tau)));
  }
  EXPECT_LT(error, 1e-9);
  // Every row up to 500 + 2 strides visited, then only the nodes that serve the record's rows:
  // the first is 500 + 27 k with k = 90 (2930 + 3 strides is past row 3000).
  EXPECT_EQ(visits.times[499], 499 * grid.tau);
  EXPECT_EQ(visits.times[500 + 2 * stride], 2930 * grid.tau);
  EXPECT_LE(visits.evaluated, grid.count / stride + 10);
  // A forcing to the end: every row evaluated as it is.
  Visits forced;
  const Eigen::MatrixXd exact = SampleSwing(grid, grid.skipped + grid.count, stride, &forced);
  EXPECT_EQ(forced.evaluated, grid.count);
  for (int j = 0; j < grid.count; ++j) ASSERT_EQ(exact(j, 0), Swing((grid.skipped + j) * grid.tau));
}

TEST(SampleRowsTest, EverySampleIsEvaluatedWhereNoStrideSaves) {
  const double tau = 1.0 / 200;
  // 200 Hz for 1.5 Hz: 120 nodes per period need more than 200 / 1.5 samples.
  EXPECT_EQ(ChooseOutputStride(tau, Joint(2 * M_PI * 1.5, 0.02), true), 1);
  // A stiff joint's fast eigenvalue sets the stride, even heavily damped (overdamped: real).
  EXPECT_EQ(ChooseOutputStride(1.0 / 5000, Joint(2 * M_PI * 50, 3.0), true), 1);
  // An integrator that stops at each output time, no Jacobian, a body without any dynamics.
  EXPECT_EQ(ChooseOutputStride(1.0 / 5000, Joint(2 * M_PI * 1.5, 0.02), false), 1);
  EXPECT_EQ(ChooseOutputStride(1.0 / 5000, Eigen::MatrixXd(), true), 1);
  EXPECT_EQ(ChooseOutputStride(1.0 / 5000, Eigen::MatrixXd::Zero(2, 2), true), 1);
}

}  // namespace
}  // namespace mbid::simulation::internal
