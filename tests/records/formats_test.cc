// Readers and writers of other tools' record formats: UFF58 (ASCII and binary), LabVIEW .lvm and
// MATLAB .mat (docs/records-formats.md).

#include <gtest/gtest.h>
#include <matio.h>

#include <Eigen/Core>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "../common/test_util.h"
#include "mbid/common/error.h"
#include "mbid/common/measurement.h"
#include "mbid/records/records.h"
#include "raw_table.h"

namespace mbid::records {
namespace {

using internal::RawTable;
using internal::ReadLvm;
using internal::ReadMat;
using internal::ReadUff58;
using mbid::testing::CatchInputError;
using mbid::testing::SameBits;
using mbid::testing::TempDir;
using mbid::testing::WriteText;

std::string DataFile(const std::string& name) {
  return std::string(MBID_SOURCE_DIR) + "/tests/data/records/" + name;
}

std::string ReadText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// Two channels of closed-form free decays y = A e^{-zeta w t} cos(w_d t), one an angle, one an
// acceleration, so that a format that mixed channels or units up shows.
Measurement MakeDecays() {
  Measurement m;
  m.channels = {"arm angle", "tip_acc"};  // a blank: the MAT writer must sanitize it
  m.units = {"rad", "m/s^2"};
  m.start_time_s = 0.25;             // non-zero: the start must survive
  m.sample_interval_s = 1.0 / 3000;  // 3 kHz: prints inexactly in record 7's six digits
  m.source = "simulation";
  const int samples = 301;  // 0.1 s; odd, so the last 4E20.12 line is incomplete
  m.values.resize(samples, 2);
  const double amplitude[2] = {0.05, 3.7};                 // rad and m/s^2 of a typical tap test
  const double zeta[2] = {0.02, 0.035};                    // light damping as in steel structures
  const double w[2] = {2 * M_PI * 11.0, 2 * M_PI * 47.0};  // 11 Hz and 47 Hz modes
  for (int j = 0; j < samples; ++j) {
    const double t = m.start_time_s + j * m.sample_interval_s;
    for (int c = 0; c < 2; ++c) {
      const double wd = w[c] * std::sqrt(1 - zeta[c] * zeta[c]);
      m.values(j, c) = amplitude[c] * std::exp(-zeta[c] * w[c] * t) * std::cos(wd * t);
    }
  }
  return m;
}

void ExpectColumnsNamed(const RawTable& table, const Measurement& m) {
  ASSERT_EQ(table.columns.size(), m.channels.size());
  for (size_t c = 0; c < m.channels.size(); ++c) {
    EXPECT_EQ(table.columns[c].name, m.channels[c]);
    EXPECT_EQ(table.columns[c].unit, m.units[c]);
    ASSERT_EQ(table.columns[c].values.size(), static_cast<size_t>(m.samples()));
  }
}

void ExpectError(const std::string& path, const std::function<void()>& call,
                 const std::string& field_part) {
  const InputError e = CatchInputError(call);
  EXPECT_EQ(e.source(), path);
  EXPECT_NE(e.field().find(field_part), std::string::npos)
      << "field '" << e.field() << "' lacks '" << field_part << "': " << e.what();
}

// --- UFF58 ---------------------------------------------------------------------------------

TEST(Uff58, AsciiRoundTripKeepsThirteenDigits) {
  TempDir dir;
  const Measurement m = MakeDecays();
  const std::string path = dir.File("decay.uff");
  WriteUff58(m, path);
  const RawTable table = ReadUff58(path);
  EXPECT_EQ(table.format, "uff58");
  EXPECT_TRUE(table.time.empty());
  EXPECT_EQ(table.time_unit, "s");
  // Exact: mbid's ID line 5 carries the shortest round-trip texts of both.
  EXPECT_TRUE(SameBits(table.interval, m.sample_interval_s));
  EXPECT_TRUE(SameBits(table.start, m.start_time_s));
  ExpectColumnsNamed(table, m);
  for (size_t c = 0; c < 2; ++c) {
    for (Eigen::Index j = 0; j < m.samples(); ++j) {
      const double y = m.values(j, static_cast<Eigen::Index>(c));
      // E20.12 prints 13 significant digits: rounding moves a value by at most half a unit in
      // the 13th digit, 5e-13 of it; 6e-13 leaves room for the last bit of the parse.
      EXPECT_NEAR(table.columns[c].values[static_cast<size_t>(j)], y, 6e-13 * std::abs(y))
          << "channel " << c << " sample " << j;
    }
  }
}

TEST(Uff58, BinaryRoundTripIsExact) {
  TempDir dir;
  const Measurement m = MakeDecays();
  const std::string path = dir.File("decay.buff");
  WriteUff58(m, path, /*binary=*/true);
  const RawTable table = ReadUff58(path);
  EXPECT_EQ(table.format, "uff58b");
  EXPECT_TRUE(SameBits(table.interval, m.sample_interval_s));
  EXPECT_TRUE(SameBits(table.start, m.start_time_s));
  ExpectColumnsNamed(table, m);
  for (size_t c = 0; c < 2; ++c) {
    const Eigen::VectorXd read = Eigen::Map<const Eigen::VectorXd>(
        table.columns[c].values.data(), static_cast<Eigen::Index>(table.columns[c].values.size()));
    EXPECT_TRUE(SameBits(read, m.values.col(static_cast<Eigen::Index>(c))));
  }
}

TEST(Uff58, WriterHeaderIsStandardDataset58) {
  TempDir dir;
  const std::string path = dir.File("decay.uff");
  WriteUff58(MakeDecays(), path);
  const std::string text = ReadText(path);
  // Record 7: real double (4), 301 values, even (1), minimum 0.25, increment 1/3000 in E13.5.
  EXPECT_NE(text.find("         4       301         1  2.50000E-01  3.33333E-04  0.00000E+00\n"),
            std::string::npos)
      << text.substr(0, 1200);
  // Record 8: abscissa is time (17) in s; record 9: acceleration (12) for m/s^2.
  EXPECT_NE(text.find("        17    0    0    0 Time                 s"), std::string::npos);
  EXPECT_NE(text.find("        12    0    0    0 tip_acc              m/s^2"), std::string::npos);
}

TEST(Uff58, ReadsSinglePrecisionFixtureWithOtherDatasets) {
  // Two datasets 58 of 20 samples in 6E13.5 after a dataset 151 and 164 (skipped).
  const RawTable table = ReadUff58(DataFile("two_channels_single.uff"));
  EXPECT_EQ(table.format, "uff58");
  EXPECT_DOUBLE_EQ(table.start, 0.5);        // record 7 abscissa minimum 5.00000E-01
  EXPECT_DOUBLE_EQ(table.interval, 2.5e-3);  // increment 2.50000E-03 (400 Hz)
  EXPECT_EQ(table.time_unit, "s");           // record 8 units label
  ASSERT_EQ(table.columns.size(), 2u);
  EXPECT_EQ(table.columns[0].name, "tip acceleration");  // ID line 1
  EXPECT_EQ(table.columns[0].unit, "m/s^2");             // record 9 units label
  // ID line 1 empty: response entity RIG, node 7, direction -2 (-Y) of record 6.
  EXPECT_EQ(table.columns[1].name, "RIG:7-Y");
  EXPECT_EQ(table.columns[1].unit, "mm");
  ASSERT_EQ(table.columns[0].values.size(), 20u);  // record 7 declares 20
  ASSERT_EQ(table.columns[1].values.size(), 20u);
  for (int j = 0; j < 20; ++j) {
    // The fixture's values: 0.125 j - 1 (exact in six digits) and 1.5e-3 (j mod 5).
    EXPECT_DOUBLE_EQ(table.columns[0].values[static_cast<size_t>(j)], 0.125 * j - 1.0);
    EXPECT_DOUBLE_EQ(table.columns[1].values[static_cast<size_t>(j)], (j % 5) * 1.5e-3);
  }
}

// A dataset 58 in single precision with `count` values declared and `values` written.
std::string Dataset58(int function_type, int ordinate_type, int count, double increment,
                      const std::vector<double>& values, const std::string& name = "ch") {
  std::string text = "    -1\n    58\n" + name + "\nNONE\nNONE\nNONE\nNONE\n";
  char line[200];
  std::snprintf(line, sizeof(line), "%5d%10d%5d%10d %-10s%10d%4d %-10s%10d%4d\n", function_type, 0,
                0, 0, "NONE", 1, 1, "NONE", 0, 0);
  text += line;
  std::snprintf(line, sizeof(line), "%10d%10d%10d%13.5E%13.5E%13.5E\n", ordinate_type, count, 1,
                0.0, increment, 0.0);
  text += line;
  text += "        17    0    0    0 Time                 s                   \n";
  text += "        12    0    0    0 NONE                 m/s^2               \n";
  text += "         0    0    0    0 NONE                 NONE                \n";
  text += "         0    0    0    0 NONE                 NONE                \n";
  for (size_t i = 0; i < values.size(); ++i) {
    std::snprintf(line, sizeof(line), "%13.5E", values[i]);
    text += line;
    if (i % 6 == 5 || i + 1 == values.size()) text += "\n";
  }
  return text + "    -1\n";
}

const std::vector<double> kSix = {1, 2, 3, 4, 5, 6};  // one full 6E13.5 line

// Test systems label an acceleration (record 9's data type 12) in standard gravity "g"; the unit
// library reads "g" as gram, and such files were refused. Read as gn (9.80665 m/s^2).
TEST(Uff58, AnAccelerationInGIsStandardGravity) {
  TempDir dir;
  const std::string path = dir.File("g.uff");
  std::string text = Dataset58(1, 2, 6, 0.01, kSix);
  text.replace(text.find("m/s^2               \n"), 21, "g                   \n");
  WriteText(path, text);
  const Measurement m = ImportMeasurement(path);
  ASSERT_EQ(m.units.size(), 1u);
  EXPECT_EQ(m.units[0], "m/s^2");
  EXPECT_NEAR(m.values(2, 0), 3 * 9.80665, 1e-9);
}

TEST(Uff58, TruncatedDatasetNamesIt) {
  TempDir dir;
  const std::string path = dir.File("cut.uff");
  std::string text = Dataset58(1, 2, 6, 1e-3, kSix);
  text = text.substr(0, text.find("  4.00000E+00"));  // cut inside the data line
  WriteText(path, text);
  ExpectError(
      path, [&] { ReadUff58(path); }, "dataset 1 (line 2)");
}

TEST(Uff58, DeclaredCountBeyondTheFile) {
  TempDir dir;
  const std::string path = dir.File("big.uff");
  // 50 million values declared (within the 1e8 cap) in a file of under a kilobyte.
  WriteText(path, Dataset58(1, 2, 50000000, 1e-3, kSix));
  ExpectError(
      path, [&] { ReadUff58(path); }, "dataset 1 (line 2), record 7");
  // Beyond the cap itself: 2e9 values.
  WriteText(path, Dataset58(1, 2, 2000000000, 1e-3, kSix));
  ExpectError(
      path, [&] { ReadUff58(path); }, "record 7");
}

TEST(Uff58, UnknownOrdinateType) {
  TempDir dir;
  const std::string path = dir.File("type3.uff");
  WriteText(path, Dataset58(1, 3, 6, 1e-3, kSix));  // 3 is no ordinate type of dataset 58
  ExpectError(
      path, [&] { ReadUff58(path); }, "dataset 1 (line 2), record 7 (line 9)");
}

TEST(Uff58, NonTimeFunctionType) {
  TempDir dir;
  const std::string path = dir.File("frf.uff");
  WriteText(path, Dataset58(4, 2, 6, 1e-3, kSix));  // 4: a frequency response function
  ExpectError(
      path, [&] { ReadUff58(path); }, "dataset 1 (line 2), record 6 (line 8)");
}

TEST(Uff58, InconsistentIntervalsBetweenChannels) {
  TempDir dir;
  const std::string path = dir.File("rates.uff");
  // 1 kHz and 1.024 kHz (9.76563E-04 printed): two acquisition rates in one file.
  WriteText(path, Dataset58(1, 2, 6, 1e-3, kSix, "a") + Dataset58(1, 2, 6, 1.0 / 1024, kSix, "b"));
  // The first dataset takes 13 lines and one data line and its -1; the second's number is line
  // 17.
  ExpectError(
      path, [&] { ReadUff58(path); }, "dataset 2 (line 17), record 7");
}

TEST(Uff58, BinaryByteCountBeyondTheFile) {
  TempDir dir;
  const std::string path = dir.File("cut.buff");
  WriteUff58(MakeDecays(), path, /*binary=*/true);
  std::string bytes = ReadText(path);
  WriteText(path, bytes.substr(0, 1500));  // the first dataset's 2408 data bytes cut short
  ExpectError(
      path, [&] { ReadUff58(path); }, "dataset 1 (line 2), header");
}

TEST(Uff58, NotUniversalFile) {
  TempDir dir;
  const std::string path = dir.File("text.uff");
  WriteText(path, "time,a\n0,1\n");
  ExpectError(
      path, [&] { ReadUff58(path); }, "line 1");
}

// --- LabVIEW .lvm ----------------------------------------------------------------------------

TEST(Lvm, ReadsTabSeparatedDecimalCommaFixture) {
  // As LabVIEW writes it: CRLF, tab-separated, decimal comma, one X column, a comment cell.
  const RawTable table = ReadLvm(DataFile("two_channels_comma.lvm"));
  EXPECT_EQ(table.format, "lvm");
  EXPECT_EQ(table.time_unit, "s");
  ASSERT_EQ(table.time.size(), 8u);                  // Samples 8
  EXPECT_DOUBLE_EQ(table.printed_resolution, 1e-6);  // X values print six decimals
  ASSERT_EQ(table.columns.size(), 2u);               // Channels 2
  EXPECT_EQ(table.columns[0].name, "accel");
  // LabVIEW's "g" of an accelerometer is standard gravity (the gram to udunits2: refused before,
  // the format's own example among such files).
  EXPECT_EQ(table.columns[0].unit, "gn");
  EXPECT_EQ(table.columns[1].name, "angle");
  EXPECT_EQ(table.columns[1].unit, "deg");
  ASSERT_EQ(table.sample_lines.size(), 8u);
  EXPECT_EQ(table.sample_lines[0], 24);  // after 22 header lines and the name row
  for (int j = 0; j < 8; ++j) {
    // The fixture's values: t = 0.002 j, accel = 0.0125 (j - 3), angle = 0.25 j - 1.5.
    EXPECT_DOUBLE_EQ(table.time[static_cast<size_t>(j)], 0.002 * j);
    EXPECT_DOUBLE_EQ(table.columns[0].values[static_cast<size_t>(j)], 0.0125 * (j - 3));
    EXPECT_DOUBLE_EQ(table.columns[1].values[static_cast<size_t>(j)], 0.25 * j - 1.5);
  }
  const Measurement imported = ImportMeasurement(DataFile("two_channels_comma.lvm"));
  EXPECT_EQ(imported.units[0], "m/s^2");
  EXPECT_DOUBLE_EQ(imported.values(4, 0), 0.0125 * 9.80665);  // j = 4: 0.0125 g
}

// An .lvm without X columns in two segments; `second_x0` is where the second starts.
std::string LvmNoX(const std::string& second_x0) {
  std::string text =
      "LabVIEW Measurement\t\nWriter_Version\t2\nSeparator\tTab\nDecimal_Separator\t.\n"
      "X_Columns\tNo\n***End_of_Header***\t\n\n";
  const auto segment = [](const std::string& x0, double first) {
    std::string s = "Channels\t1\t\nSamples\t3\t\nY_Unit_Label\tV\t\nX_Dimension\tTime\t\nX0\t" +
                    x0 + "\t\nDelta_X\t0.5\t\n***End_of_Header***\t\nvoltage\tComment\n";
    for (int j = 0; j < 3; ++j) s += std::to_string(first + j) + "\n";
    return s;
  };
  return text + segment("1.0", 10) + segment(second_x0, 13);
}

TEST(Lvm, NoXColumnSegmentsConcatenate) {
  TempDir dir;
  const std::string path = dir.File("nox.lvm");
  WriteText(path, LvmNoX("2.5"));  // 1.0 + 3 samples x 0.5 s: continues the first segment
  const RawTable table = ReadLvm(path);
  EXPECT_TRUE(table.time.empty());
  EXPECT_EQ(table.start, 1.0);     // X0 of the first segment
  EXPECT_EQ(table.interval, 0.5);  // Delta_X
  ASSERT_EQ(table.columns.size(), 1u);
  EXPECT_EQ(table.columns[0].name, "voltage");
  EXPECT_EQ(table.columns[0].unit, "V");
  EXPECT_EQ(table.columns[0].values, (std::vector<double>{10, 11, 12, 13, 14, 15}));
}

// A 3 kHz logger writes Delta_X to six decimals, 0.000333: taken as printed it is 3003.003 Hz,
// and every frequency came out 0.1 % high (1700 std on a clean record) with nothing said. The
// interval is known to +-5e-10 s, which 2999..3007 Hz all fit: the roundest, 3000 Hz, is taken,
// and the report says so. A rate the user states wins when the print allows it.
TEST(Lvm, AnIntervalPrintedToFewDigitsIsTheRoundRateItRoundsFrom) {
  TempDir dir;
  const std::string path = dir.File("3k.lvm");
  std::string text =
      "LabVIEW Measurement\t\nWriter_Version\t2\nSeparator\tTab\nDecimal_Separator\t.\n"
      "X_Columns\tNo\n***End_of_Header***\t\n\nChannels\t1\t\nSamples\t8\t\n"
      "Y_Unit_Label\tm/s^2\t\nX_Dimension\tTime\t\nX0\t0\t\nDelta_X\t0.000333\t\n"
      "***End_of_Header***\t\nacc\tComment\n";
  for (int j = 0; j < 8; ++j) text += std::to_string(0.1 * j) + "\n";
  WriteText(path, text);
  ImportReport report;
  const Measurement m = ImportMeasurement(path, {}, &report);
  EXPECT_EQ(m.sample_interval_s, 1.0 / 3000);
  // Still a guess within the print's bounds [3.325e-4, 3.335e-4] s: 1/3000 s is 8.3e-7 s from the
  // lower one, 0.25 %, which every frequency read from the record carries.
  EXPECT_NEAR(m.sample_interval_uncertainty, (1.0 / 3000 - 3.325e-4) * 3000, 1e-9);
  ASSERT_FALSE(report.conversions.empty());
  EXPECT_NE(report.conversions.back().find("read as 1/3000 s"), std::string::npos)
      << report.conversions.back();
  ImportOptions stated;
  stated.sample_rate_hz = 3001;  // 3.33222e-4 s prints as 0.000333 too
  EXPECT_EQ(ImportMeasurement(path, stated).sample_interval_s, 1.0 / 3001);
  stated.sample_rate_hz = 2500;
  const InputError e = CatchInputError([&] { ImportMeasurement(path, stated); });
  EXPECT_EQ(e.field(), "sample_rate_hz");
  // Printed exactly enough (0.002000 at 500 Hz, 1e-6 of 0.002 is 5e-4 relative, yet only 500 Hz
  // fits among round rates): the same value.
  const std::string exact = dir.File("500.lvm");
  std::string slow = text;
  slow.replace(slow.find("0.000333"), 8, "0.002000");
  WriteText(exact, slow);
  EXPECT_EQ(ImportMeasurement(exact).sample_interval_s, 1.0 / 500);
  // The print is exactly a whole rate's: taken as exact.
  EXPECT_EQ(ImportMeasurement(exact).sample_interval_uncertainty, 0.0);
  // A rate the user states is exact.
  stated.sample_rate_hz = 3000;
  EXPECT_EQ(ImportMeasurement(path, stated).sample_interval_uncertainty, 0.0);
}

// A logger's time in ms read as s makes every frequency 1000 times too low. An .lvm without
// X_Unit_Label (and a MAT file, whose time has no unit) is read in s as the readers assume; a
// step of 0.1 s or more is said, as for a CSV `time` column without a unit. With X_Unit_Label s
// nothing is said.
TEST(Lvm, ATimeWithoutUnitThatStepsSlowlyIsSaid) {
  TempDir dir;
  const auto lvm = [](const std::string& x_unit) {
    std::string text =
        "LabVIEW Measurement\t\nWriter_Version\t2\nSeparator\tTab\nDecimal_Separator\t.\n"
        "X_Columns\tNo\n***End_of_Header***\t\n\nChannels\t1\t\nSamples\t8\t\n"
        "Y_Unit_Label\tm/s^2\t\n" +
        x_unit +
        "X_Dimension\tTime\t\nX0\t0\t\nDelta_X\t5\t\n***End_of_Header***\t\nacc\tComment\n";
    for (int j = 0; j < 8; ++j) text += std::to_string(0.1 * j) + "\n";
    return text;
  };
  const std::string unlabelled = dir.File("ms.lvm");
  WriteText(unlabelled, lvm(""));
  ImportReport report;
  EXPECT_EQ(ImportMeasurement(unlabelled, {}, &report).sample_interval_s, 5.0);
  ASSERT_EQ(report.warnings.size(), 1u);
  EXPECT_NE(report.warnings[0].find("states no unit and is read in s"), std::string::npos)
      << report.warnings[0];
  const std::string labelled = dir.File("s.lvm");
  WriteText(labelled, lvm("X_Unit_Label\ts\t\n"));
  ImportReport stated;
  ImportMeasurement(labelled, {}, &stated);
  EXPECT_TRUE(stated.warnings.empty());
}

TEST(Lvm, SegmentThatDoesNotContinueIsAnError) {
  TempDir dir;
  const std::string path = dir.File("gap.lvm");
  WriteText(path, LvmNoX("7.0"));  // a pause: 4.5 s missing after the first segment
  ExpectError(
      path, [&] { ReadLvm(path); }, "line 19");  // the second segment's header
}

TEST(Lvm, MissingEndOfHeader) {
  TempDir dir;
  const std::string path = dir.File("noend.lvm");
  WriteText(path, "LabVIEW Measurement\t\nWriter_Version\t2\nSeparator\tTab\n0.0\t1.0\n");
  ExpectError(
      path, [&] { ReadLvm(path); }, "line 1");
}

TEST(Lvm, DeclaredSamplesMustAllArrive) {
  TempDir dir;
  const std::string path = dir.File("short.lvm");
  std::string text = ReadText(DataFile("two_channels_comma.lvm"));
  WriteText(path, text.substr(0, text.rfind("0,012000")));  // the last sample row cut off
  ExpectError(
      path, [&] { ReadLvm(path); }, "line 15");  // the Samples line
}

// --- MATLAB .mat -----------------------------------------------------------------------------

TEST(Mat, RoundTripIsExact) {
  TempDir dir;
  const Measurement m = MakeDecays();
  const std::string path = dir.File("decay.mat");
  WriteMat(m, path);
  const RawTable table = ReadMat(path);
  EXPECT_EQ(table.format, "mat");
  EXPECT_TRUE(table.si_by_contract);
  EXPECT_TRUE(table.time.empty());
  EXPECT_TRUE(SameBits(table.interval, m.sample_interval_s));
  EXPECT_TRUE(SameBits(table.start, m.start_time_s));
  ExpectColumnsNamed(table, m);
  EXPECT_EQ(table.columns[0].where, "variable arm_angle");  // the sanitized MATLAB name
  for (size_t c = 0; c < 2; ++c) {
    const Eigen::VectorXd read = Eigen::Map<const Eigen::VectorXd>(
        table.columns[c].values.data(), static_cast<Eigen::Index>(table.columns[c].values.size()));
    EXPECT_TRUE(SameBits(read, m.values.col(static_cast<Eigen::Index>(c))));
  }
}

TEST(Mat, ChannelVariablesAvoidMbidNamesAndEachOther) {
  TempDir dir;
  Measurement m = MakeDecays();
  m.channels = {"units", "2nd mode"};  // a name of the layout itself; a leading digit
  const std::string path = dir.File("names.mat");
  WriteMat(m, path);
  const RawTable table = ReadMat(path);
  ASSERT_EQ(table.columns.size(), 2u);
  EXPECT_EQ(table.columns[0].name, "units");
  EXPECT_EQ(table.columns[0].where, "variable units_2");
  EXPECT_EQ(table.columns[1].name, "2nd mode");
  EXPECT_EQ(table.columns[1].where, "variable ch_2nd_mode");
}

matvar_t* CellOfNames(const char* name, const std::vector<std::string>& names) {
  size_t dims[2] = {1, names.size()};
  matvar_t* cell = Mat_VarCreate(name, MAT_C_CELL, MAT_T_CELL, 2, dims, nullptr, 0);
  for (size_t i = 0; i < names.size(); ++i) {
    size_t text_dims[2] = {1, names[i].size()};
    Mat_VarSetCell(cell, static_cast<int>(i),
                   Mat_VarCreate(nullptr, MAT_C_CHAR, MAT_T_UTF8, 2, text_dims,
                                 const_cast<char*>(names[i].data()), 0));
  }
  return cell;
}

void WriteVar(mat_t* mat, matvar_t* var) {
  ASSERT_NE(var, nullptr);
  EXPECT_EQ(Mat_VarWrite(mat, var, MAT_COMPRESSION_NONE), 0);
  Mat_VarFree(var);
}

TEST(Mat, ReadsV73MatrixWithTimeFirst) {
  TempDir dir;
  const std::string path = dir.File("lab73.mat");
  // 5 samples x 3 columns (time, a, b), column-major as MATLAB stores it.
  const int n = 5;  // a handful of samples suffices for the layout
  std::vector<double> data(3 * n);
  for (int j = 0; j < n; ++j) {
    data[static_cast<size_t>(j)] = 0.01 * j;           // 100 Hz
    data[static_cast<size_t>(n + j)] = 1.0 / (j + 1);  // a: values needing 17 digits
    data[static_cast<size_t>(2 * n + j)] = -2.0 * j;   // b
  }
  mat_t* mat = Mat_CreateVer(path.c_str(), nullptr, MAT_FT_MAT73);
  ASSERT_NE(mat, nullptr) << "matio without HDF5: no v7.3";
  size_t dims[2] = {static_cast<size_t>(n), 3};
  WriteVar(mat, Mat_VarCreate("data", MAT_C_DOUBLE, MAT_T_DOUBLE, 2, dims, data.data(), 0));
  WriteVar(mat, CellOfNames("names", {"time", "a", "b"}));  // one more name: time first
  WriteVar(mat, CellOfNames("units", {"V", "g"}));
  Mat_Close(mat);
  const RawTable table = ReadMat(path);
  EXPECT_FALSE(table.si_by_contract);
  ASSERT_EQ(table.time.size(), 5u);
  EXPECT_EQ(table.time[3], 0.01 * 3);  // as stored
  ASSERT_EQ(table.columns.size(), 2u);
  EXPECT_EQ(table.columns[0].name, "a");
  EXPECT_EQ(table.columns[0].unit, "V");
  EXPECT_EQ(table.columns[1].name, "b");
  EXPECT_EQ(table.columns[1].unit, "g");
  for (int j = 0; j < n; ++j) {
    EXPECT_EQ(table.columns[0].values[static_cast<size_t>(j)], 1.0 / (j + 1));  // exact
    EXPECT_EQ(table.columns[1].values[static_cast<size_t>(j)], -2.0 * j);
  }
}

// h5py (hdf5storage) writes a v7.3 variable's MATLAB_class null-padded, not null-terminated as
// MATLAB does; matio then reads the variable as an empty array (a trial's file was refused:
// "a 1901x1 empty"). Such numeric variables are read through HDF5.
TEST(Mat, ReadsV73VariablesWhoseClassIsNullPadded) {
  if (std::system("/usr/bin/python3 -c 'import h5py' >/dev/null 2>&1") != 0) {
    GTEST_SKIP() << "h5py is not installed for /usr/bin/python3";
  }
  TempDir dir;
  const std::string path = dir.File("padded73.mat");
  const std::vector<double> time = {0, 0.01, 0.02, 0.03};  // 100 Hz
  const std::vector<float> a = {1.0f / 3, -2.5f, 7, 0};    // single precision, as loggers store
  mat_t* mat = Mat_CreateVer(path.c_str(), nullptr, MAT_FT_MAT73);
  ASSERT_NE(mat, nullptr) << "matio without HDF5: no v7.3";
  size_t column[2] = {4, 1}, row[2] = {1, 4};
  WriteVar(mat, Mat_VarCreate("time", MAT_C_DOUBLE, MAT_T_DOUBLE, 2, column,
                              const_cast<double*>(time.data()), 0));
  WriteVar(mat,
           Mat_VarCreate("a", MAT_C_SINGLE, MAT_T_SINGLE, 2, row, const_cast<float*>(a.data()), 0));
  Mat_Close(mat);
  const std::string pad = dir.File("pad.py");
  WriteText(pad,
            "import sys, h5py, numpy as np\n"
            "with h5py.File(sys.argv[1], 'r+') as f:\n"
            "    for k in f:\n"
            "        v = f[k].attrs['MATLAB_class']\n"
            "        v = v if isinstance(v, bytes) else v.encode()\n"
            "        del f[k].attrs['MATLAB_class']\n"
            "        f[k].attrs.create('MATLAB_class', np.bytes_(v))\n"
            "        t = h5py.h5a.open(f[k].id, b'MATLAB_class').get_type()\n"
            "        assert t.get_strpad() == h5py.h5t.STR_NULLPAD\n");
  ASSERT_EQ(std::system(("/usr/bin/python3 " + pad + " " + path).c_str()), 0);
  const RawTable table = ReadMat(path);
  EXPECT_EQ(table.time, time);
  ASSERT_EQ(table.columns.size(), 1u);
  EXPECT_EQ(table.columns[0].name, "a");
  EXPECT_EQ(table.columns[0].values, std::vector<double>(a.begin(), a.end()));  // exact
}

TEST(Mat, ReadsVectorsWithSampleRate) {
  TempDir dir;
  const std::string path = dir.File("vectors.mat");
  mat_t* mat = Mat_CreateVer(path.c_str(), nullptr, MAT_FT_MAT5);
  ASSERT_NE(mat, nullptr);
  const std::vector<float> x = {1.5f, 2.5f, 3.5f};  // single precision, as loggers store
  const std::vector<double> y = {-1, 0, 1};
  const double fs = 2048;  // Hz, a common logger rate
  size_t column[2] = {3, 1}, row[2] = {1, 3}, one[2] = {1, 1};
  WriteVar(mat, Mat_VarCreate("x", MAT_C_SINGLE, MAT_T_SINGLE, 2, column,
                              const_cast<float*>(x.data()), 0));
  WriteVar(mat, Mat_VarCreate("y", MAT_C_DOUBLE, MAT_T_DOUBLE, 2, row,
                              const_cast<double*>(y.data()), 0));  // a row vector reads too
  WriteVar(mat,
           Mat_VarCreate("fs", MAT_C_DOUBLE, MAT_T_DOUBLE, 2, one, const_cast<double*>(&fs), 0));
  Mat_Close(mat);
  const RawTable table = ReadMat(path);
  EXPECT_TRUE(table.time.empty());
  EXPECT_EQ(table.interval, 1.0 / 2048);  // exact: a power of two
  EXPECT_EQ(table.start, 0.0);            // no t0
  ASSERT_EQ(table.columns.size(), 2u);
  EXPECT_EQ(table.columns[0].name, "x");
  EXPECT_EQ(table.columns[0].values, (std::vector<double>{1.5, 2.5, 3.5}));
  EXPECT_EQ(table.columns[1].name, "y");
  EXPECT_EQ(table.columns[1].values, y);
}

TEST(Mat, ReadsCompressedStructWithNames) {
  TempDir dir;
  const std::string path = dir.File("struct.mat");
  mat_t* mat = Mat_CreateVer(path.c_str(), nullptr, MAT_FT_MAT5);
  ASSERT_NE(mat, nullptr);
  const size_t n = 4;                           // a handful of samples suffices for the layout
  std::vector<double> time = {0, 0.5, 1, 1.5};  // 2 Hz
  // Stored channels x samples (2 x 4): the dimension of length 4 holds the samples.
  std::vector<double> data = {1, -1, 2, -2, 3, -3, 4, -4};
  size_t time_dims[2] = {n, 1}, data_dims[2] = {2, n}, one[2] = {1, 1};
  const char* fields[] = {"time", "data", "names"};
  matvar_t* record = Mat_VarCreateStruct("rec", 2, one, fields, 3);
  Mat_VarSetStructFieldByName(
      record, "time", 0,
      Mat_VarCreate(nullptr, MAT_C_DOUBLE, MAT_T_DOUBLE, 2, time_dims, time.data(), 0));
  Mat_VarSetStructFieldByName(
      record, "data", 0,
      Mat_VarCreate(nullptr, MAT_C_DOUBLE, MAT_T_DOUBLE, 2, data_dims, data.data(), 0));
  Mat_VarSetStructFieldByName(record, "names", 0, CellOfNames(nullptr, {"left", "right"}));
  EXPECT_EQ(Mat_VarWrite(mat, record, MAT_COMPRESSION_ZLIB), 0);  // as MATLAB's save -v7
  Mat_VarFree(record);
  Mat_Close(mat);
  const RawTable table = ReadMat(path);
  EXPECT_EQ(table.time, time);
  ASSERT_EQ(table.columns.size(), 2u);
  EXPECT_EQ(table.columns[0].name, "left");
  EXPECT_EQ(table.columns[0].values, (std::vector<double>{1, 2, 3, 4}));
  EXPECT_EQ(table.columns[1].name, "right");
  EXPECT_EQ(table.columns[1].values, (std::vector<double>{-1, -2, -3, -4}));
}

TEST(Mat, ThreeDimensionalArrayNamesTheVariable) {
  TempDir dir;
  const std::string path = dir.File("cube.mat");
  mat_t* mat = Mat_CreateVer(path.c_str(), nullptr, MAT_FT_MAT5);
  ASSERT_NE(mat, nullptr);
  std::vector<double> cube(2 * 3 * 4, 1.0);  // 2x3x4: no samples x columns reading
  size_t dims[3] = {2, 3, 4};
  WriteVar(mat, Mat_VarCreate("cube", MAT_C_DOUBLE, MAT_T_DOUBLE, 3, dims, cube.data(), 0));
  Mat_Close(mat);
  ExpectError(
      path, [&] { ReadMat(path); }, "variable cube");
}

TEST(Mat, StringWhereNumberIsExpected) {
  TempDir dir;
  const std::string path = dir.File("fs_text.mat");
  mat_t* mat = Mat_CreateVer(path.c_str(), nullptr, MAT_FT_MAT5);
  ASSERT_NE(mat, nullptr);
  const std::vector<double> y = {1, 2, 3};  // any channel
  std::string fs = "1kHz";                  // the rate as text, not a number
  size_t column[2] = {3, 1}, text[2] = {1, fs.size()};
  WriteVar(mat, Mat_VarCreate("y", MAT_C_DOUBLE, MAT_T_DOUBLE, 2, column,
                              const_cast<double*>(y.data()), 0));
  WriteVar(mat, Mat_VarCreate("fs", MAT_C_CHAR, MAT_T_UTF8, 2, text, fs.data(), 0));
  Mat_Close(mat);
  ExpectError(
      path, [&] { ReadMat(path); }, "variable fs");
}

TEST(Mat, RandomBytesAreNotAMatFile) {
  TempDir dir;
  const std::string path = dir.File("noise.mat");
  std::mt19937 random(58);        // fixed seed: the same bytes every run
  std::string bytes(4096, '\0');  // more than a MAT header (128 bytes)
  for (char& b : bytes) b = static_cast<char>(random() & 0xff);
  WriteText(path, bytes);
  const InputError e = CatchInputError([&] { ReadMat(path); });
  EXPECT_EQ(e.source(), path);
}

TEST(Mat, DamagedMbidFileNeverCrashes) {
  TempDir dir;
  const std::string good = dir.File("good.mat");
  WriteMat(MakeDecays(), good);
  const std::string bytes = ReadText(good);
  std::mt19937 random(7);  // fixed seed
  // 200 files, each with 8 bytes past the 128-byte header overwritten at random: every read
  // must end in a table or an InputError, never a crash or another exception.
  for (int trial = 0; trial < 200; ++trial) {
    std::string damaged = bytes;
    for (int k = 0; k < 8; ++k) {
      damaged[128 + random() % (damaged.size() - 128)] = static_cast<char>(random() & 0xff);
    }
    const std::string path = dir.File("damaged.mat");
    WriteText(path, damaged);
    try {
      ReadMat(path);
    } catch (const InputError&) {
    }
  }
}

}  // namespace
}  // namespace mbid::records
