// Thousands separators in logger exports (issue 13): 1,234.5 with ';' or tabs, 1.234,5 and
// 1 234,5 with a decimal comma, read back against the closed-form decay they were printed from;
// a cell that reads both ways ("1,234") takes the file's decimal mark, and one no number in the
// file decides is refused naming file, line and column.
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "logger_export.h"
#include "mbid/common/error.h"
#include "mbid/records/records.h"
#include "number_marks.h"
#include "test_util.h"

namespace mbid::records {
namespace {

using internal::DecimalMark;
using internal::ReadNumber;
using mbid::testing::CatchInputError;
using mbid::testing::Decay;
using mbid::testing::MakeExport;
using mbid::testing::TempDir;
using mbid::testing::WriteText;
using ::testing::HasSubstr;

// `value` with 6 decimals, its integer digits grouped in thousands by `group` and the decimal
// mark `decimal`: Grouped(-12345.5, ",", '.') = "-12,345.500000".
std::string Grouped(double value, const std::string& group, char decimal) {
  const std::string plain = fmt::format("{:.6f}", std::abs(value));
  const size_t point = plain.find('.');
  std::string integer = plain.substr(0, point);
  for (int at = static_cast<int>(integer.size()) - 3; at > 0; at -= 3) {
    integer.insert(static_cast<size_t>(at), group);
  }
  return (value < 0 ? "-" : "") + integer + decimal + plain.substr(point + 1);
}

// A displacement in mm of amplitude 2500 around 1000: values up to 3500, grouped when above 999.
const Decay kDisplacement{1.5, 0.02, 2500.0, 1000.0};

// 201 rows at 100 Hz of time (s) and the displacement, printed with 6 decimals.
std::string Export(const std::string& separator, const std::string& group, char decimal) {
  return MakeExport("t [s]" + separator + "x [mm]\n", 201, [&](int j) {
    const double t = j * 0.01;
    std::string time = fmt::format("{:.2f}", t);
    if (decimal == ',') time[time.find('.')] = ',';
    return time + separator + Grouped(kDisplacement(t), group, decimal);
  });
}

void ExpectDisplacement(const Measurement& m) {
  ASSERT_EQ(m.samples(), 201);
  EXPECT_EQ(m.units[0], "m");
  const Eigen::VectorXd t = m.CalcTime();
  for (Eigen::Index j = 0; j < m.samples(); ++j) {
    // 6 decimals in mm: a rounding error of at most 5e-7 mm, 5e-10 m; 1e-9 m leaves a factor 2
    // for the mm -> m factor's rounding.
    ASSERT_NEAR(m.values(j, 0), 1e-3 * kDisplacement(t[j]), 1e-9) << j;
  }
}

TEST(ThousandsTest, ReadingsOfOneCell) {
  // Only the decimal point reads: a fraction of other than 3 digits, or both marks.
  EXPECT_EQ(ReadNumber("1.5").Evidence(), DecimalMark::kPoint);
  EXPECT_EQ(*ReadNumber("1,234.5").point, 1234.5);
  EXPECT_EQ(ReadNumber("1,234.5").Evidence(), DecimalMark::kPoint);
  EXPECT_EQ(*ReadNumber("-12,345,678.25").point, -12345678.25);
  // Only the decimal comma reads.
  EXPECT_EQ(*ReadNumber("1.234,5").comma, 1234.5);
  EXPECT_EQ(ReadNumber("1.234,5").Evidence(), DecimalMark::kComma);
  EXPECT_EQ(*ReadNumber("1.234.567").comma, 1234567.0);  // two '.': grouping
  EXPECT_EQ(ReadNumber("1.234.567").Evidence(), DecimalMark::kComma);
  EXPECT_EQ(ReadNumber("0,123").Evidence(), DecimalMark::kComma);  // no group starts with 0
  EXPECT_EQ(*ReadNumber("1 234,5").comma, 1234.5);
  EXPECT_EQ(*ReadNumber("1\xC2\xA0"
                        "234,5")
                 .comma,
            1234.5);  // a no-break space
  EXPECT_EQ(*ReadNumber("1,5e-3").comma, 1.5e-3);
  // Both read, differently: ambiguous.
  EXPECT_TRUE(ReadNumber("1,234").Ambiguous());
  EXPECT_TRUE(ReadNumber("-999.000").Ambiguous());
  // Both read, the same: nothing to decide.
  EXPECT_FALSE(ReadNumber("1 234").Ambiguous());
  EXPECT_EQ(ReadNumber("1 234").Evidence(), DecimalMark::kUnknown);
  EXPECT_EQ(*ReadNumber("1 234").With(DecimalMark::kUnknown), 1234.0);
  // Neither: bad groups, mixed separators, a grouped exponent, a separator in the fraction.
  for (const char* bad : {"1,23,456.5", "12,34", "1,234 567.5", "1,234e3", "1.5,234", "1 2"}) {
    const auto readings = ReadNumber(bad);
    EXPECT_FALSE(readings.point && readings.point_grouped) << bad;
    EXPECT_FALSE(readings.comma && readings.comma_grouped) << bad;
  }
}

TEST(ThousandsTest, CommaGroupsWithDecimalPointInSemicolonAndTabFiles) {
  for (const std::string separator : {";", "\t"}) {
    TempDir dir;
    const std::string path = dir.File("grouped.csv");
    WriteText(path, Export(separator, ",", '.'));
    ImportReport report;
    ExpectDisplacement(ImportMeasurement(path, {}, &report));
    EXPECT_THAT(report.dialect, HasSubstr("thousands separators"));
    EXPECT_THAT(report.dialect, ::testing::Not(HasSubstr("decimal comma")));
  }
}

TEST(ThousandsTest, PointOrSpaceGroupsWithDecimalComma) {
  for (const std::string group : {".", " ", "\xE2\x80\xAF"}) {  // '.', space, narrow no-break
    TempDir dir;
    const std::string path = dir.File("grouped.csv");
    WriteText(path, Export(";", group, ','));
    ImportReport report;
    ExpectDisplacement(ImportMeasurement(path, {}, &report));
    EXPECT_THAT(report.dialect, HasSubstr("decimal comma, thousands separators"));
  }
}

TEST(ThousandsTest, AnAmbiguousColumnIsReadWithTheFilesDecimalMark) {
  // Column y holds only cells like "1,250": 1.25 or 1250. Column x's "2,5" shows a decimal
  // comma, so y is 1.25 + j / 1000 mm; with x printed "2.5" (a decimal point) y is 1250 + j.
  for (const char decimal : {',', '.'}) {
    TempDir dir;
    const std::string path = dir.File("ambiguous.csv");
    WriteText(path, MakeExport("t [s];x [mm];y [mm]\n", 5, [&](int j) {
                return fmt::format("{};2{}5;1,{:03d}", j, decimal, 250 + j);
              }));
    const Measurement m = ImportMeasurement(path);
    for (int j = 0; j < 5; ++j) {
      const double y_mm = decimal == ',' ? 1.25 + j / 1000.0 : 1250.0 + j;
      EXPECT_NEAR(m.values(j, 1), 1e-3 * y_mm, 1e-15) << j;
    }
  }
}

TEST(ThousandsTest, AGenuinelyAmbiguousNumberNamesFileLineAndColumn) {
  TempDir dir;
  const std::string path = dir.File("undecided.csv");
  // No cell shows the decimal mark: "1,250" on line 2 is the first that needs one.
  WriteText(path, "t [s];y [mm]\n0;1,250\n1;1,500\n2;2\n");
  const InputError e = CatchInputError([&] { ImportMeasurement(path); });
  EXPECT_EQ(e.source(), path);
  EXPECT_EQ(e.field(), "line 2, column 2 (y)");
  EXPECT_THAT(e.problem(), HasSubstr("'1,250' reads as 1.25 with a decimal comma and as 1250"));
  EXPECT_THAT(e.expected(), HasSubstr("decimal mark is evident"));
}

TEST(ThousandsTest, TwoDecimalMarksInOneFileNameTheCellAndTheEvidence) {
  TempDir dir;
  const std::string path = dir.File("mixed.csv");
  WriteText(path, "t [s];y [mm]\n0;0,5\n1;1.25\n");
  const InputError e = CatchInputError([&] { ImportMeasurement(path); });
  EXPECT_EQ(e.field(), "line 3, column 2 (y)");
  EXPECT_THAT(e.problem(), HasSubstr("'1.25' does not read with a decimal comma, which line 2, "
                                     "column 2 ('0,5') shows"));
}

// A ','-separated export whose quoted cells hold commas (a spreadsheet in a decimal-comma
// locale): a cell that shows a decimal comma ("0,0005") sets the file's mark; cells that only
// read both ways ("107,389") were read as thousands, 1000 times too large, and are now refused
// as ambiguous.
TEST(ThousandsTest, QuotedCommasOfACommaSeparatedFileShowTheirMarkOrAreRefused) {
  TempDir dir;
  const std::string shown = dir.File("quoted_comma.csv");
  WriteText(shown,
            "\"t [s]\",\"y [mm]\"\n\"0\",\"1,001\"\n\"0,0005\",\"0,999\"\n"
            "\"0,001\",\"1,5\"\n");
  const Measurement m = ImportMeasurement(shown);
  EXPECT_NEAR(m.sample_interval_s, 0.0005, 1e-15);
  EXPECT_NEAR(m.values(0, 0), 1.001e-3, 1e-15);  // mm -> m
  EXPECT_NEAR(m.values(2, 0), 1.5e-3, 1e-15);
  const std::string undecided = dir.File("quoted_thousands.csv");
  WriteText(undecided, "\"t [ms]\",\"y [mm]\"\n\"0\",\"107,389\"\n\"1\",\"107,365\"\n");
  const InputError e = CatchInputError([&] { ImportMeasurement(undecided); });
  EXPECT_EQ(e.field(), "line 2, column 2 (y)");
  EXPECT_THAT(e.problem(), HasSubstr("'107,389' reads as 107.389 with a decimal comma"));
  // Plain ','-separated files keep their decimal point, "1.234" included.
  const std::string plain = dir.File("plain.csv");
  WriteText(plain, "t [s],y [mm]\n0,1.234\n0.5,2.5\n1,3\n");
  EXPECT_NEAR(ImportMeasurement(plain).values(0, 0), 1.234e-3, 1e-15);
}

}  // namespace
}  // namespace mbid::records
