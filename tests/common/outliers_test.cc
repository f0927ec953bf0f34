// Glitches found where a sample jumps off a channel's course, and nowhere else: smooth decays,
// fast or slow, noisy or not.
#include "mbid/common/outliers.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace mbid {
namespace {

using ::testing::HasSubstr;

// `frequency_hz` at `damping` ratio, 8 s at 100 Hz, amplitude 1, white noise of `noise` (seeded).
Eigen::VectorXd Decay(double frequency_hz, double damping, double noise) {
  std::mt19937_64 generator(5);
  std::normal_distribution<double> gaussian(0.0, noise);
  Eigen::VectorXd y(801);
  const double w = 2 * M_PI * frequency_hz;
  for (Eigen::Index j = 0; j < y.size(); ++j) {
    const double t = 0.01 * static_cast<double>(j);
    y[j] = std::exp(-damping * w * t) * std::cos(w * t) + gaussian(generator);
  }
  return y;
}

TEST(OutliersTest, SmoothDecaysHaveNone) {
  // The reference crane's range of modes: 0.58 Hz at 25 % (down to 1e-3 of its start in 4 s,
  // where a whole-record spread would call the start an outlier) to 40 Hz, near Nyquist.
  EXPECT_TRUE(FindOutliers(Decay(0.58, 0.25, 0.0)).empty());
  EXPECT_TRUE(FindOutliers(Decay(1.5, 0.05, 1e-3)).empty());
  EXPECT_TRUE(FindOutliers(Decay(40.0, 0.02, 1e-3)).empty());
  // White noise alone with a 6-sigma sample: about 7 times the spread, not a glitch.
  Eigen::VectorXd noise = Decay(1.5, 0.05, 1e-3) - Decay(1.5, 0.05, 0.0);
  noise[400] = 6e-3;
  EXPECT_TRUE(FindOutliers(noise).empty());
}

// Trial records called glitches that were none: a 40 Hz mode at 30 % damping sampled at 200 Hz
// bends the course for several samples at its start, decaying (a glitch is back within two);
// a 12-bit logger whose noise is under one step moves by 0 or 1 step, and its median second
// difference is 0 (one step was called 8e5 times the local spread). A real glitch in the
// quantized record is still found.
TEST(OutliersTest, AFastDecayAndAQuantizedRecordHaveNone) {
  Eigen::VectorXd fast(400);
  const double w = 2 * M_PI * 40 / std::sqrt(1 - 0.09);
  for (Eigen::Index j = 0; j < fast.size(); ++j) {
    const double t = 0.005 * static_cast<double>(j);
    fast[j] = std::exp(-0.3 * w * t) * std::cos(0.954 * w * t) +
              0.2 * std::exp(-0.1 * t) * std::cos(2 * M_PI * 2 * t);
  }
  EXPECT_TRUE(FindOutliers(fast).empty());
  // 1.5 Hz at 5 %, amplitude 1 on a 12-bit range of +-2 (step 2^-10), noise a fifth of a step.
  const double step = 4.0 / 4096;
  Eigen::VectorXd quantized = Decay(1.5, 0.05, 0.2 * step);
  for (Eigen::Index j = 0; j < quantized.size(); ++j) {
    quantized[j] = step * std::round(quantized[j] / step);
  }
  EXPECT_TRUE(FindOutliers(quantized).empty());
  quantized[500] += 100 * step;
  const std::vector<Outlier> glitch = FindOutliers(quantized);
  ASSERT_EQ(glitch.size(), 1u);
  EXPECT_EQ(glitch[0].sample, 500);
}

TEST(OutliersTest, AGlitchIsFoundAtItsSample) {
  Eigen::VectorXd y = Decay(1.5, 0.05, 1e-3);
  y[300] += 0.5;  // half the release amplitude, one sample
  y[600] -= 0.2;
  const std::vector<Outlier> outliers = FindOutliers(y);
  ASSERT_EQ(outliers.size(), 2u);
  EXPECT_EQ(outliers[0].sample, 300);
  EXPECT_EQ(outliers[1].sample, 600);
  EXPECT_GT(outliers[0].ratio, 30.0);
  EXPECT_THAT(OutlierReason("a_tip", outliers, 0.01, 1.0),
              HasSubstr("channel a_tip jumps off its course at 4 s ("));
  EXPECT_THAT(OutlierReason("a_tip", outliers, 0.01, 1.0), HasSubstr("and at 1 more sample"));
  // Two neighbouring samples off are one glitch.
  Eigen::VectorXd pair = Decay(1.5, 0.05, 1e-3);
  pair[300] += 0.5;
  pair[301] += 0.5;
  EXPECT_EQ(FindOutliers(pair).size(), 1u);
}

}  // namespace
}  // namespace mbid
