// Files mbid must refuse: each InputError names the file and the line and/or column, says what
// is wrong and what is expected.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <string_view>

#include "mbid/common/error.h"
#include "mbid/records/records.h"
#include "test_util.h"

namespace mbid::records {
namespace {

using mbid::testing::CatchInputError;
using mbid::testing::TempDir;
using mbid::testing::WriteText;
using ::testing::HasSubstr;

struct BadFile {
  const char* name;
  std::string_view text;  // may hold a NUL byte
  const char* field;      // the field the error must name exactly
  const char* problem;    // a phrase of the problem
  const char* expected;   // a phrase of what is expected
};

// Header on line 1, data from line 2 unless a preamble says otherwise.
const BadFile kBadFiles[] = {
    {"UnknownUnit", "t [s];x [blorp]\n0;1\n1;2\n", "column 2 (x)", "'blorp'", "udunits2"},
    {"MissingUnit", "t [s];x\n0;1\n1;2\n", "column 2 (x)", "no unit", "units:"},
    {"GramIsNotGravity", "t [s];acc [g]\n0;1\n1;2\n", "column 2 (acc)", "'g'", "gn"},
    {"TimeWithoutUnit", "Zeit;x [mm]\n0;1\n1;2\n", "column 1 (Zeit)", "no unit", "Zeit [ms]"},
    {"UnknownTimeUnit", "Zeit [fortnightz];x [mm]\n0;1\n1;2\n", "column 1 (Zeit)", "'fortnightz'",
     "s"},
    {"AngleAsTime", "Zeit [deg];x [mm]\n0;1\n1;2\n", "column 1 (Zeit)", "cannot be converted", "s"},
    {"FieldCount", "t [s];x [mm]\n0;1\n1;2\n2;3;4\n3;4\n", "line 4", "3 fields", "2 fields"},
    {"NotANumber", "t [s];x [mm]\n0;1\n1;zwei\n", "line 3, column 2 (x)", "'zwei'", "number"},
    // The first row's bad cell: the row below had been taken for the header ("no time column").
    {"FirstRowNotANumber", "t [s],x [mm]\n0,1x\n1,2\n2,3\n", "line 2, column 2 (x)", "'1x'",
     "number"},
    // Zeroed blocks of a damaged file (the same "no time column" before).
    {"NulByte", std::string_view("t [s],x [mm]\n0,1\0\n1,2\n2,3\n", 26), "line 2",
     "NUL byte at column 4", "without NUL"},
    // A number, but none a double holds: said so, not "not a number".
    {"BeyondADouble", "t [s];x [mm]\n0;1\n1;1e400\n", "line 3, column 2 (x)",
     "'1e400' is a number beyond a double's range", "number"},
    {"NanCell", "t [s];x [mm]\n0;1\n1;NaN\n2;3\n", "line 3, column 2 (x)", "empty or NaN cell",
     "--fill-gaps linear"},
    {"NonUniformTime", "t [s];x [mm]\n0;1\n1;2\n2;3\n3.5;4\n4;5\n", "line 5", "non-uniform",
     "uniform"},
    {"DecreasingTime", "t [s];x [mm]\n0;1\n2;2\n1;3\n", "line 4", "decreases", "increasing"},
    {"GapRefused", "# preamble comment\nt [s];x [mm];y [mm]\n0;1;1\n1;2;\n2;3;3\n",
     "line 4, column 3 (y)", "gap", "--fill-gaps linear"},
    {"NoTimeColumn", "a [mm];b [mm]\n0;1\n1;2\n", "header", "no time column", "sample_rate_hz"},
    {"NoHeader", "0;1\n1;2\n", "line 1", "without a line of names", "header line naming"},
    {"NoTable", "Messung 7\nok\n", "", "no header", "header"},
    {"TwoUnits", "t [s];x [mm]\ns;m\n0;1\n1;2\n", "line 1, column 2", "'mm' in the header",
     "one unit"},
    // A Latin-1 export: refused where it is read, not when the JSON summary is written.
    {"NotUtf8", "t [s];Winkel [\xB0]\n0;1\n1;2\n", "line 1", "byte 0xB0 at column 15", "UTF-8"},
};

void PrintTo(const BadFile& bad, std::ostream* os) { *os << bad.name; }

class BadFileTest : public ::testing::TestWithParam<BadFile> {};

TEST_P(BadFileTest, NamesFileAndPlace) {
  const BadFile& bad = GetParam();
  TempDir dir;
  const std::string path = dir.File("bad.csv");
  WriteText(path, std::string(bad.text));
  const InputError e = CatchInputError([&] { ImportMeasurement(path); });
  EXPECT_EQ(e.source(), path);
  EXPECT_EQ(e.field(), bad.field);
  EXPECT_THAT(e.problem(), HasSubstr(bad.problem));
  EXPECT_THAT(e.expected(), HasSubstr(bad.expected));
}

INSTANTIATE_TEST_SUITE_P(Records, BadFileTest, ::testing::ValuesIn(kBadFiles),
                         [](const ::testing::TestParamInfo<BadFile>& param_info) {
                           return std::string(param_info.param.name);
                         });

// A cell of 100,000 digits (a logger's runaway line): the message quotes its start and end and
// stays one line of a few hundred characters (it was the whole cell).
TEST(BadFileMessageTest, AHugeCellIsQuotedShort) {
  TempDir dir;
  const std::string path = dir.File("huge.csv");
  WriteText(path, "t [s];x [mm]\n0;1\n1;2x" + std::string(100000, '7') + "\n");
  const InputError e = CatchInputError([&] { ImportMeasurement(path); });
  const std::string message = e.what();
  EXPECT_LT(message.size(), 1200u) << message.substr(0, 2000);
  EXPECT_THAT(message, HasSubstr("line 3, column 2 (x): '2x777"));
  EXPECT_THAT(message, HasSubstr(" bytes ...] 777"));
  EXPECT_EQ(message.find('\n'), std::string::npos);
}

TEST(BadOptionsTest, UnknownMappedColumnListsTheColumns) {
  TempDir dir;
  const std::string path = dir.File("map.csv");
  WriteText(path, "t [s];Boom angle [deg]\n0;1\n1;2\n");
  ImportOptions options;
  options.channel_columns = {{"psi", "Boom angel"}};
  const InputError e = CatchInputError([&] { ImportMeasurement(path, options); });
  EXPECT_EQ(e.source(), path);
  EXPECT_EQ(e.field(), "channels.psi");
  EXPECT_THAT(e.problem(), HasSubstr("'Boom angel'"));
  EXPECT_THAT(e.expected(), HasSubstr("1 'Boom angle'"));
  options.channel_columns = {{"psi", "2"}};  // one data column only
  EXPECT_EQ(CatchInputError([&] { ImportMeasurement(path, options); }).field(), "channels.psi");
}

TEST(BadOptionsTest, GapAtTheFirstSampleCannotBeFilled) {
  TempDir dir;
  const std::string path = dir.File("gap.csv");
  WriteText(path, "t [s];x [mm]\n0;\n1;2\n2;3\n");
  ImportOptions options;
  options.fill_gaps = GapFill::kLinear;
  const InputError e = CatchInputError([&] { ImportMeasurement(path, options); });
  EXPECT_EQ(e.field(), "line 2, column 2 (x)");
  EXPECT_THAT(e.problem(), HasSubstr("first sample"));
  // ... and at the last.
  WriteText(path, "t [s];x [mm]\n0;1\n1;2\n2;NaN\n");
  EXPECT_EQ(CatchInputError([&] { ImportMeasurement(path, options); }).field(),
            "line 4, column 2 (x)");
}

TEST(BadOptionsTest, UnitIncompatibleWithTheModel) {
  TempDir dir;
  const std::string path = dir.File("model.csv");
  WriteText(path, "t [s];psi [mm]\n0;1\n1;2\n");
  ImportOptions options;
  options.target_units = {{"psi", "rad"}};  // the model's psi is an angle
  const InputError e = CatchInputError([&] { ImportMeasurement(path, options); });
  EXPECT_EQ(e.field(), "column 2 (psi)");
  EXPECT_THAT(e.problem(), HasSubstr("'mm'"));
  EXPECT_THAT(e.expected(), HasSubstr("rad"));
}

TEST(BadOptionsTest, UnitsKeyNamingNothing) {
  TempDir dir;
  const std::string path = dir.File("units.csv");
  WriteText(path, "t [s];x\n0;1\n1;2\n");
  ImportOptions options;
  options.units = {{"y", "mm"}};
  EXPECT_EQ(CatchInputError([&] { ImportMeasurement(path, options); }).field(), "units.y");
}

TEST(BadOptionsTest, UnsupportedExtension) {
  TempDir dir;
  const std::string path = dir.File("data.xlsx");
  WriteText(path, "");
  const InputError e = CatchInputError([&] { ImportMeasurement(path); });
  EXPECT_THAT(e.problem(), HasSubstr(".xlsx"));
  EXPECT_THAT(e.expected(), HasSubstr(".csv"));
}

}  // namespace
}  // namespace mbid::records

namespace mbid::records {
namespace {

// Hostile files found by fuzzing (fuzz/, docs/reliability.md), each a regression test: the
// reader ends in an InputError naming the file instead of crashing.
TEST(HostileFileTest, MatV73ThatCrashesLibhdf5) {
  TempDir dir;
  const std::string path = dir.File("corrupt.mat");
  std::filesystem::copy_file(
      std::string(MBID_SOURCE_DIR) + "/tests/data/records/hostile/mat73_corrupt_group_btree.mat",
      path);
  const InputError e = CatchInputError([&] { ImportMeasurement(path); });
  EXPECT_EQ(e.source(), path);
  EXPECT_THAT(e.problem(), HasSubstr("matio crashed reading the file"));
}

// A 58b header whose byte count fits the file when the header is read but not after the 11
// ASCII records (found by fuzz_logger: the reader read past the end of its buffer).
TEST(HostileFileTest, Uff58bByteCountPastTheEnd) {
  TempDir dir;
  const std::string path = dir.File("short.uff");
  std::filesystem::copy_file(
      std::string(MBID_SOURCE_DIR) + "/tests/data/records/hostile/uff58b_byte_count_past_end.uff",
      path);
  const InputError e = CatchInputError([&] { ImportMeasurement(path); });
  EXPECT_EQ(e.field(), "dataset 2 (line 17), header");
  EXPECT_THAT(e.problem(), HasSubstr("byte count 64 with"));
  EXPECT_THAT(e.problem(), HasSubstr("bytes left after the ASCII records"));
}

TEST(HostileFileTest, LvmChannelNameThatIsNotUtf8) {
  TempDir dir;
  const std::string path = dir.File("latin1.lvm");
  WriteText(path, "LabVIEW Measurement\t\nX_Value\tWinkel \xE4\n0\t1\n1\t2\n");
  const InputError e = CatchInputError([&] { ImportMeasurement(path); });
  EXPECT_EQ(e.field(), "line 2");
  EXPECT_EQ(e.problem(), "invalid UTF-8: byte 0xE4 at column 16");
}

}  // namespace
}  // namespace mbid::records
