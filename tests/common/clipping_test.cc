// Clipping found where a channel sits at an extreme, and nowhere else: a free decay, noisy or
// not, come to rest at its end, or printed on a coarse grid.
#include "mbid/common/clipping.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace mbid {
namespace {

using ::testing::HasSubstr;

// 1.5 Hz at 5 % damping, 8 s at 100 Hz, amplitude 1, white noise of `noise` (seeded).
Eigen::VectorXd Decay(double noise) {
  std::mt19937_64 generator(3);
  std::normal_distribution<double> gaussian(0.0, noise);
  Eigen::VectorXd y(801);
  for (Eigen::Index j = 0; j < y.size(); ++j) {
    const double t = 0.01 * static_cast<double>(j);
    y[j] =
        std::exp(-0.05 * 2 * M_PI * 1.5 * t) * std::cos(2 * M_PI * 1.5 * t) + gaussian(generator);
  }
  return y;
}

TEST(ClippingTest, AFreeDecayIsNotClipped) {
  EXPECT_FALSE(FindClipping(Decay(0.0)));
  EXPECT_FALSE(FindClipping(Decay(1e-3)));
  // A creeping return that has come to rest at its smallest value (a noiseless record whose
  // motion stopped at the end): no rail.
  Eigen::VectorXd at_rest = (-0.5 * Eigen::VectorXd::LinSpaced(801, 0.0, 8.0)).array().exp();
  at_rest.tail(100).setConstant(at_rest[700]);
  EXPECT_FALSE(FindClipping(at_rest));
  EXPECT_FALSE(FindClipping(Eigen::VectorXd::Constant(100, 0.3)));  // no range: nothing moves
}

TEST(ClippingTest, PeaksHeldAtARailAreClipping) {
  // The release itself held at a rail at 0.9 (its largest amplitude is at the start).
  const std::optional<Clipping> start = FindClipping(Decay(1e-3).cwiseMin(0.9));
  ASSERT_TRUE(start);
  EXPECT_TRUE(start->at_maximum);
  // The first three positive peaks (1, 0.74, 0.62) above a rail at 0.6: held there.
  const Eigen::VectorXd clipped = Decay(1e-3).cwiseMin(0.6);
  const std::optional<Clipping> top = FindClipping(clipped);
  ASSERT_TRUE(top);
  EXPECT_TRUE(top->at_maximum);
  EXPECT_FALSE(top->at_minimum);
  EXPECT_EQ(top->maximum, 0.6);
  EXPECT_EQ(top->samples, (clipped.array() == 0.6).count());
  EXPECT_THAT(ClippingReason("a_tip", "m/s^2", *top),
              HasSubstr("channel a_tip stays at its largest value, 0.6 m/s^2, for"));
  // Both rails at +-0.8: the first peak on each side only, one stretch each.
  const Eigen::VectorXd both = Decay(1e-3).cwiseMin(0.8).cwiseMax(-0.8);
  const std::optional<Clipping> rails = FindClipping(both);
  ASSERT_TRUE(rails);
  EXPECT_TRUE(rails->at_maximum && rails->at_minimum);
  EXPECT_THAT(ClippingReason("psi", "rad", *rails), HasSubstr("largest and smallest values"));
}

TEST(ClippingTest, ACoarseGridIsNotJudgedAFineOneIs) {
  // 8 bits over the range (256 steps): a peak held for one step is ordinary; not judged.
  const Eigen::VectorXd decay = Decay(1e-3);
  const double step = 2.0 / 256;
  const Eigen::VectorXd coarse = (decay / step).array().round() * step;
  EXPECT_FALSE(FindClipping(coarse.cwiseMin(0.6)));
  // 16 bits (65536 steps): clipping stands out.
  const double fine_step = 2.0 / 65536;
  const Eigen::VectorXd fine = (decay / fine_step).array().round() * fine_step;
  EXPECT_FALSE(FindClipping(fine));
  EXPECT_TRUE(FindClipping(fine.cwiseMin(0.6)));
}

// Two channels of the decay: `a` held at a rail of 0.6 on its first peaks, `b` as given.
Measurement TwoChannels(const Eigen::VectorXd& b) {
  Measurement record;
  record.channels = {"a", "b"};
  record.units = {"m", "m"};
  record.sample_interval_s = 0.01;
  record.values.resize(801, 2);
  record.values.col(0) = Decay(1e-3).cwiseMin(0.6);
  record.values.col(1) = b;
  return record;
}

TEST(ClippingTest, AClippedStartIsFoundInTheAnalysedChannelsOnly) {
  // `a`'s last clipped sample is on its third peak (t = 1.33 s, 1.33 periods in): the record is
  // whole from the next one on, well over half of it left.
  const Eigen::VectorXd decay = Decay(1e-3);
  const std::optional<ClippedStart> start = FindClippedStart(TwoChannels(decay), 0, 800);
  ASSERT_TRUE(start);
  const Eigen::VectorXd a = Decay(1e-3).cwiseMin(0.6);
  EXPECT_EQ(a[start->first_whole - 1], 0.6);
  EXPECT_LT(a.segment(start->first_whole, 801 - start->first_whole).maxCoeff(), 0.6);
  EXPECT_THAT(start->reason, HasSubstr("channel a stays at its largest value"));
  // `b` on a rail to the end (0.02 and above held; the decay's last peaks are 0.023): no decay back
  // inside its range, so no start is whole - unless `b` is left out of the analysis.
  const Measurement stuck = TwoChannels(decay.cwiseMin(0.02));
  EXPECT_FALSE(FindClippedStart(stuck, 0, 800));
  const std::optional<ClippedStart> without_b = FindClippedStart(stuck, 0, 800, {"a"});
  ASSERT_TRUE(without_b);
  EXPECT_EQ(without_b->first_whole, start->first_whole);
  // Only `b` analysed: clipped to the end, nothing to skip to.
  EXPECT_FALSE(FindClippedStart(stuck, 0, 800, {"b"}));
}

}  // namespace
}  // namespace mbid
