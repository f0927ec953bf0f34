// Units through udunits2: the aliases loggers write, the SI unit of each dimension, and the
// conversions mbid refuses.
#include "units.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <thread>
#include <vector>

#include "mbid/common/error.h"
#include "test_util.h"

namespace mbid::records::internal {
namespace {

using mbid::testing::CatchInputError;
using ::testing::HasSubstr;

TEST(UnitsTest, SiUnitOfEachDimension) {
  EXPECT_EQ(SiUnitFor("deg", "f", "c"), "rad");  // angles are told apart from numbers
  EXPECT_EQ(SiUnitFor("mrad", "f", "c"), "rad");
  EXPECT_EQ(SiUnitFor("deg/s", "f", "c"), "rad/s");
  EXPECT_EQ(SiUnitFor("rpm", "f", "c"), "rad/s");
  EXPECT_EQ(SiUnitFor("mm", "f", "c"), "m");
  EXPECT_EQ(SiUnitFor("mm/s", "f", "c"), "m/s");
  EXPECT_EQ(SiUnitFor("mm/s^2", "f", "c"), "m/s^2");
  EXPECT_EQ(SiUnitFor("gn", "f", "c"), "m/s^2");
  EXPECT_EQ(SiUnitFor("kN", "f", "c"), "N");
  EXPECT_EQ(SiUnitFor("kN*m", "f", "c"), "N*m");  // not J: machines measure torques
  EXPECT_EQ(SiUnitFor("bar", "f", "c"), "Pa");
  EXPECT_EQ(SiUnitFor("mV", "f", "c"), "V");
  EXPECT_EQ(SiUnitFor("ms", "f", "c"), "s");
  EXPECT_EQ(SiUnitFor("%", "f", "c"), "1");
}

// The units answered without udunits2 are the ones udunits2 maps to themselves.
TEST(UnitsTest, SelfSiUnitsAreTheirOwnSiUnit) {
  ASSERT_FALSE(SelfSiUnits().empty());
  for (const std::string& unit : SelfSiUnits()) {
    EXPECT_EQ(SiUnitByUdunits(unit, "f", "c"), unit);
    EXPECT_EQ(SiUnitFor(unit, "f", "c"), unit);
  }
}

TEST(UnitsTest, ConversionFactors) {
  // udunits' factors against the definitions; 1e-15 relative: the last bits of its products.
  EXPECT_NEAR(FindConversion("deg", "rad", "f", "c").scale, M_PI / 180, 1e-15 * M_PI / 180);
  EXPECT_NEAR(FindConversion("°", "rad", "f", "c").scale, M_PI / 180, 1e-15 * M_PI / 180);
  // Prefixed degrees as loggers print them (refused before: udunits2 has no "mdeg").
  EXPECT_NEAR(FindConversion("mdeg", "rad", "f", "c").scale, M_PI / 180e3, 1e-15 * M_PI / 180e3);
  EXPECT_NEAR(FindConversion("µdeg/s", "rad/s", "f", "c").scale, M_PI / 180e6,
              1e-15 * M_PI / 180e6);
  EXPECT_DOUBLE_EQ(FindConversion("mm/s^2", "m/s^2", "f", "c").scale, 1e-3);
  EXPECT_DOUBLE_EQ(FindConversion("gn", "m/s^2", "f", "c").scale, 9.80665);  // CGPM 1901
  EXPECT_DOUBLE_EQ(FindConversion("g0", "m/s^2", "f", "c").scale, 9.80665);
  EXPECT_DOUBLE_EQ(FindConversion("g_n", "m/s^2", "f", "c").scale, 9.80665);
  EXPECT_DOUBLE_EQ(FindConversion("ms", "s", "f", "c").scale, 1e-3);
  EXPECT_DOUBLE_EQ(FindConversion("us", "s", "f", "c").scale, 1e-6);
  EXPECT_TRUE(FindConversion("rad", "rad", "f", "c").identity());  // same text: no arithmetic
  const UnitConversion celsius = FindConversion("degC", "K", "f", "c");
  EXPECT_DOUBLE_EQ(celsius.offset, 273.15);  // offsets are kept, not just factors
}

TEST(UnitsTest, RefusesUnknownAndIncompatibleUnits) {
  const InputError unknown =
      CatchInputError([] { FindConversion("blorp", "rad", "f.csv", "column 2"); });
  EXPECT_EQ(unknown.source(), "f.csv");
  EXPECT_EQ(unknown.field(), "column 2");
  EXPECT_THAT(unknown.problem(), HasSubstr("'blorp'"));
  // Radians are dimensionless to udunits; mbid still refuses to read a number as an angle.
  const InputError ratio = CatchInputError([] { FindConversion("%", "rad", "f", "c"); });
  EXPECT_THAT(ratio.expected(), HasSubstr("rad"));
  CatchInputError([] { FindConversion("deg", "1", "f", "c"); });
  CatchInputError([] { FindConversion("Hz", "rad/s", "f", "c"); });  // 2 pi apart
  CatchInputError([] { FindConversion("mm", "rad", "f", "c"); });
  // udunits' g is the gram: the message says how standard gravity is written.
  const InputError gram = CatchInputError([] { FindConversion("g", "m/s^2", "f", "c"); });
  EXPECT_THAT(gram.expected(), HasSubstr("gn"));
  // And mg the milligram: a trial's milli-g accelerometer found no spelling that worked.
  const InputError milli = CatchInputError([] { FindConversion("mg", "m/s^2", "f", "c"); });
  EXPECT_THAT(milli.expected(), HasSubstr("'0.001 gn'"));
  EXPECT_NEAR(FindConversion("0.001 gn", "m/s^2", "f", "c").scale, 9.80665e-3, 1e-15);
  // Without a model the target is the column's own SI unit: mg was read as a mass, Grad (German
  // for degree) as 1e9 rad, ms-2 (British m s-2) as 1e6 s-2, each without a word.
  for (const char* unit : {"mg", "Grad", "ms-2", "ms^-2", "ms-1", "Mrad", "G"}) {
    const InputError ambiguous = CatchInputError([unit] { SiUnitFor(unit, "f", "c"); });
    EXPECT_THAT(ambiguous.problem(), HasSubstr("ambiguous")) << unit;
  }
  EXPECT_THAT(CatchInputError([] { SiUnitFor("Grad", "f", "c"); }).expected(), HasSubstr("deg"));
  // Inside compound units too: a gyro's Grad/s read 1e9 too large, ms**-2 1e6.
  for (const char* unit : {"Grad/s", "Grad/s^2", "ms**-2", "m*ms-2"}) {
    const InputError ambiguous = CatchInputError([unit] { SiUnitFor(unit, "f", "c"); });
    EXPECT_THAT(ambiguous.problem(), HasSubstr("ambiguous")) << unit;
  }
  EXPECT_DOUBLE_EQ(FindConversion("ms", "s", "f", "c").scale, 1e-3);  // a time unit stays
  EXPECT_DOUBLE_EQ(FindConversion("MM/S", "m/s", "f", "c").scale, 1e-3);
  EXPECT_DOUBLE_EQ(FindConversion("DEG/S", "rad/s", "f", "c").scale, M_PI / 180);
  EXPECT_DOUBLE_EQ(FindConversion("kNm", "N*m", "f", "c").scale, 1e3);
  // Upper-case spellings of loggers' exports.
  EXPECT_DOUBLE_EQ(FindConversion("DEG", "rad", "f", "c").scale, M_PI / 180);
  EXPECT_DOUBLE_EQ(FindConversion("Deg", "rad", "f", "c").scale, M_PI / 180);
  EXPECT_TRUE(FindConversion("RAD", "rad", "f", "c").scale == 1.0);
  EXPECT_DOUBLE_EQ(FindConversion("MM", "m", "f", "c").scale, 1e-3);
  EXPECT_EQ(SiUnitFor("Nm", "f", "c"), "N*m");
}

TEST(UnitsTest, ConcurrentUseIsSafe) {
  // udunits2 is not thread-safe; the lock makes it so. 4 threads x 200 calls: enough to
  // interleave on any machine, fast on all.
  std::vector<std::thread> threads;
  std::vector<int> wrong(4, 0);
  for (int k = 0; k < 4; ++k) {
    threads.emplace_back([k, &wrong] {
      for (int i = 0; i < 200; ++i) {
        if (FindConversion("mm", "m", "f", "c").scale != 1e-3) ++wrong[static_cast<size_t>(k)];
      }
    });
  }
  for (auto& thread : threads) thread.join();
  EXPECT_EQ(wrong, std::vector<int>(4, 0));
}

}  // namespace
}  // namespace mbid::records::internal
