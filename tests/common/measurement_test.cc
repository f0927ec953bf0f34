// Measurement: time grid, channel lookup, validation and the uniform-time check.
#include "mbid/common/measurement.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <limits>

#include "test_util.h"

namespace mbid {
namespace {

using testing::CatchInputError;
using ::testing::HasSubstr;
using testing::MakeMeasurement;

TEST(MeasurementTest, TimeIsStartPlusIndexTimesInterval) {
  const Measurement m = MakeMeasurement(5);  // 5 samples: enough to see the grid
  const Eigen::VectorXd t = m.CalcTime();
  ASSERT_EQ(t.size(), 5);             // one time per sample
  EXPECT_EQ(t[0], 0.125);             // the start time of MakeMeasurement
  EXPECT_EQ(t[4], 0.125 + 4 * 0.01);  // sample 4 = start + 4 intervals, same arithmetic
}

TEST(MeasurementTest, FindChannelReturnsIndexOrMinusOne) {
  const Measurement m = MakeMeasurement(2);  // 2 samples: the minimum valid record
  EXPECT_EQ(m.FindChannel("phi"), 1);        // second channel of MakeMeasurement
  EXPECT_EQ(m.FindChannel("theta"), -1);     // documented "not found"
}

TEST(MeasurementTest, ValidAcceptsMakeMeasurement) {
  EXPECT_NO_THROW(MakeMeasurement(10).Validate("test"));  // 10 samples: any valid size
}

TEST(MeasurementTest, NaNNamesChannelAndSample) {
  Measurement m = MakeMeasurement(10);  // 10 samples: room for a bad one inside
  m.values(7, 1) = std::numeric_limits<double>::quiet_NaN();  // sample 7 of channel phi
  const InputError e = CatchInputError([&] { m.Validate("data.h5"); });
  EXPECT_EQ(e.source(), "data.h5");
  EXPECT_EQ(e.field(), "phi");
  EXPECT_THAT(e.problem(), HasSubstr("sample 7"));  // the sample set to NaN
  EXPECT_THAT(e.problem(), HasSubstr("NaN"));
}

TEST(MeasurementTest, SingleSampleIsRejected) {
  const Measurement m = MakeMeasurement(1);  // 1 sample: one fewer than the minimum
  const InputError e = CatchInputError([&] { m.Validate("data.csv"); });
  EXPECT_EQ(e.source(), "data.csv");
  EXPECT_THAT(e.expected(), HasSubstr("at least 2 samples"));  // the contract's minimum
}

TEST(MeasurementTest, DuplicateChannelIsRejected) {
  Measurement m = MakeMeasurement(4);  // 4 samples: any valid size
  m.channels[2] = "psi";               // channel 2 repeats channel 0
  const InputError e = CatchInputError([&] { m.Validate("data.csv"); });
  EXPECT_EQ(e.field(), "psi");
  EXPECT_THAT(e.problem(), HasSubstr("twice"));
}

TEST(MeasurementTest, ChannelNamedTimeIsRejected) {
  Measurement m = MakeMeasurement(4);  // 4 samples: any valid size
  m.channels[0] = "time";              // would collide with the time column/dataset
  EXPECT_THROW(m.Validate("data.csv"), InputError);
}

TEST(MeasurementTest, NonPositiveIntervalIsRejected) {
  Measurement m = MakeMeasurement(4);  // 4 samples: any valid size
  m.sample_interval_s = 0;             // zero: time would not advance
  const InputError e = CatchInputError([&] { m.Validate("data.csv"); });
  EXPECT_EQ(e.field(), "sample_interval_s");
}

TEST(CheckUniformTimeTest, ReturnsTheMeanStep) {
  const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(11, 0.0, 1.0);  // 11 points, step 0.1
  const auto field = [](Eigen::Index j) { return "sample " + std::to_string(j); };
  EXPECT_DOUBLE_EQ(CheckUniformTime(t, "x", field), 0.1);  // (1 - 0) / (11 - 1)
}

TEST(CheckUniformTimeTest, ToleratesDeviationBelowOnePpmOfAStep) {
  Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(11, 0.0, 1.0);  // 11 points, step 0.1
  t[5] += 0.5e-6 * 0.1;  // half the 1e-6 tolerance of a 0.1 s step
  const auto field = [](Eigen::Index j) { return "sample " + std::to_string(j); };
  EXPECT_NO_THROW(CheckUniformTime(t, "x", field));
}

TEST(CheckUniformTimeTest, RejectsDeviationAboveOnePpmOfAStep) {
  Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(11, 0.0, 1.0);  // 11 points, step 0.1
  t[5] += 2e-6 * 0.1;  // twice the 1e-6 tolerance of a 0.1 s step
  const auto field = [](Eigen::Index j) { return "sample " + std::to_string(j); };
  const InputError e = CatchInputError([&] { CheckUniformTime(t, "x", field); });
  EXPECT_THAT(e.field(), ::testing::AnyOf("sample 5", "sample 6"));  // either step touching 5
  EXPECT_THAT(e.problem(), HasSubstr("non-uniform"));
}

}  // namespace
}  // namespace mbid
