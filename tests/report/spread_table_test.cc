// The run report's table of several tests (the paper's Table 2): the spread row is over the
// tests that determine each parameter.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "mbid/report/run_report.h"

namespace mbid::report {
namespace {

updating::ParameterEstimate Tuned(const std::string& name, double value, bool determined) {
  updating::ParameterEstimate p;
  p.name = name;
  p.value = value;
  p.determined = determined;
  return p;
}

// A pull test determines both joints; a load drop that does not excite the slew keeps c_slew
// at its start (undetermined). That start set against the pull's value made a spread of 23 %
// that no test measured: now none ("-"), and c_lift's spread is (100 - 95) / 100.
TEST(SpreadTableTest, AnUndeterminedValueIsNoPartOfTheSpread) {
  updating::UpdateResult pull, drop;
  pull.parameters = {Tuned("c_lift", 95.0, true), Tuned("c_slew", 10.0, true)};
  drop.parameters = {Tuned("c_lift", 100.0, true), Tuned("c_slew", 13.0, false)};
  const auto spread = CalcRelativeSpread({&pull, &drop});
  ASSERT_EQ(spread.size(), 2u);
  EXPECT_EQ(spread[0].first, "c_lift");
  EXPECT_DOUBLE_EQ(spread[0].second, 0.05);
  EXPECT_EQ(spread[1].first, "c_slew");
  EXPECT_TRUE(std::isnan(spread[1].second));
  const std::string table = TestsTableMarkdown({"pull", "drop"}, {&pull, &drop});
  EXPECT_NE(table.find("| relative spread, % | 5 | - |"), std::string::npos) << table;
  EXPECT_NE(table.find("13 (undetermined)"), std::string::npos) << table;
}

}  // namespace
}  // namespace mbid::report
