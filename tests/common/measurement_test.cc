// Measurement: time grid, channel lookup, validation and the uniform-time check.
#include "mbid/common/measurement.h"

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <limits>
#include <string>
#include <vector>

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

// Times j * tau printed to `digits` decimals (as loggers write them), with sample `drop` left out.
Eigen::VectorXd PrintedTimes(int n, double tau, int digits, int drop = -1) {
  std::vector<double> times;
  for (int j = 0; j < n + (drop >= 0 ? 1 : 0); ++j) {
    if (j != drop) times.push_back(std::stod(fmt::format("{:.{}f}", j * tau, digits)));
  }
  return Eigen::Map<Eigen::VectorXd>(times.data(), static_cast<Eigen::Index>(times.size()));
}

TEST(CheckUniformTimeTest, ADroppedSampleInACoarselyPrintedColumnIsNeverAClockRate) {
  const auto field = [](Eigen::Index j) { return "sample " + std::to_string(j); };
  // 100 Hz printed to 0.01 s without sample 300: the least-squares grid (99.82 Hz) lies within
  // the printed digit of every time, but a step of 2 tau is as likely a dropped sample.
  InputError e =
      CatchInputError([&] { CheckUniformTime(PrintedTimes(800, 0.01, 2, 300), "x", field, 0.01); });
  EXPECT_EQ(e.field(), "sample 300");
  EXPECT_THAT(e.problem(), HasSubstr("may be a dropped sample"));
  // 80 Hz printed to 0.01 s has steps 0.01 and 0.02: the same ambiguity, said so.
  e = CatchInputError([&] { CheckUniformTime(PrintedTimes(640, 1.0 / 80, 2), "x", field, 0.01); });
  EXPECT_THAT(e.problem(), HasSubstr("cannot tell"));
  // 512 Hz printed to 1 ms: steps 1 or 2 ms, a dropped sample would make 3 or 4 ms.
  const double tau = CheckUniformTime(PrintedTimes(4096, 1.0 / 512, 3), "x", field, 1e-3);
  EXPECT_NEAR(tau, 1.0 / 512, 1e-3 / 4096);  // least squares: about resolution / n
  e = CatchInputError(
      [&] { CheckUniformTime(PrintedTimes(4096, 1.0 / 512, 3, 1000), "x", field, 1e-3); });
  EXPECT_THAT(e.problem(), HasSubstr("non-uniform"));
  // 30 Hz to 1 ms (tau 33 place values): a dropped sample is far off any grid.
  EXPECT_NEAR(CheckUniformTime(PrintedTimes(240, 1.0 / 30, 3), "x", field, 1e-3), 1.0 / 30, 1e-6);
  EXPECT_THROW(CheckUniformTime(PrintedTimes(240, 1.0 / 30, 3, 100), "x", field, 1e-3), InputError);
}

}  // namespace
}  // namespace mbid
