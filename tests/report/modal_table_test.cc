// The run report's modal table: each channel's amplitudes in its own unit, and a combination
// tone marked as such with no reference mode beside it.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "mbid/report/run_report.h"

namespace mbid::report {
namespace {

identification::IdentifiedMode TableMode(double frequency_hz, double decay_per_s) {
  identification::IdentifiedMode mode;
  mode.SetPole({-decay_per_s, 2 * M_PI * frequency_hz});
  mode.amplitude = Eigen::Vector2d(1e-3, 0.5);
  mode.phase_rad = Eigen::Vector2d::Zero();
  return mode;
}

TEST(ModalTableTest, UnitsPerChannelAndTonesMarked) {
  identification::ModalResult result;
  result.channels = {"boom_incl", "a_bucket_z"};
  result.units = {"rad", "m/s^2"};
  result.samples = 601;
  result.sample_interval_s = 0.01;
  result.correlation = Eigen::Vector2d(0.999, 0.999);
  result.modes = {TableMode(3.04, 1.22), TableMode(7.42, 3.51), TableMode(10.46, 4.73)};
  result.modes[2].combination = "f1 + f2";
  const std::vector<ReferenceMode> exact = {{3.04, 1.22, {}}, {7.42, 3.51, {}}};
  const std::string table = ModalTableMarkdown(result, &exact, "model's exact");
  EXPECT_NE(table.find("| A_boom_incl, rad | A_a_bucket_z, m/s^2 |"), std::string::npos) << table;
  EXPECT_EQ(table.find("A_a_bucket_z, rad"), std::string::npos) << table;
  // The tone's row: its label, and "-" where the nearest exact mode (7.42 Hz) would stand.
  const size_t row = table.find("| 3 (combination tone f1 + f2) | 10.4600");
  ASSERT_NE(row, std::string::npos) << table;
  const std::string line = table.substr(row, table.find('\n', row) - row);
  EXPECT_EQ(line.substr(line.size() - 9), "| - | - |") << line;
  EXPECT_EQ(line.find("7.4200"), std::string::npos) << line;
  // A mode keeps its reference.
  EXPECT_NE(table.find("| 3.0400 | -1.220 |"), std::string::npos) << table;
}

}  // namespace
}  // namespace mbid::report
