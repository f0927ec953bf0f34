// `mbid simulate --export FILE`: the simulated record also as UFF58 (ASCII, binary) and .mat,
// read back with mbid's own readers (docs/records-formats.md).

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "command_test.h"
#include "mbid/common/hdf5_io.h"
#include "mbid/common/measurement.h"
#include "mbid/records/records.h"
#include "raw_table.h"

namespace mbid::testing {
namespace {

// The load-drop scenario: 8 s at 100 Hz, a few seconds to simulate.
const std::string kLoadDrop =
    std::string(MBID_SOURCE_DIR) + "/scenarios/reference-crane-load-drop.yaml";

class ExportTest : public CommandTest {};

void ExpectSameRecord(const records::internal::RawTable& table, const Measurement& m,
                      double relative) {
  ASSERT_EQ(table.columns.size(), m.channels.size());
  EXPECT_EQ(table.interval, m.sample_interval_s);  // exact: mbid writes the exact interval
  EXPECT_EQ(table.start, m.start_time_s);
  for (size_t c = 0; c < m.channels.size(); ++c) {
    EXPECT_EQ(table.columns[c].name, m.channels[c]);
    EXPECT_EQ(table.columns[c].unit, m.units[c]);
    ASSERT_EQ(table.columns[c].values.size(), static_cast<size_t>(m.samples()));
    for (Eigen::Index j = 0; j < m.samples(); ++j) {
      const double y = m.values(j, static_cast<Eigen::Index>(c));
      EXPECT_NEAR(table.columns[c].values[static_cast<size_t>(j)], y, relative * std::abs(y));
    }
  }
}

TEST_F(ExportTest, SimulateExportsUffAndMat) {
  const fs::path h5 = dir_ / "drop.h5";
  const fs::path uff = dir_ / "drop.uff", uffb = dir_ / "drop.uffb", mat = dir_ / "drop.mat";
  const fs::path csv = dir_ / "drop.csv";
  const CommandResult result =
      Run("simulate " + kLoadDrop + " -o " + h5.string() + " --export " + uff.string() +
          " --export " + uffb.string() + " --export " + mat.string() + " --export " + csv.string());
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const Measurement m = ReadMeasurementH5(h5.string());
  // ASCII UFF58 prints 13 significant digits (4E20.12): within 5e-13 relative, 6e-13 with the
  // parse's last bit.
  const auto ascii = records::internal::ReadUff58(uff.string());
  EXPECT_EQ(ascii.format, "uff58");
  ExpectSameRecord(ascii, m, 6e-13);
  const auto binary = records::internal::ReadUff58(uffb.string());
  EXPECT_EQ(binary.format, "uff58b");
  ExpectSameRecord(binary, m, 0.0);  // raw doubles: exact
  const auto matlab = records::internal::ReadMat(mat.string());
  EXPECT_TRUE(matlab.si_by_contract);
  ExpectSameRecord(matlab, m, 0.0);  // uncompressed v5 doubles: exact
  // mbid's CSV: every double in its shortest round-trip form, units and the exact interval in
  // comments: imported, the same record to the bit.
  const Measurement read = records::ImportMeasurement(csv.string());
  EXPECT_EQ(read.channels, m.channels);
  EXPECT_EQ(read.units, m.units);
  EXPECT_EQ(read.sample_interval_s, m.sample_interval_s);
  EXPECT_EQ(read.start_time_s, m.start_time_s);
  EXPECT_TRUE(read.values == m.values);
}

// -o writes HDF5: a name that says another record format would be misread, by mbid itself
// too. Refused before anything runs, for every command that writes one.
TEST_F(ExportTest, AnHdf5OutputNamedAsAnotherFormatIsRefused) {
  for (const char* name : {"drop.csv", "drop.MAT", "drop.uff"}) {
    const fs::path out = dir_ / name;
    const CommandResult result = Run("simulate " + kLoadDrop + " -o " + out.string());
    EXPECT_EQ(result.exit_code, 2) << result.err;
    EXPECT_EQ(result.err.rfind("mbid: error: " + out.string() + ": ", 0), 0u) << result.err;
    EXPECT_NE(result.err.find("-o writes HDF5"), std::string::npos) << result.err;
    EXPECT_FALSE(fs::exists(out));
  }
  const CommandResult update =
      Run("update " + kLoadDrop + " " + kLoadDrop + " -o " + (dir_ / "up.csv").string());
  EXPECT_EQ(update.exit_code, 2) << update.err;
  EXPECT_NE(update.err.find("-o writes HDF5"), std::string::npos) << update.err;
  EXPECT_FALSE(fs::exists(dir_ / "up.csv"));
  // Names without another format's extension are the user's choice.
  const CommandResult plain =
      Run("identify " + (dir_ / "missing.h5").string() + " -o " + (dir_ / "modes.out").string());
  EXPECT_EQ(plain.err.find("-o writes HDF5"), std::string::npos) << plain.err;
}

TEST_F(ExportTest, UnknownExtensionFailsBeforeSimulating) {
  const fs::path h5 = dir_ / "drop.h5";
  const CommandResult result = Run("simulate " + kLoadDrop + " -o " + h5.string() + " --export " +
                                   (dir_ / "drop.xlsx").string());
  EXPECT_EQ(result.exit_code, 2) << result.err;  // invalid input
  EXPECT_EQ(result.err.rfind("mbid: error: --export:", 0), 0u) << result.err;
  EXPECT_NE(result.err.find(".uffb"), std::string::npos) << result.err;
  EXPECT_FALSE(fs::exists(h5));  // nothing written
}

}  // namespace
}  // namespace mbid::testing
