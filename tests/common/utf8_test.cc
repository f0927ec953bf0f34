// UTF-8 checks of text read from files: names and units go into JSON summaries, so a bad byte
// is refused where it is read (exit 2) with the file and place, not after the whole cycle.
#include "mbid/common/utf8.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "mbid/common/csv_io.h"
#include "mbid/common/yaml_reader.h"
#include "test_util.h"

namespace mbid {
namespace {

using testing::CatchInputError;
using ::testing::HasSubstr;

TEST(Utf8Test, AcceptsAsciiAndMultiByteCharacters) {
  EXPECT_EQ(FindInvalidUtf8(""), std::string_view::npos);
  EXPECT_EQ(FindInvalidUtf8("psi [rad]"), std::string_view::npos);
  EXPECT_EQ(FindInvalidUtf8("Winkel [\xC2\xB0] \xE2\x82\xAC \xF0\x9F\x99\x82"),
            std::string_view::npos);
  EXPECT_EQ(FindInvalidUtf8("\xF4\x8F\xBF\xBF"), std::string_view::npos);  // U+10FFFF
}

TEST(Utf8Test, FindsTheFirstInvalidByte) {
  EXPECT_EQ(FindInvalidUtf8("ab\xE9"
                            "cd"),
            2u);                                       // Latin-1 e-acute
  EXPECT_EQ(FindInvalidUtf8("\x80"), 0u);              // a lone continuation byte
  EXPECT_EQ(FindInvalidUtf8("x\xC3"), 1u);             // truncated at the end
  EXPECT_EQ(FindInvalidUtf8("\xC0\xAF"), 0u);          // overlong '/'
  EXPECT_EQ(FindInvalidUtf8("\xE0\x80\xAF"), 0u);      // overlong, 3 bytes
  EXPECT_EQ(FindInvalidUtf8("\xED\xA0\x80"), 0u);      // a UTF-16 surrogate
  EXPECT_EQ(FindInvalidUtf8("\xF4\x90\x80\x80"), 0u);  // above U+10FFFF
  EXPECT_EQ(FindInvalidUtf8("\xC3\xA9\xFF"), 2u);
}

TEST(Utf8Test, ValidateNamesTheSourceAndField) {
  const InputError e = CatchInputError([] { ValidateUtf8("ph\xE9", "rec.mat", "channel 2 name"); });
  EXPECT_EQ(e.source(), "rec.mat");
  EXPECT_EQ(e.field(), "channel 2 name");
  EXPECT_EQ(e.problem(), "invalid UTF-8: byte 0xE9 at byte 3");
  EXPECT_THAT(e.expected(), HasSubstr("UTF-8 text"));
}

TEST(Utf8Test, TextErrorsNameLineAndColumn) {
  const InputError e =
      CatchInputError([] { ValidateUtf8Text("name: a\nmodel:\n  b\xE9: 1\n", "s.yaml"); });
  EXPECT_EQ(e.field(), "line 3");
  EXPECT_EQ(e.problem(), "invalid UTF-8: byte 0xE9 at column 4");
  const InputError first = CatchInputError([] { ValidateUtf8Text("\xFFx", "s.yaml"); });
  EXPECT_EQ(first.field(), "line 1");
  EXPECT_EQ(first.problem(), "invalid UTF-8: byte 0xFF at column 1");
}

// NUL is valid UTF-8 but no text: a scenario starting with zeroed blocks was "not a mapping".
TEST(Utf8Test, ANulByteIsNamedWhereItIs) {
  using namespace std::string_view_literals;
  const InputError e = CatchInputError([] { ValidateUtf8Text("\0\1\2name: x\n"sv, "s.yaml"); });
  EXPECT_EQ(e.field(), "line 1");
  EXPECT_THAT(e.problem(), HasSubstr("NUL byte at column 1"));
  const InputError later =
      CatchInputError([] { ValidateUtf8Text("a: 1\nb: \0\xFF\n"sv, "s.yaml"); });
  EXPECT_EQ(later.field(), "line 2");
  EXPECT_THAT(later.problem(), HasSubstr("NUL byte at column 4"));  // the first bad byte
}

TEST(Utf8Test, YamlThatIsNotUtf8IsRefusedWhereItIsRead) {
  const InputError e = CatchInputError([] {
    YamlReader::FromString(
        "name: kran-\xFC"
        "ber\nmodel: {}\n",
        "scenario.yaml");
  });
  EXPECT_EQ(e.source(), "scenario.yaml");
  EXPECT_EQ(e.field(), "line 1");
  EXPECT_EQ(e.problem(), "invalid UTF-8: byte 0xFC at column 12");
}

TEST(Utf8Test, CsvChannelNameThatIsNotUtf8IsRefused) {
  testing::TempDir dir;
  const std::string path = dir.File("m.csv");
  testing::WriteText(path, "time,psi,ph\xE9\n0,1,2\n0.1,1,2\n");
  const InputError e = CatchInputError([&] { ReadMeasurementCsv(path); });
  EXPECT_EQ(e.source(), path);
  EXPECT_EQ(e.field(), "line 1");
  EXPECT_EQ(e.problem(), "invalid UTF-8: byte 0xE9 at column 12");
}

TEST(Utf8Test, MeasurementValidateChecksNamesAndUnits) {
  Measurement m = testing::MakeMeasurement(4);
  m.units[1] = "\xB0";  // a Latin-1 degree sign
  const InputError e = CatchInputError([&] { m.Validate("rec.uff"); });
  EXPECT_EQ(e.field(), "channel 2 unit");
  EXPECT_EQ(e.problem(), "invalid UTF-8: byte 0xB0 at byte 1");
}

}  // namespace
}  // namespace mbid
