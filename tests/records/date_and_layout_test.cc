// Layouts spreadsheets and loggers write around the numbers: a separator at every line's end,
// dates day first or month first, a date column beside a time of day, a time of day that passes
// midnight.
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "iso_time.h"
#include "logger_export.h"
#include "mbid/common/error.h"
#include "mbid/records/records.h"
#include "test_util.h"

namespace mbid::records {
namespace {

using mbid::testing::CatchInputError;
using mbid::testing::Decay;
using mbid::testing::MakeExport;
using mbid::testing::Print;
using mbid::testing::TempDir;
using mbid::testing::WriteText;
using ::testing::HasSubstr;

constexpr double kDegree = M_PI / 180;

// 9 printed digits: error <= 5e-9 of amplitude + offset (as import_test.cc).
void ExpectDecayRead(const Measurement& m, int c, const Decay& decay, double factor) {
  const Eigen::VectorXd t = m.CalcTime();
  for (Eigen::Index j = 0; j < m.samples(); ++j) {
    ASSERT_NEAR(m.values(j, c), decay(t[j]) * factor,
                1e-8 * (std::abs(decay.amplitude) + std::abs(decay.offset)) * factor)
        << "sample " << j;
  }
}

// "hh:mm:ss,mmm" of second-of-day s (s < 86400), as German loggers print it.
std::string PrintTimeOfDay(double s) {
  const int ms = static_cast<int>(std::lround(s * 1000));
  return fmt::format("{:02d}:{:02d}:{:02d},{:03d}", ms / 3600000, ms / 60000 % 60, ms / 1000 % 60,
                     ms % 1000);
}

TEST(DateAndLayoutTest, ASeparatorAtEveryLineEndIsNoColumn) {
  TempDir dir;
  const Decay psi;
  // Header and rows both end with ';' (a spreadsheet's export, after Excel's "sep=;" line).
  const std::string both = dir.File("both.csv");
  WriteText(both, MakeExport("sep=;\nTime [s];psi [deg];\n", 201, [&](int j) {
              return fmt::format("{};{};", Print(j * 0.01, true), Print(psi(j * 0.01), true));
            }));
  ImportReport report;
  Measurement m = ImportMeasurement(both, {}, &report);
  EXPECT_EQ(m.channels, std::vector<std::string>{"psi"});
  EXPECT_THAT(report.dialect, HasSubstr("1 empty column ignored"));
  ExpectDecayRead(m, 0, psi, kDegree);
  // Only the rows end with ',' (some loggers): the header still finds them.
  const std::string rows = dir.File("rows.csv");
  WriteText(rows, MakeExport("Time [s],psi [deg]\n", 201, [&](int j) {
              return fmt::format("{},{},", Print(j * 0.01), Print(psi(j * 0.01)));
            }));
  m = ImportMeasurement(rows);
  EXPECT_EQ(m.channels, std::vector<std::string>{"psi"});
  ExpectDecayRead(m, 0, psi, kDegree);
  // A column with a name stays a channel even when it is all gaps: refused as gaps, not dropped.
  const std::string named = dir.File("named.csv");
  WriteText(named, MakeExport("Time [s],psi [deg],spare [deg]\n", 201, [&](int j) {
              return fmt::format("{},{},", Print(j * 0.01), Print(psi(j * 0.01)));
            }));
  try {
    ImportMeasurement(named);
    ADD_FAILURE() << "a named column of gaps was dropped";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("column 3"));
    EXPECT_THAT(e.what(), HasSubstr("gap"));
  }
}

TEST(DateAndLayoutTest, DateColumnBesideATimeOfDayAcrossMidnight) {
  TempDir dir;
  const std::string path = dir.File("dates.csv");
  const Decay psi;
  // 10 s at 100 Hz from 23:59:55 on 28 Nov: the date turns at row 500.
  WriteText(path, MakeExport("Datum;Uhrzeit;psi [deg]\n", 1001, [&](int j) {
              const double s = 86395.0 + j * 0.01;
              const int day = s < 86400 ? 28 : 29;
              return fmt::format("{:02d}.11.2026;{};{}", day, PrintTimeOfDay(std::fmod(s, 86400.0)),
                                 Print(psi(j * 0.01), true));
            }));
  ImportReport report;
  const Measurement m = ImportMeasurement(path, {}, &report);
  EXPECT_EQ(m.channels, std::vector<std::string>{"psi"});  // neither date nor time is a channel
  EXPECT_THAT(report.dialect, HasSubstr("dates in column 1"));
  EXPECT_EQ(m.samples(), 1001);
  EXPECT_EQ(m.start_time_s, 0.0);                 // seconds from the first sample
  EXPECT_NEAR(m.sample_interval_s, 0.01, 1e-15);  // whole seconds subtracted first: exact
  ExpectDecayRead(m, 0, psi, kDegree);
  // The same times without the date column: the day is carried over midnight.
  const std::string alone = dir.File("alone.csv");
  WriteText(alone, MakeExport("Uhrzeit;psi [deg]\n", 1001, [&](int j) {
              const double s = 86395.0 + j * 0.01;
              return fmt::format("{};{}", PrintTimeOfDay(std::fmod(s, 86400.0)),
                                 Print(psi(j * 0.01), true));
            }));
  const Measurement m2 = ImportMeasurement(alone);
  EXPECT_NEAR(m2.sample_interval_s, 0.01, 1e-15);
  ExpectDecayRead(m2, 0, psi, kDegree);
}

TEST(DateAndLayoutTest, DayFirstDateAndTimeInOneCell) {
  TempDir dir;
  const std::string path = dir.File("de.csv");
  const Decay psi;
  WriteText(path, MakeExport("Date/Time;psi [deg]\n", 301, [&](int j) {
              return fmt::format("01.03.2026 {};{}", PrintTimeOfDay(43200.0 + j * 0.01),
                                 Print(psi(j * 0.01), true));
            }));
  const Measurement m = ImportMeasurement(path);
  EXPECT_EQ(m.channels, std::vector<std::string>{"psi"});
  EXPECT_NEAR(m.sample_interval_s, 0.01, 1e-15);
  ExpectDecayRead(m, 0, psi, kDegree);
  // A row whose time lost its date is refused naming its line.
  const std::string mixed = dir.File("mixed.csv");
  WriteText(mixed,
            "Date/Time;psi [deg]\n01.03.2026 12:00:00,000;1\n"
            "01.03.2026 12:00:00,010;1\n12:00:00,020;1\n");
  try {
    ImportMeasurement(mixed);
    ADD_FAILURE() << "a time without its date was read";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("line 4"));
    EXPECT_THAT(e.what(), HasSubstr("date and time as in the first row"));
  }
}

TEST(DateAndLayoutTest, DatesAndTimesOfDayParse) {
  using internal::ParseDate;
  using internal::ParseTimestamp;
  using internal::SecondsBetween;
  using internal::Timestamp;
  Timestamp iso, slash, dotted, date;
  ASSERT_TRUE(ParseTimestamp("2026-03-01 12:00:00.5", &iso));
  ASSERT_TRUE(ParseTimestamp("2026/03/01 12:00:00,5", &slash));
  ASSERT_TRUE(ParseTimestamp("01.03.2026 12:00:00", &dotted));  // day first
  EXPECT_DOUBLE_EQ(SecondsBetween(iso, slash), 0.0);
  EXPECT_DOUBLE_EQ(SecondsBetween(dotted, iso), 0.5);
  ASSERT_TRUE(ParseDate("01.03.2026", &date));
  EXPECT_EQ(iso.seconds - date.seconds, 12 * 3600);
  Timestamp morning;
  ASSERT_TRUE(ParseTimestamp("9:05:00.25", &morning));  // one-digit hour, no date
  EXPECT_FALSE(morning.has_date);
  EXPECT_EQ(morning.seconds, 9 * 3600 + 5 * 60);
  EXPECT_EQ(morning.decimals, 2);
  // "01/03/2026" is the 1st of March day first, the 3rd of January month first.
  Timestamp day_first, month_first;
  ASSERT_TRUE(ParseTimestamp("01/03/2026 12:00:00", &day_first));
  EXPECT_DOUBLE_EQ(SecondsBetween(dotted, day_first), 0.0);
  ASSERT_TRUE(
      ParseTimestamp("03/01/2026 12:00:00.5", &month_first, internal::SlashOrder::kMonthFirst));
  EXPECT_DOUBLE_EQ(SecondsBetween(iso, month_first), 0.0);
  Timestamp t;
  // Impossible dates and times are not read.
  for (const char* text : {"13/13/2026 12:00:00", "32.01.2026 12:00:00", "01.13.2026", "24:00:00",
                           "12:60:00", "1.3.2026 12:00:00", "9:05", "01/03.2026 12:00:00"}) {
    EXPECT_FALSE(ParseTimestamp(text, &t)) << text;
  }
  EXPECT_FALSE(ParseTimestamp("12/13/2026 12:00:00", &t));  // day first: no 13th month
  EXPECT_TRUE(ParseTimestamp("12/13/2026 12:00:00", &t, internal::SlashOrder::kMonthFirst));
  EXPECT_FALSE(ParseDate("01.13.2026", &t));
}

// "MM/DD/YYYY hh:mm:ss.sss" at 100 Hz from `start_s` after midnight of `first_date`'s day,
// printed as a US logger prints it (dates month first) or day first.
std::string SlashExport(int month, int day, double start_s, bool month_first, int samples,
                        const Decay& psi) {
  return MakeExport("Date/Time,psi [deg]\n", samples, [&](int j) {
    const int ms = static_cast<int>(std::lround((start_s + j * 0.01) * 1000));
    const int d = day + ms / 86400000;  // the test dates stay inside their month
    const int of_day = ms % 86400000;
    return fmt::format("{:02d}/{:02d}/2026 {:02d}:{:02d}:{:02d}.{:03d},{}", month_first ? month : d,
                       month_first ? d : month, of_day / 3600000, of_day / 60000 % 60,
                       of_day / 1000 % 60, of_day % 1000, Print(psi(j * 0.01)));
  });
}

TEST(DateAndLayoutTest, SlashDatesAreReadInTheOrderTheRecordTells) {
  TempDir dir;
  const Decay psi;
  const std::string path = dir.File("slash.csv");
  // November 28th, month first (a day of 28 tells the order), across midnight.
  WriteText(path, SlashExport(11, 28, 86399.0, true, 301, psi));
  Measurement m = ImportMeasurement(path);
  EXPECT_NEAR(m.sample_interval_s, 0.01, 1e-12);
  ExpectDecayRead(m, 0, psi, kDegree);
  // March 1st to 2nd: 03/01 -> 03/02 runs on by a day month first; day first it would jump from
  // January 3rd to February 3rd, so month first it is.
  WriteText(path, SlashExport(3, 1, 86399.0, true, 301, psi));
  m = ImportMeasurement(path);
  EXPECT_NEAR(m.sample_interval_s, 0.01, 1e-12);
  ExpectDecayRead(m, 0, psi, kDegree);
  // The same days day first (01/03 -> 02/03).
  WriteText(path, SlashExport(3, 1, 86399.0, false, 301, psi));
  m = ImportMeasurement(path);
  EXPECT_NEAR(m.sample_interval_s, 0.01, 1e-12);
  ExpectDecayRead(m, 0, psi, kDegree);
  // All of one ambiguous day: the times are the same in either order.
  WriteText(path, SlashExport(3, 1, 43200.0, true, 301, psi));
  m = ImportMeasurement(path);
  EXPECT_NEAR(m.sample_interval_s, 0.01, 1e-12);
  ExpectDecayRead(m, 0, psi, kDegree);
}

TEST(DateAndLayoutTest, SlashDatesInBothOrdersAreRefused) {
  TempDir dir;
  const std::string path = dir.File("both.csv");
  WriteText(path,
            "Date/Time,psi [deg]\n13/01/2026 12:00:00.00,1\n13/01/2026 12:00:00.01,1\n"
            "01/13/2026 12:00:00.02,1\n");
  try {
    ImportMeasurement(path);
    ADD_FAILURE() << "dates in both orders were read";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("line 4"));
    EXPECT_THAT(e.what(), HasSubstr("day first or month first"));
  }
}

TEST(DateAndLayoutTest, AStatedRateSettlesACoarselyPrintedTimeColumn) {
  TempDir dir;
  const Decay psi;
  // 80 Hz printed to 0.01 s: the column alone cannot tell its 0.02 s steps from dropped samples
  // (common/measurement_test.cc); with the rate stated, every time lies within 0.01 s of j / 80.
  const std::string path = dir.File("coarse.csv");
  WriteText(path, MakeExport("t [s],psi [deg]\n", 640, [&](int j) {
              return fmt::format("{:.2f},{}", j / 80.0, Print(psi(j / 80.0)));
            }));
  EXPECT_THROW(ImportMeasurement(path), InputError);
  ImportOptions options;
  options.sample_rate_hz = 80;
  ImportReport report;
  const Measurement m = ImportMeasurement(path, options, &report);
  EXPECT_EQ(m.sample_interval_s, 1.0 / 80);
  EXPECT_NEAR(m.start_time_s, 0.0, 0.005);  // within half the printed digit
  ExpectDecayRead(m, 0, psi, kDegree);
  // 100 Hz printed to 0.01 s with sample 300 missing: the stated rate finds it.
  const std::string dropped = dir.File("dropped.csv");
  WriteText(dropped, MakeExport("t [s],psi [deg]\n", 800, [&](int j) {
              const int k = j < 300 ? j : j + 1;
              return fmt::format("{:.2f},{}", k / 100.0, Print(psi(k / 100.0)));
            }));
  options.sample_rate_hz = 100;
  try {
    ImportMeasurement(dropped, options);
    ADD_FAILURE() << "a dropped sample was read as uniform";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("line 302"));  // header + 300 samples before it
    EXPECT_THAT(e.what(), HasSubstr("dropped or repeated sample"));
  }
  // A stated rate that is not the column's is refused too.
  options.sample_rate_hz = 81;
  EXPECT_THROW(ImportMeasurement(path, options), InputError);
  // Where the column is printed finely enough to show its own grid (100 Hz to 1 ms), at the first
  // sample off the stated grid and with the column's rate (it was named at the last sample, as
  // a dropped or repeated one).
  const std::string fine = dir.File("fine.csv");
  WriteText(fine, MakeExport("t [s],psi [deg]\n", 800, [&](int j) {
              return fmt::format("{:.3f},{}", j / 100.0, Print(psi(j / 100.0)));
            }));
  options.sample_rate_hz = 200;
  const InputError other = CatchInputError([&] { ImportMeasurement(fine, options); });
  EXPECT_THAT(other.what(),
              HasSubstr(":line 3: the time column steps 0.01 s (100 Hz), not the stated 200 Hz"));
  // 200 Hz printed to 0.01 s: every other time repeats the one before (0.00, 0.01, 0.01, ...),
  // which the stated rate reads as its grid (it was refused as a repeated time).
  const std::string repeats = dir.File("repeats.csv");
  WriteText(repeats, MakeExport("t [s],psi [deg]\n", 400, [&](int j) {
              return fmt::format("{:.2f},{}", j / 200.0, Print(psi(j / 200.0)));
            }));
  options.sample_rate_hz = 200;
  EXPECT_EQ(ImportMeasurement(repeats, options).sample_interval_s, 1.0 / 200);
}

// A logger that stamps its blocks from a PC clock: 1 kHz, the stamps scattered by up to 30 us
// (a trial's logger file; it could not be read at all). The values are the grid's, j / 1000 Hz.
std::string JitteredExport(int rows, double rate_error, int dropped_at = -1) {
  const Decay psi;
  return MakeExport("t [s],psi [deg]\n", rows, [&](int j) {
    const int k = dropped_at >= 0 && j >= dropped_at ? j + 1 : j;
    // A fixed scatter of +-30 us that no straight line follows (golden-ratio sequence).
    const double jitter = 30e-6 * (2 * std::fmod(0.6180339887 * k, 1.0) - 1);
    return fmt::format("{:.6f},{}", k * 1e-3 * (1 + rate_error) + jitter, Print(psi(k * 1e-3)));
  });
}

TEST(DateAndLayoutTest, StampsWithJitterAreReadAtAStatedRate) {
  TempDir dir;
  const Decay psi;
  const std::string path = dir.File("jitter.csv");
  WriteText(path, JitteredExport(3000, 0));
  // Alone, the column is not uniform; the message says what reads it.
  const InputError e = CatchInputError([&] { ImportMeasurement(path); });
  EXPECT_THAT(e.what(), HasSubstr("non-uniform time"));
  EXPECT_THAT(e.what(), HasSubstr("stamps with jitter, its rate (sample_rate_hz"));
  ImportOptions options;
  options.sample_rate_hz = 1000;
  ImportReport report;
  const Measurement m = ImportMeasurement(path, options, &report);
  EXPECT_EQ(m.sample_interval_s, 1e-3);
  EXPECT_NEAR(m.start_time_s, 0.0, 2e-6);         // the mean of 3000 stamps' scatter, < 30 us / 15
  EXPECT_EQ(m.sample_interval_uncertainty, 0.0);  // no drift: the stated rate is the stamps'
  for (Eigen::Index j = 0; j < m.samples(); ++j) {  // 9 printed digits, as ExpectDecayRead
    ASSERT_NEAR(m.values(j, 0), psi(1e-3 * j) * kDegree,
                1e-8 * (psi.amplitude + psi.offset) * kDegree)
        << j;
  }
  EXPECT_THAT(report.conversions[0],
              HasSubstr("scattered by up to 3.0"));  // 30 us about their mean
  EXPECT_THAT(report.conversions[0], HasSubstr("(3 % of the interval)"));
  EXPECT_TRUE(report.warnings.empty());  // the identification judges its residual
  // A dropped sample amid the jitter is still found: it moves the stamps by a whole interval.
  const std::string dropped = dir.File("dropped.csv");
  WriteText(dropped, JitteredExport(3000, 0, 1200));
  const InputError d = CatchInputError([&] { ImportMeasurement(dropped, options); });
  EXPECT_THAT(d.what(), HasSubstr("dropped or repeated sample"));
  // A stated rate that is not the stamps' is said so (it was "off the grid by 3 s").
  ImportOptions half;
  half.sample_rate_hz = 500;
  const InputError other = CatchInputError([&] { ImportMeasurement(path, half); });
  // (the first and last stamps jitter too: the mean step is 1000 Hz to 1e-5)
  EXPECT_THAT(other.what(), HasSubstr("Hz) on average, not the stated 500 Hz"));
  // Stamps from a clock 50 ppm off the stated rate: 0.15 ms over 3 s, read at the stated rate
  // with the disagreement as the time base's uncertainty.
  const std::string drifting = dir.File("drift.csv");
  WriteText(drifting, JitteredExport(3000, 50e-6));
  ImportReport drift_report;
  const Measurement drift = ImportMeasurement(drifting, options, &drift_report);
  EXPECT_EQ(drift.sample_interval_s, 1e-3);
  EXPECT_NEAR(drift.sample_interval_uncertainty, 50e-6, 5e-6);  // + the slope's own std
  EXPECT_THAT(drift_report.conversions[0], HasSubstr("ppm off the stated one"));
}

TEST(DateAndLayoutTest, AColumnOfTextIsNoChannel) {
  TempDir dir;
  const Decay psi;
  // A logger's status column ("OK", "MARK" every second) between two channels.
  const std::string path = dir.File("status.csv");
  WriteText(path, MakeExport("Time [s];psi [deg];Status;phi [deg]\n", 301, [&](int j) {
              return fmt::format("{};{};{};{}", Print(j * 0.01, true), Print(psi(j * 0.01), true),
                                 j % 100 == 0 ? "MARK" : "OK", Print(psi(j * 0.01), true));
            }));
  ImportReport report;
  const Measurement m = ImportMeasurement(path, {}, &report);
  EXPECT_EQ(m.channels, (std::vector<std::string>{"psi", "phi"}));
  EXPECT_THAT(report.dialect, HasSubstr("text in column 3 (Status), no channel"));
  ExpectDecayRead(m, 1, psi, kDegree);
  // Asked for as a channel, it is refused naming its text.
  ImportOptions options;
  options.channel_columns = {{"x", "Status"}};
  try {
    ImportMeasurement(path, options);
    ADD_FAILURE() << "a text column became a channel";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("holds text ('MARK' at line 2)"));
  }
  // A column of numbers with one stray word is still refused at that cell.
  const std::string stray = dir.File("stray.csv");
  WriteText(stray, MakeExport("Time [s];psi [deg];phi [deg]\n", 301, [&](int j) {
              return fmt::format("{};{};{}", Print(j * 0.01, true), Print(psi(j * 0.01), true),
                                 j == 150 ? "ERR" : Print(psi(j * 0.01), true));
            }));
  try {
    ImportMeasurement(stray);
    ADD_FAILURE() << "a stray word in a column of numbers was read";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("line 152, column 3"));
    EXPECT_THAT(e.what(), HasSubstr("'ERR' is not a number"));
  }
}

}  // namespace
}  // namespace mbid::records
