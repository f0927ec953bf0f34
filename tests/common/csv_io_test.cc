// CSV measurements: exact round trip, hand-written files, and one test per bad input, each
// naming the file and the line (and column).
#include "mbid/common/csv_io.h"

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "mbid/common/hdf5_io.h"
#include "test_util.h"

namespace mbid {
namespace {

using testing::CatchInputError;
using ::testing::HasSubstr;
using testing::MakeMeasurement;
using testing::SameBits;
using testing::TempDir;
using testing::WriteText;

TEST(CsvIoTest, RoundTripIsExact) {
  TempDir dir;
  const std::string path = dir.File("m.csv");
  const Measurement written = MakeMeasurement(300);  // 300 samples: several output buffers' worth
  WriteMeasurementCsv(written, path);
  const Measurement read = ReadMeasurementCsv(path);
  EXPECT_EQ(read.channels, written.channels);
  EXPECT_EQ(read.units, written.units);
  EXPECT_EQ(read.source, written.source);
  EXPECT_TRUE(SameBits(read.start_time_s, written.start_time_s));
  EXPECT_TRUE(SameBits(read.sample_interval_s, written.sample_interval_s));
  EXPECT_TRUE(SameBits(read.values, written.values));
  EXPECT_TRUE(SameBits(read.CalcTime(), written.CalcTime()));
  EXPECT_EQ(dir.Entries(), std::vector<std::string>{"m.csv"});  // no temporary left over
}

TEST(CsvIoTest, ReadsAHandWrittenFile) {
  TempDir dir;
  const std::string path = dir.File("hand.csv");
  // Comments, CRLF line ends, spaces and a blank line: all tolerated. Rows at t = 0, 0.5, 1 s
  // (step 0.5 s, exact in binary); the angles are arbitrary, in plain and exponent notation.
  WriteText(path,
            "# exported by a logger\r\n"
            "time, psi, phi\r\n"
            "0.0, 0.001, -2e-3\r\n"
            "\r\n"
            "0.5, 0.002, -0.004\r\n"
            "# a comment between rows\r\n"
            "1.0, +0.003, -0.006\r\n");
  const Measurement m = ReadMeasurementCsv(path);
  EXPECT_EQ(m.channels, (std::vector<std::string>{"psi", "phi"}));
  EXPECT_EQ(m.units, (std::vector<std::string>{"rad", "rad"}));  // documented CSV default
  EXPECT_EQ(m.source, "import");                                 // Measurement's default
  EXPECT_EQ(m.samples(), 3);                                     // three data rows
  EXPECT_EQ(m.start_time_s, 0.0);                                // first time in the file
  EXPECT_EQ(m.sample_interval_s, 0.5);                           // (1.0 - 0.0) / (3 - 1)
  EXPECT_EQ(m.values(2, 0), 0.003);                              // last psi, written with a '+'
  EXPECT_EQ(m.values(0, 1), -2e-3);                              // first phi, in exponent form
}

TEST(CsvIoTest, ReadMeasurementDispatchesCsv) {
  TempDir dir;
  const std::string path = dir.File("m.CSV");     // upper case: extensions are case-insensitive
  WriteMeasurementCsv(MakeMeasurement(3), path);  // 3 samples: any valid size
  EXPECT_EQ(ReadMeasurement(path).samples(), 3);  // the 3 written
}

// ---- one bad input per test --------------------------------------------------------------

struct CsvCase {
  TempDir dir;
  std::string path;
  explicit CsvCase(const std::string& text) : path(dir.File("bad.csv")) { WriteText(path, text); }
  InputError Read() const {
    return CatchInputError([this] { ReadMeasurementCsv(path); });
  }
};

TEST(CsvBadInputTest, NonUniformTimeNamesTheLine) {
  // Line 5 is 0.025 instead of 0.03: a quarter step off the grid.
  const CsvCase c("time,psi\n0,1\n0.01,2\n0.02,3\n0.025,4\n0.04,5\n0.05,6\n");
  const InputError e = c.Read();
  EXPECT_EQ(e.source(), c.path);
  EXPECT_THAT(e.field(), ::testing::AnyOf("line 5", "line 6"));  // either step touching it
  EXPECT_THAT(e.problem(), HasSubstr("non-uniform time"));
}

// A logger that prints time with five decimals at 3 kHz rounds each time by up to 5e-6 s, 1.5%
// of the step: uniform within the printed resolution, so accepted, and the least-squares grid
// gives the step far better than any printed value (error ~ 1e-5 / N^1.5 ~ 3e-11 s here). A
// missing sample is still a step off the grid, far beyond the resolution.
TEST(CsvTest, TimePrintedWithFewDigitsIsUniformWithinItsResolution) {
  const double tau = 1.0 / 3000;
  std::string text = "time,psi\n";
  for (int j = 0; j < 3000; ++j)
    text += fmt::format("{:.5f},{}\n", 0.1 + j * tau, std::sin(0.01 * j));
  TempDir dir;
  const std::string path = dir.File("logger.csv");
  WriteText(path, text);
  const Measurement m = ReadMeasurementCsv(path);
  EXPECT_NEAR(m.sample_interval_s, tau, 1e-7 * tau);
  EXPECT_NEAR(m.start_time_s, 0.1, 1e-8);
  EXPECT_EQ(m.samples(), 3000);

  std::string gap = "time,psi\n";
  for (int j = 0; j < 3000; ++j) {
    if (j != 1500) gap += fmt::format("{:.5f},{}\n", 0.1 + j * tau, std::sin(0.01 * j));
  }
  const CsvCase c(gap);
  const InputError e = c.Read();
  EXPECT_THAT(e.problem(), HasSubstr("non-uniform time"));
  EXPECT_THAT(e.expected(), HasSubstr("printed resolution 1e-05 s"));
}

TEST(CsvBadInputTest, DecreasingTimeNamesTheLine) {
  const CsvCase c("time,psi\n0,1\n0.02,2\n0.01,3\n");  // line 4 goes back in time
  const InputError e = c.Read();
  EXPECT_EQ(e.source(), c.path);
  EXPECT_EQ(e.field(), "line 4");  // the header is line 1, so the third row is line 4
  EXPECT_THAT(e.problem(), HasSubstr("time decreases"));
  EXPECT_EQ(e.expected(), "strictly increasing time");
}

TEST(CsvBadInputTest, RepeatedTimeNamesTheLine) {
  const CsvCase c("# header comment\ntime,psi\n0,1\n0,2\n");  // line 4 repeats time 0
  const InputError e = c.Read();
  EXPECT_EQ(e.field(), "line 4");  // comment, header, first row, then the repeat
  EXPECT_THAT(e.problem(), HasSubstr("repeats"));
  // A column that rises overall (200 Hz printed to 0.01 s) is a coarse print: the rate reads it.
  const CsvCase coarse("time,psi\n0,1\n0.01,2\n0.01,3\n0.02,4\n");
  EXPECT_THAT(coarse.Read().expected(), HasSubstr("--sample-rate-hz"));
}

TEST(CsvBadInputTest, NaNNamesLineAndColumn) {
  const CsvCase c("time,psi,phi\n0,1,2\n0.1,nan,3\n");  // arbitrary values around the NaN
  const InputError e = c.Read();
  EXPECT_EQ(e.source(), c.path);
  EXPECT_EQ(e.field(), "line 3, column 2 (psi)");  // row 2 is line 3; psi is column 2
  EXPECT_EQ(e.problem(), "'nan' is not finite");
}

TEST(CsvBadInputTest, InfinityNamesLineAndColumn) {
  const CsvCase c("time,psi,phi\n0,1,2\n0.1,3,-inf\n");  // arbitrary values around the -inf
  const InputError e = c.Read();
  EXPECT_EQ(e.field(), "line 3, column 3 (phi)");  // row 2 is line 3; phi is column 3
  EXPECT_EQ(e.problem(), "'-inf' is not finite");
}

TEST(CsvBadInputTest, EmptyDataIsRejected) {
  const CsvCase c("# only a header\ntime,psi\n");
  const InputError e = c.Read();
  EXPECT_EQ(e.source(), c.path);
  EXPECT_EQ(e.field(), "line 2");                          // the header line, after one comment
  EXPECT_EQ(e.problem(), "0 data rows after the header");  // the file has none
  EXPECT_EQ(e.expected(), "at least 2 samples");           // the contract's minimum
}

TEST(CsvBadInputTest, SingleRowIsRejected) {
  const CsvCase c("time,psi\n0,1\n");  // one row at t = 0: one fewer than the minimum
  const InputError e = c.Read();
  EXPECT_EQ(e.problem(), "1 data rows after the header");  // the single row written
}

TEST(CsvBadInputTest, EmptyFileHasNoHeader) {
  const CsvCase c("# nothing but a comment\n");
  const InputError e = c.Read();
  EXPECT_EQ(e.source(), c.path);
  EXPECT_EQ(e.problem(), "no header line");
}

TEST(CsvBadInputTest, BadNumberNamesLineAndColumn) {
  const CsvCase c("time,psi,phi\n0,1,2\n0.1,1.5rad,3\n");  // a unit glued to 1.5
  const InputError e = c.Read();
  EXPECT_EQ(e.source(), c.path);
  EXPECT_EQ(e.field(), "line 3, column 2 (psi)");  // row 2 is line 3; psi is column 2
  EXPECT_EQ(e.problem(), "'1.5rad' is not a number");
}

TEST(CsvBadInputTest, EmptyCellIsABadNumber) {
  const CsvCase c("time,psi,phi\n0,1,2\n0.1,,3\n");  // psi left empty in row 2
  const InputError e = c.Read();
  EXPECT_EQ(e.field(), "line 3, column 2 (psi)");  // row 2 is line 3; psi is column 2
}

TEST(CsvBadInputTest, MissingTimeColumn) {
  const CsvCase c("psi,phi\n1,2\n3,4\n");  // arbitrary values; no time column
  const InputError e = c.Read();
  EXPECT_EQ(e.source(), c.path);
  EXPECT_EQ(e.field(), "line 1");  // the header
  EXPECT_EQ(e.problem(), "the first column is 'psi', not 'time'");
}

TEST(CsvBadInputTest, HeaderWithoutChannels) {
  const CsvCase c("time\n0\n1\n");  // two valid times, but no channel
  const InputError e = c.Read();
  EXPECT_EQ(e.field(), "line 1");  // the header
  EXPECT_EQ(e.problem(), "the header has no channel columns");
}

TEST(CsvBadInputTest, DuplicateChannelName) {
  const CsvCase c("time,psi,psi\n0,1,2\n1,3,4\n");  // arbitrary values; psi twice
  const InputError e = c.Read();
  EXPECT_EQ(e.field(), "line 1, column 3");  // the second 'psi'
  EXPECT_THAT(e.problem(), HasSubstr("appears twice"));
}

TEST(CsvBadInputTest, WrongFieldCountNamesTheLine) {
  const CsvCase c("time,psi,phi\n0,1,2\n1,3\n");  // row 2 lacks phi
  const InputError e = c.Read();
  EXPECT_EQ(e.field(), "line 3");                    // the short row
  EXPECT_EQ(e.problem(), "2 fields");                // time and psi only
  EXPECT_THAT(e.expected(), HasSubstr("3 fields"));  // time + 2 channels
}

TEST(CsvBadInputTest, UnitsCommentWithWrongCount) {
  const CsvCase c("# units: rad\ntime,psi,phi\n0,1,2\n1,3,4\n");  // 1 unit, 2 channels
  const InputError e = c.Read();
  EXPECT_EQ(e.field(), "line 1");                                 // the comment
  EXPECT_THAT(e.problem(), HasSubstr("1 units for 2 channels"));  // as written above
}

TEST(CsvBadInputTest, IntervalCommentDisagreesWithTimeColumn) {
  // The comment claims 0.02 s; the time column steps by 0.01 s.
  const CsvCase c("# sample_interval_s: 0.02\ntime,psi\n0,1\n0.01,2\n");
  const InputError e = c.Read();
  EXPECT_EQ(e.field(), "line 1");  // the comment
  EXPECT_THAT(e.problem(), HasSubstr("disagrees with the time column"));
}

TEST(CsvBadInputTest, MissingFileCannotOpen) {
  TempDir dir;
  const std::string path = dir.File("absent.csv");
  const InputError e = CatchInputError([&] { ReadMeasurementCsv(path); });
  EXPECT_EQ(e.source(), path);
  EXPECT_THAT(e.problem(), HasSubstr("cannot open"));
}

TEST(CsvBadInputTest, WritingAnInvalidMeasurementLeavesNoFile) {
  TempDir dir;
  Measurement m = MakeMeasurement(4);                        // 4 samples: any valid size
  m.values(2, 0) = std::numeric_limits<double>::infinity();  // sample 2 of psi
  const std::string path = dir.File("out.csv");
  const InputError e = CatchInputError([&] { WriteMeasurementCsv(m, path); });
  EXPECT_EQ(e.source(), path);
  EXPECT_EQ(e.field(), "psi");
  EXPECT_TRUE(dir.Entries().empty());
}

}  // namespace
}  // namespace mbid
