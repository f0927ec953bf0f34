// Logger exports in each dialect, written from a closed-form decay and read back in SI; mbid's
// own files through the same door, bit for bit.
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "logger_export.h"
#include "mbid/common/csv_io.h"
#include "mbid/common/hdf5_io.h"
#include "mbid/records/records.h"
#include "test_util.h"

namespace mbid::records {
namespace {

using mbid::testing::CatchInputError;
using mbid::testing::Decay;
using mbid::testing::MakeExport;
using mbid::testing::Print;
using mbid::testing::SameBits;
using mbid::testing::TempDir;
using mbid::testing::WriteText;
using ::testing::HasSubstr;

constexpr double kDeg = M_PI / 180;
// Values are printed with 9 significant digits: error <= 5e-9 of the largest value, amplitude
// + offset; 1e-8 of that leaves a factor 2 for the unit factor's and the sum's rounding.
double PrintTolerance(const Decay& decay, double factor) {
  return 1e-8 * (std::abs(decay.amplitude) + std::abs(decay.offset)) * std::abs(factor);
}

void ExpectChannel(const Measurement& m, int c, const Decay& decay, double factor) {
  const Eigen::VectorXd t = m.CalcTime();
  for (Eigen::Index j = 0; j < m.samples(); ++j) {
    ASSERT_NEAR(m.values(j, c), decay(t[j]) * factor, PrintTolerance(decay, factor))
        << "channel " << c << ", sample " << j;
  }
}

TEST(ImportTest, SemicolonDecimalCommaPreambleUnitsRowMilliseconds) {
  TempDir dir;
  const std::string path = dir.File("logger.csv");
  const Decay angle;                        // degrees
  const Decay acc{1.5, 0.02, 250.0, 20.0};  // mm/s^2
  const std::string head =
      "Logger: XYZ-200\nSerial: 12345\nSample rate: 100 Hz\n\nZeit;Boom angle;Acc\nms;deg;mm/s^2\n";
  // 201 rows at 100 Hz: 2 s, three periods of the 1.5 Hz decay.
  WriteText(path, MakeExport(head, 201, [&](int j) {
              const double t = j * 0.01;
              return fmt::format("{};{};{}", Print(10.0 * j + 0.0, true), Print(angle(t), true),
                                 Print(acc(t), true));
            }));
  ImportReport report;
  const Measurement m = ImportMeasurement(path, {}, &report);
  EXPECT_EQ(report.format, "csv");
  EXPECT_THAT(report.dialect, HasSubstr("';'-separated"));
  EXPECT_THAT(report.dialect, HasSubstr("3 preamble lines"));  // the blank line is not one
  EXPECT_THAT(report.dialect, HasSubstr("units row"));
  EXPECT_EQ(m.channels, (std::vector<std::string>{"Boom angle", "Acc"}));
  EXPECT_EQ(m.units, (std::vector<std::string>{"rad", "m/s^2"}));
  EXPECT_EQ(m.samples(), 201);
  EXPECT_EQ(m.start_time_s, 0.0);                 // the first time, 0 ms
  EXPECT_NEAR(m.sample_interval_s, 0.01, 1e-15);  // 10 ms: a few ulps of the ms -> s factor
  ExpectChannel(m, 0, angle, kDeg);
  ExpectChannel(m, 1, acc, 1e-3);
  ASSERT_EQ(report.conversions.size(), 3u);  // time, angle, acceleration
  EXPECT_THAT(report.conversions[1], HasSubstr("Boom angle: deg -> rad"));
}

TEST(ImportTest, DecimalCommaFlaggedWhenUsed) {
  TempDir dir;
  const std::string path = dir.File("comma.csv");
  WriteText(path, "t [s];x [mm]\n0,0;1,5\n0,5;2,5\n1,0;3,5\n");  // three rows, step 0.5 s
  ImportReport report;
  const Measurement m = ImportMeasurement(path, {}, &report);
  EXPECT_THAT(report.dialect, HasSubstr("decimal comma"));
  EXPECT_DOUBLE_EQ(m.values(1, 0), 2.5e-3);  // 2,5 mm
  EXPECT_EQ(m.sample_interval_s, 0.5);
}

// An inclinometer's ';' export with decimal commas and trailing zeros trimmed: two data lines
// ("1,49;34,999;-12" then "1,5;35;-11,998") split on ',' as a 3-field header and a row, which
// tied with the real header's 3 fields and won; the next line's 4 fields refused the file (8 of
// 8 such exports, ';' and tab, a trial's). A header's rows must go on as it says.
TEST(ImportTest, DataLinesThatSplitLikeAHeaderOnCommasAreNoHeader) {
  TempDir dir;
  for (const char* separator : {";", "\t"}) {
    std::string text = fmt::format("time [s]{0}a [deg]{0}b [deg]\n", separator);
    const char* rows[] = {"1,48;35,017;-12,014", "1,49;34,999;-12", "1,5;35;-11,998",
                          "1,51;35,011;-12,017", "1,52;35,009;-12,018"};
    for (int j = 0; j < 148; ++j) {  // 1.47 s of rest before them, one sample per 10 ms
      std::string time = fmt::format("{:g}", j * 0.01);
      std::replace(time.begin(), time.end(), '.', ',');
      text += fmt::format("{}{}35,02{}-12,01\n", time, separator, separator);
    }
    for (const char* row : rows) {
      std::string line = row;
      for (char& c : line) {
        if (c == ';') c = separator[0];
      }
      text += line + "\n";
    }
    const std::string path = dir.File(separator[0] == ';' ? "semicolon.csv" : "tab.txt");
    WriteText(path, text);
    ImportReport report;
    const Measurement m = ImportMeasurement(path, {}, &report);
    EXPECT_EQ(m.samples(), 153) << separator;
    EXPECT_EQ(m.channels, (std::vector<std::string>{"a", "b"}));
    EXPECT_NEAR(m.values(149, 0), 34.999 * kDeg, 1e-12);  // "1,49;34,999;-12"
    EXPECT_NEAR(m.values(149, 1), -12 * kDeg, 1e-12);
  }
}

// A unitless `time` in ms of a 20 kHz logger reads as 20 Hz: its 1.2 Hz decay then swings over
// 16,667 samples per period (periods of 833 s), and the reading is doubted; a true 20 Hz record
// of the same decay (17 samples per period, then 1950 s at rest), a true 2 kHz one, or the same
// file with its unit stated, is not.
TEST(ImportTest, AUnitlessTimeOfThousandsOfSamplesPerPeriodIsDoubted) {
  TempDir dir;
  const auto write = [&](const std::string& name, double step, double rate_hz,
                         double frequency_hz = 1.2) {
    std::string text = "time,x [mm]\n";
    for (int j = 0; j < 40000; ++j) {  // 2 s at 20 kHz, or 2000 s at 20 Hz
      const double t = j / rate_hz;
      text += fmt::format("{},{:.9g}\n", j * step,
                          std::exp(-0.2 * t) * std::cos(2 * M_PI * frequency_hz * t));
    }
    WriteText(dir.File(name), text);
    return dir.File(name);
  };
  ImportReport report;
  ImportMeasurement(write("ms.csv", 0.05, 20000.0), {}, &report);  // 0.05 ms steps
  ASSERT_EQ(report.warnings.size(), 1u);
  EXPECT_THAT(report.warnings[0], HasSubstr("every frequency is 1000 times too low"));
  ImportOptions stated;
  stated.time_unit = "s";
  ImportMeasurement(dir.File("ms.csv"), stated, &report);
  EXPECT_TRUE(report.warnings.empty());
  ImportMeasurement(write("slow.csv", 0.05, 20.0), {}, &report);  // a true 20 Hz logger
  EXPECT_TRUE(report.warnings.empty()) << report.warnings.front();
  // A true 2 kHz logger in s: 1667 samples per period, but no ms clock ticks 0.5 us (the release
  // corpus's crane records at 2-10 kHz were doubted so).
  ImportMeasurement(write("fast.csv", 0.0005, 2000.0), {}, &report);
  EXPECT_TRUE(report.warnings.empty()) << report.warnings.front();
  // Judged by the period the time gives, over 22 s (0.045 Hz; no machine's structure): a 40 Hz
  // mode of a 25.6 kHz logger in ms (25 s, 640 samples) is doubted (the re-audit's, once
  // missed), a 100 m rope's 0.05 Hz pendulum logged at 50 Hz (20 s, 1000 samples) is not.
  ImportMeasurement(write("ms25k6.csv", 1 / 25.6, 25600.0, 40.0), {}, &report);
  EXPECT_EQ(report.warnings.size(), 1u);
  ImportMeasurement(write("rope.csv", 0.02, 50.0, 0.05), {}, &report);
  EXPECT_TRUE(report.warnings.empty()) << report.warnings.front();
}

// A German logger's preamble: "Abtastrate;100;Hz" then "Messbereich;-10;10", which reads as a
// header and its row; the rows after it do not go on so, and the real header below them wins
// (a trial's file was refused).
TEST(ImportTest, APreambleLineOfNumbersIsNoRowOfTheLineAbove) {
  TempDir dir;
  std::string text =
      "Gerät;XYZ-1000\nAbtastrate;100;Hz\nMessbereich;-10;10\nKanäle;2\n"
      "Zeit [s];x [mm];y [mm]\n";
  for (int j = 0; j < 50; ++j)
    text += fmt::format("{},{:02d};{},5;-{},25\n", j / 100, j % 100, j, j);
  WriteText(dir.File("logger.csv"), text);
  ImportReport report;
  const Measurement m = ImportMeasurement(dir.File("logger.csv"), {}, &report);
  EXPECT_EQ(m.channels, (std::vector<std::string>{"x", "y"}));
  EXPECT_EQ(m.samples(), 50);
  EXPECT_NEAR(m.values(3, 1), -3.25e-3, 1e-15);  // "-3,25" mm
  EXPECT_THAT(report.dialect, HasSubstr("4 preamble lines"));
}

// A logger's "Weg, links [mm]" cannot name a channel (mbid's CSV header): refused saying how to
// read it under a name of the user's, which then reads it (the refusal gave no way out before).
TEST(ImportTest, AColumnNameThatCannotNameAChannelSaysHowToReadIt) {
  TempDir dir;
  WriteText(dir.File("weg.csv"), "Zeit [s];Weg, links [mm]\n0,00;1,5\n0,01;2,5\n0,02;3,5\n");
  const InputError refused = CatchInputError([&] { ImportMeasurement(dir.File("weg.csv")); });
  EXPECT_THAT(refused.expected(), HasSubstr("--channel Weg_links=1"));
  ImportOptions named;
  named.channel_columns = {{"Weg_links", "1"}};
  const Measurement m = ImportMeasurement(dir.File("weg.csv"), named);
  EXPECT_EQ(m.channels, std::vector<std::string>{"Weg_links"});
  EXPECT_DOUBLE_EQ(m.values(1, 0), 2.5e-3);
}

// Text tables aligned by blanks (numpy.savetxt, an oscilloscope's .dat, "formatted text") and
// names in a comment line right above the numbers (numpy.savetxt's header=) were refused as "no
// header line"; a name's unit suffix (`theta_deg`) was "no unit". Each is read to the printed
// digit: values are printed with 6 decimals of a decay of amplitude 1.
TEST(ImportTest, BlankSeparatedTablesAndHeadersInACommentAreRead) {
  TempDir dir;
  const auto decay = [](double t) { return std::exp(-0.2 * t) * std::cos(2 * M_PI * 1.3 * t); };
  std::string aligned = "  t [s]      y [mm]\ttheta_deg\n";
  std::string commented = "# produced by a script\n# time_s,acc_m_s2,theta_deg\n";
  for (int j = 0; j < 200; ++j) {
    const double t = 0.01 * j;
    aligned += fmt::format("{:7.2f}   {:10.6f}\t{:.6f}\n", t, decay(t), 2 * decay(t));
    commented += fmt::format("{:.2f},{:.6f},{:.6f}\n", t, decay(t), 2 * decay(t));
  }
  WriteText(dir.File("aligned.dat"), aligned);
  WriteText(dir.File("savetxt.csv"), commented);
  for (const char* name : {"aligned.dat", "savetxt.csv"}) {
    ImportReport report;
    const Measurement m = ImportMeasurement(dir.File(name), {}, &report);
    ASSERT_EQ(m.samples(), 200) << name;
    EXPECT_EQ(m.sample_interval_s, 0.01);
    const bool blanks = name[0] == 'a';
    EXPECT_EQ(report.dialect, blanks ? "blank-separated" : "','-separated, header in a comment");
    EXPECT_THAT(report.conversions,
                ::testing::Contains("theta_deg: unit deg from the name's suffix, channel theta"));
    EXPECT_EQ(m.channels.back(), "theta");
    const double scale = blanks ? 1e-3 : 1.0;  // y [mm] -> m; acc_m_s2 is SI
    EXPECT_NEAR(m.values(37, 0), decay(0.37) * scale, 5e-7 * scale) << name;
    EXPECT_NEAR(m.values(37, 1), 2 * decay(0.37) * kDeg, 5e-7 * kDeg) << name;
  }
  // Numbers alone: which column is the time, and in what unit, is not guessed.
  WriteText(dir.File("bare.txt"), "0.0 1.0\n0.01 0.9\n0.02 0.8\n");
  const InputError bare = CatchInputError([&] { ImportMeasurement(dir.File("bare.txt")); });
  EXPECT_EQ(bare.field(), "line 1");
  EXPECT_THAT(bare.problem(), HasSubstr("without a line of names"));
}

// A name that states its unit by the suffix names its channel without it, as `boom [rad]` does
// (a trial's `boom_incl_rad` was refused by the scenario: no output of that name), unless the
// model has an output of the whole name, or two columns would share the shorter one.
TEST(ImportTest, AUnitSuffixIsNoPartOfTheChannelsName) {
  TempDir dir;
  WriteText(dir.File("log.csv"),
            "time_s,boom_incl_rad,tip_mm,theta_deg,theta_rad,stick_m\n0,0.1,2,3,4,5\n"
            "0.01,0.1,2,3,4,5\n0.02,0.1,2,3,4,5\n");
  ImportOptions options;
  options.target_units = {{"stick_m", "m"}};
  ImportReport report;
  const Measurement m = ImportMeasurement(dir.File("log.csv"), options, &report);
  EXPECT_EQ(m.channels,
            (std::vector<std::string>{"boom_incl", "tip", "theta_deg", "theta_rad", "stick_m"}));
  EXPECT_NEAR(m.values(1, 1), 0.002, 1e-15);  // mm -> m
  EXPECT_THAT(report.conversions,
              ::testing::Contains("boom_incl_rad: unit rad from the name's suffix, channel "
                                  "boom_incl"));
  // A ',' file whose first column is `time` (as pandas writes one) looks like mbid's CSV, whose
  // units without a comment are SI: a name's suffix still states its unit (`jib_deg` was read
  // as radians, 57 times too large, without a word).
  WriteText(dir.File("pandas.csv"), "time,jib_deg,tip_mm\n0,1,2\n0.01,1,2\n0.02,1,2\n");
  const Measurement pandas = ImportMeasurement(dir.File("pandas.csv"));
  EXPECT_EQ(pandas.channels, (std::vector<std::string>{"jib", "tip"}));
  EXPECT_NEAR(pandas.values(0, 0), kDeg, 1e-15);
  EXPECT_NEAR(pandas.values(0, 1), 0.002, 1e-15);
}

// An inclinometer of 50 mV per degree, logged in mV and mounted reversed: refused for a model's
// angle with the way to give its calibration (a trial's message said only "cannot be converted
// to rad"), and read through it, its sign turned, as that way says.
TEST(ImportTest, ASensorsRawSignalIsReadThroughItsCalibration) {
  TempDir dir;
  WriteText(dir.File("jib.csv"), "time [s],Jib [mV]\n0,50\n0.01,-25\n0.02,100\n");
  ImportOptions options;
  options.target_units = {{"Jib", "rad"}};
  const InputError raw = CatchInputError([&] { ImportMeasurement(dir.File("jib.csv"), options); });
  EXPECT_THAT(raw.expected(), HasSubstr("`units: {\"Jib\": \"0.02 deg\"}`"));
  EXPECT_THAT(raw.expected(), HasSubstr("a minus sign for a sensor mounted reversed"));
  options.units = {{"Jib", "-0.02 deg"}};
  const Measurement m = ImportMeasurement(dir.File("jib.csv"), options);
  EXPECT_NEAR(m.values(0, 0), -1.0 * kDeg, 1e-15);  // 50 mV: 1 deg, reversed
  EXPECT_NEAR(m.values(1, 0), 0.5 * kDeg, 1e-15);
  // The sign given under the channel's name beside the calibration under the column's: two
  // units for one column are refused (the channel's "-1 deg" won, 50 times off, silently).
  ImportOptions both;
  both.channel_columns = {{"jib_incl", "Jib"}};
  both.units = {{"Jib", "0.02 deg"}, {"jib_incl", "-1 deg"}};
  both.target_units = {{"jib_incl", "rad"}};
  const InputError twice = CatchInputError([&] { ImportMeasurement(dir.File("jib.csv"), both); });
  EXPECT_EQ(twice.field(), "units.jib_incl");
  EXPECT_THAT(twice.expected(), HasSubstr("one unit per column"));
  // A word processor's minus (U+2212) is a minus.
  ImportOptions typographic = options;
  typographic.units = {{"Jib",
                        "\xE2\x88\x92"
                        "0.02 deg"}};
  EXPECT_NEAR(ImportMeasurement(dir.File("jib.csv"), typographic).values(0, 0), -1.0 * kDeg, 1e-15);
  // A bridge's ratio (mV/V) is raw too; a sensitivity (deg/mV) where the unit goes is named as
  // one (both were "cannot be converted to rad", nothing more).
  ImportOptions read_as_rad;
  read_as_rad.target_units = {{"Jib", "rad"}};
  WriteText(dir.File("bridge.csv"), "time [s],Jib [mV/V]\n0,0.5\n0.01,-0.25\n0.02,1\n");
  EXPECT_THAT(
      CatchInputError([&] { ImportMeasurement(dir.File("bridge.csv"), read_as_rad); }).expected(),
      HasSubstr("the sensor's calibration, what one mV/V of its signal measures"));
  WriteText(dir.File("sensitivity.csv"), "time [s],Jib [deg/mV]\n0,50\n0.01,-25\n0.02,100\n");
  const InputError sensitivity =
      CatchInputError([&] { ImportMeasurement(dir.File("sensitivity.csv"), read_as_rad); });
  EXPECT_THAT(sensitivity.problem(), HasSubstr("'deg/mV' is a sensitivity"));
  EXPECT_THAT(sensitivity.expected(), HasSubstr("`units: {\"Jib\": \"0.02 deg\"}`"));
}

// A column without a unit is refused with an example in the unit its channel is read in (an
// accelerometer's was told '[deg]').
TEST(ImportTest, AMissingUnitsExampleIsOfTheChannelsKind) {
  TempDir dir;
  WriteText(dir.File("na.csv"), "time [s];acc\n0;1\n0,01;2\n0,02;3\n");
  ImportOptions options;
  options.target_units = {{"acc", "m/s^2"}};
  const InputError e = CatchInputError([&] { ImportMeasurement(dir.File("na.csv"), options); });
  EXPECT_THAT(e.expected(), HasSubstr("a header 'acc [gn]'"));
}

// Epoch stamps (a logger's PC clock): in ms, scaled to s before the first was subtracted, exact
// 1 ms steps read as 1.00017 ms and the file was refused as a dropped sample; in s printed to
// 0.01 s, each stamp parses 2.4e-7 s off its printed value, with the same result. Both are read
// on their grid, the start at the first stamp.
TEST(ImportTest, EpochStampsAreReadToTheirPrintedDigit) {
  TempDir dir;
  std::string ms = "timestamp [ms],x [mm]\n", s = "timestamp [s],x [mm]\n";
  for (int j = 0; j < 2000; ++j) {
    ms += fmt::format("{},{:.6f}\n", 1772366400000LL + j, std::sin(0.01 * j));
    s += fmt::format("{}.{:02d},{:.6f}\n", 1772366400 + j / 100, j % 100, std::sin(0.01 * j));
  }
  WriteText(dir.File("ms.csv"), ms);
  WriteText(dir.File("s.csv"), s);
  const Measurement in_ms = ImportMeasurement(dir.File("ms.csv"));
  EXPECT_EQ(in_ms.sample_interval_s, 1e-3);
  EXPECT_EQ(in_ms.start_time_s, 1772366400.0);
  const Measurement in_s = ImportMeasurement(dir.File("s.csv"));
  EXPECT_NEAR(in_s.sample_interval_s, 0.01, 1e-15);
  EXPECT_EQ(in_s.start_time_s, 1772366400.0);
}

// Two inclinometers both headed "Incl" (a logger's default names): by name they are ambiguous,
// by number each is its own. The file was refused whatever the mapping.
TEST(ImportTest, TwoColumnsOfOneNameAreReadByNumber) {
  TempDir dir;
  const std::string path = dir.File("twins.csv");
  WriteText(path, "t [s],Incl [rad],Incl [rad],Acc [m/s^2]\n0,1,2,3\n0.5,4,5,6\n1,7,8,9\n");
  ImportOptions numbered;
  numbered.channel_columns = {{"arm", "1"}, {"tower", "2"}, {"tip", "Acc"}};
  const Measurement m = ImportMeasurement(path, numbered);
  EXPECT_EQ(m.values(1, m.FindChannel("arm")), 4);
  EXPECT_EQ(m.values(1, m.FindChannel("tower")), 5);
  const InputError unmapped = CatchInputError([&] { ImportMeasurement(path); });
  EXPECT_EQ(unmapped.field(), "line 1, column 3");
  EXPECT_THAT(unmapped.expected(), HasSubstr("column numbers"));
  ImportOptions by_name = numbered;
  by_name.channel_columns = {{"arm", "Incl"}, {"tip", "Acc"}};
  const InputError ambiguous = CatchInputError([&] { ImportMeasurement(path, by_name); });
  EXPECT_EQ(ambiguous.field(), "channels.arm");
  EXPECT_THAT(ambiguous.problem(), HasSubstr("appears twice"));
}

TEST(ImportTest, TabsBomCrlfAndBracketedUnitsWithStandardGravity) {
  TempDir dir;
  const std::string path = dir.File("logger.txt");
  const Decay angle;                      // degrees
  const Decay disp{1.5, 0.02, 4.0, 1.0};  // mm
  const Decay acc{1.5, 0.02, 0.03, 0.0};  // gn
  const std::string head = "\xEF\xBB\xBFTime [s]\tangle [deg]\tdisp (mm)\tacc [gn]\r\n";
  WriteText(path, MakeExport(
                      head, 201,
                      [&](int j) {
                        const double t = j * 0.01;
                        return fmt::format("{:.2f}\t{}\t{}\t{}", t, Print(angle(t)), Print(disp(t)),
                                           Print(acc(t)));
                      },
                      "\r\n"));
  ImportReport report;
  const Measurement m = ImportMeasurement(path, {}, &report);
  EXPECT_THAT(report.dialect, HasSubstr("tab-separated"));
  EXPECT_THAT(report.dialect, HasSubstr("CRLF"));
  EXPECT_THAT(report.dialect, HasSubstr("BOM"));
  EXPECT_EQ(m.channels, (std::vector<std::string>{"angle", "disp", "acc"}));
  EXPECT_EQ(m.units, (std::vector<std::string>{"rad", "m", "m/s^2"}));
  EXPECT_NEAR(m.sample_interval_s, 0.01, 1e-15);  // printed exactly to 2 decimals
  ExpectChannel(m, 0, angle, kDeg);
  ExpectChannel(m, 1, disp, 1e-3);
  ExpectChannel(m, 2, acc, 9.80665);  // standard gravity (CGPM 1901)
}

TEST(ImportTest, IsoTimestampsBecomeSecondsFromTheFirstSample) {
  TempDir dir;
  const std::string path = dir.File("iso.csv");
  const Decay angle;
  // 12:00:00.125 + j * 10 ms, 301 rows (3 s): crosses whole seconds and a minute boundary is
  // not needed; the offset "Z" is accepted.
  WriteText(path, MakeExport("timestamp,theta [deg]\n", 301, [&](int j) {
              const int ms = 125 + 10 * j;
              return fmt::format("2026-03-01T12:00:{:02d}.{:03d}Z,{}", ms / 1000, ms % 1000,
                                 Print(angle(j * 0.01)));
            }));
  ImportReport report;
  const Measurement m = ImportMeasurement(path, {}, &report);
  EXPECT_EQ(m.start_time_s, 0.0);                 // seconds from the first sample
  EXPECT_NEAR(m.sample_interval_s, 0.01, 1e-15);  // integer seconds subtracted first: exact
  ExpectChannel(m, 0, angle, kDeg);
  // The import line says so, with the origin (the record's time 0 is that instant).
  EXPECT_THAT(report.dialect,
              HasSubstr("timestamps read as s from the first (2026-03-01T12:00:00.125Z)"));
}

TEST(ImportTest, TimePrintedWithFewDigitsIsFittedByLeastSquares) {
  TempDir dir;
  const std::string path = dir.File("coarse.csv");
  const Decay psi{1.5, 0.02, 0.02, 0.0};  // radians
  const int n = 301;                      // 10 s at 30 Hz
  // 1/30 s printed to 1 ms: each time is off the grid by up to 0.5 ms, 1.5 % of a step.
  WriteText(path, MakeExport("t [s],psi [rad]\n", n, [&](int j) {
              return fmt::format("{:.3f},{}", j / 30.0, Print(psi(j / 30.0)));
            }));
  const Measurement m = ImportMeasurement(path);
  // Least squares over j: |slope error| <= 0.5 ms * sum|j - mean| / sum (j - mean)^2 ~ 1.5 ms / n.
  EXPECT_NEAR(m.sample_interval_s, 1.0 / 30, 1.5e-3 / n);
  EXPECT_NEAR(m.start_time_s, 0.0, 0.5e-3);  // within the printed resolution
}

TEST(ImportTest, UnitsFromOptionsAndTimeSuffix) {
  TempDir dir;
  const std::string path = dir.File("suffix.csv");
  const Decay x{1.5, 0.02, 3.0, 0.0};  // mm
  // time_us: the project's unit suffix; 2000 us = 2 ms steps, 101 rows.
  WriteText(path, MakeExport("time_us,x\n", 101, [&](int j) {
              return fmt::format("{},{}", 2000 * j, Print(x(j * 2e-3)));
            }));
  ImportOptions options;
  options.units["x"] = "mm";  // the file states none
  const Measurement m = ImportMeasurement(path, options);
  EXPECT_NEAR(m.sample_interval_s, 2e-3, 1e-17);  // us -> s factor's rounding
  EXPECT_EQ(m.units, std::vector<std::string>{"m"});
  ExpectChannel(m, 0, x, 1e-3);
  // By the column's number among the data columns, as the error for an unknown key lists them.
  ImportOptions by_number;
  by_number.units["1"] = "mm";
  ExpectChannel(ImportMeasurement(path, by_number), 0, x, 1e-3);
}

// A column named `time` without a unit is in s (the contract), so a logger's ms clock is read
// 1000 times too slow: said beside the import when its step is 0.1 s or more; a 100 Hz record
// in s is not.
TEST(ImportTest, AUnitlessTimeColumnSlowerThanTenHertzIsSaidToMaybeBeMilliseconds) {
  TempDir dir;
  const std::string ms = dir.File("ms.csv");
  WriteText(ms, MakeExport("time,x [m]\n", 101, [&](int j) {  // 1 kHz in ms: steps of 1
              return fmt::format("{},{}", j, Print(std::cos(0.1 * j)));
            }));
  ImportReport report;
  const Measurement m = ImportMeasurement(ms, {}, &report);
  EXPECT_EQ(m.sample_interval_s, 1.0);  // as the contract reads it
  ASSERT_EQ(report.warnings.size(), 1u);
  EXPECT_THAT(report.warnings[0], HasSubstr("if it is in ms, write 'time [ms]'"));
  const std::string s = dir.File("s.csv");
  WriteText(s, MakeExport("time,x [m]\n", 101, [&](int j) {  // 100 Hz in s
              return fmt::format("{},{}", Print(0.01 * j), Print(std::cos(0.1 * j)));
            }));
  ImportReport seconds;
  ImportMeasurement(s, {}, &seconds);
  EXPECT_TRUE(seconds.warnings.empty());
  // A step of 0.1 s itself (fitted as 0.09999999999999999 s) is doubted too.
  const std::string tenth = dir.File("tenth.csv");
  WriteText(tenth, MakeExport("time,x [m]\n", 3000, [&](int j) {  // 0 to 299.9 s
              return fmt::format("{:.10g},{}", 0.1 * j, Print(std::cos(0.1 * j)));
            }));
  ImportReport ten_hertz;
  ImportMeasurement(tenth, {}, &ten_hertz);
  EXPECT_EQ(ten_hertz.warnings.size(), 1u);
  // Stated, the unit is not doubted.
  const std::string stated = dir.File("stated.csv");
  WriteText(stated, MakeExport("time [s],x [m]\n", 101, [&](int j) {
              return fmt::format("{},{}", j, Print(std::cos(0.1 * j)));
            }));
  ImportReport given;
  ImportMeasurement(stated, {}, &given);
  EXPECT_TRUE(given.warnings.empty());
}

TEST(ImportTest, ChannelMappingByNameAndNumberWithModelTargets) {
  TempDir dir;
  const std::string path = dir.File("map.csv");
  const Decay a;
  WriteText(path, MakeExport("Time [ms];Boom angle [deg];Slew [deg];Spare [V]\n", 101, [&](int j) {
              const double t = j * 0.01;
              return fmt::format("{};{};{};0", 10 * j, Print(a(t)), Print(-a(t)));
            }));
  ImportOptions options;
  options.channel_columns = {{"psi", "Boom angle"}, {"phi", "2"}};  // 2: the second data column
  options.target_units = {{"psi", "rad"}, {"phi", "rad"}};
  ImportReport report;
  const Measurement m = ImportMeasurement(path, options, &report);
  EXPECT_EQ(m.channels, (std::vector<std::string>{"psi", "phi"}));  // the spare column dropped
  ExpectChannel(m, 0, a, kDeg);
  ExpectChannel(m, 1, a, -kDeg);
  EXPECT_EQ(report.mapping,
            (std::vector<std::string>{"psi <- column 2 (Boom angle)", "phi <- column 3 (Slew)"}));
}

TEST(ImportTest, GapsFilledLinearlyWithinTheInterpolationBound) {
  TempDir dir;
  const std::string path = dir.File("gaps.csv");
  const Decay angle;
  const double h = 0.01;
  // Rows 50 and 120 lose a value: an empty cell and a NaN.
  WriteText(path, MakeExport("time [s],theta [deg]\n", 201, [&](int j) {
              const std::string value = j == 50 ? "" : j == 120 ? "NaN" : Print(angle(j * h));
              return fmt::format("{:.2f},{}", j * h, value);
            }));
  ImportOptions options;
  options.fill_gaps = GapFill::kLinear;
  ImportReport report;
  const Measurement m = ImportMeasurement(path, options, &report);
  EXPECT_EQ(report.filled_samples, 2);
  // A chord over 2h misses the curve by at most (2h)^2 / 8 max|y''| (linear interpolation).
  const double bound = (2 * h) * (2 * h) / 8 * angle.SecondDerivativeBound() * kDeg;
  for (const int j : {50, 120}) {
    EXPECT_NEAR(m.values(j, 0), angle(j * h) * kDeg, bound) << j;
    EXPECT_NE(m.values(j, 0), angle(j * h) * kDeg);  // interpolated, not read
  }
  // The rest as read.
  for (Eigen::Index j = 0; j < m.samples(); ++j) {
    if (j == 50 || j == 120) continue;
    ASSERT_NEAR(m.values(j, 0), angle(j * h) * kDeg, PrintTolerance(angle, kDeg)) << j;
  }
}

TEST(ImportTest, NoTimeColumnWithSampleRate) {
  TempDir dir;
  const std::string path = dir.File("rate.csv");
  WriteText(path, "a [rad],b [rad]\n1,2\n3,4\n5,6\n");
  ImportOptions options;
  options.sample_rate_hz = 200;  // 5 ms steps
  const Measurement m = ImportMeasurement(path, options);
  EXPECT_EQ(m.sample_interval_s, 1.0 / 200);
  EXPECT_EQ(m.start_time_s, 0.0);
  EXPECT_EQ(m.values(2, 1), 6.0);
}

// One channel logged without a time column: no separator anywhere, which the dialect search
// needed (refused as "no header line followed by rows of numbers"). A decimal comma stays in its
// number; a units row is read as with several columns.
TEST(ImportTest, OneChannelWithoutATimeColumn) {
  TempDir dir;
  ImportOptions options;
  options.sample_rate_hz = 100;
  const std::string plain = dir.File("one.csv");
  WriteText(plain, "# logger 7\npsi [mrad]\n1.5\n-2\n0.25\n");
  const Measurement m = ImportMeasurement(plain, options);
  ASSERT_EQ(m.channels, std::vector<std::string>{"psi"});
  ASSERT_EQ(m.samples(), 3);
  EXPECT_EQ(m.sample_interval_s, 0.01);
  EXPECT_DOUBLE_EQ(m.values(1, 0), -2e-3);
  const std::string comma = dir.File("komma.csv");
  WriteText(comma, "Neigung\ndeg\n0,5\n1,25\n");
  ImportReport report;
  const Measurement c = ImportMeasurement(comma, options, &report);
  EXPECT_EQ(report.dialect, "one column, decimal comma, units row");
  ASSERT_EQ(c.samples(), 2);
  EXPECT_DOUBLE_EQ(c.values(1, 0), 1.25 * M_PI / 180);
}

TEST(ImportTest, MbidCsvAndHdf5RoundTripsStayBitExact) {
  TempDir dir;
  const Measurement written = mbid::testing::MakeMeasurement(300);
  const std::string csv = dir.File("m.csv");
  WriteMeasurementCsv(written, csv);
  const std::string h5 = dir.File("m.h5");
  H5Writer writer(h5);
  writer.WriteMeasurement(written);
  writer.Commit();
  for (const std::string& path : {csv, h5}) {
    ImportReport report;
    const Measurement read = ImportMeasurement(path, {}, &report);
    EXPECT_EQ(read.channels, written.channels) << path;
    EXPECT_EQ(read.units, written.units) << path;
    EXPECT_EQ(read.source, written.source) << path;
    EXPECT_TRUE(SameBits(read.start_time_s, written.start_time_s)) << path;
    EXPECT_TRUE(SameBits(read.sample_interval_s, written.sample_interval_s)) << path;
    EXPECT_TRUE(SameBits(read.values, written.values)) << path;
    EXPECT_TRUE(report.conversions.empty()) << path;  // SI in, nothing converted
  }
}

// A time dataset in ms (a lab's own writer of mbid's layout) is converted by its units attribute
// like any channel; a user's time unit stands over the file's, and the step it gives must still
// be sample_interval_s (a trial's file was refused, and --time-unit on a file in s divided its
// rate by 1000 unnoticed).
TEST(ImportTest, AnHdf5TimeIsReadInTheUnitItsAttributeOrTheUserStates) {
  TempDir dir;
  const Measurement written = mbid::testing::MakeMeasurement(300);
  const std::string ms = dir.File("ms.h5");
  {
    H5Writer writer(ms);
    writer.WriteMeasurement(written);
    writer.WriteVector("/measurement", "time", 1e3 * written.CalcTime(), "ms");
    writer.Commit();
  }
  ImportOptions user_ms;
  user_ms.time_unit = "ms";
  for (const ImportOptions& options : {ImportOptions(), user_ms}) {
    ImportReport report;
    const Measurement read = ImportMeasurement(ms, options, &report);
    // The stated interval, through ms and back: within a few ulps of 0.01 s.
    EXPECT_NEAR(read.sample_interval_s, written.sample_interval_s, 1e-16);
    EXPECT_NEAR(read.start_time_s, written.start_time_s, 1e-15);
    EXPECT_THAT(fmt::format("{}", fmt::join(report.conversions, "; ")),
                HasSubstr("time: ms -> s (x 0.001)"));
  }
  const std::string s = dir.File("s.h5");
  {
    H5Writer writer(s);
    writer.WriteMeasurement(written);
    writer.Commit();
  }
  const InputError e = CatchInputError([&] { ImportMeasurement(s, user_ms); });
  EXPECT_THAT(e.what(), HasSubstr("sample_interval_s': is 0.01 s but /measurement/time has a "
                                  "step of 1e-05 s (its times read in ms)"));
  // A unit that is no time is refused naming the attribute.
  const std::string metres = dir.File("m.h5");
  {
    H5Writer writer(metres);
    writer.WriteMeasurement(written);
    writer.WriteVector("/measurement", "time", written.CalcTime(), "m");
    writer.Commit();
  }
  const InputError m = CatchInputError([&] { ImportMeasurement(metres); });
  EXPECT_THAT(m.what(), HasSubstr("/measurement/time attribute 'units'"));
}

TEST(ImportTest, MbidCsvUnitsCommentIsConverted) {
  TempDir dir;
  const std::string path = dir.File("deg.csv");
  // Before this change `# units: deg` was stored and the values left in degrees.
  WriteText(path, "# units: deg,mm\ntime,psi,x\n0,90,1000\n0.5,180,2000\n");
  ImportReport report;
  const Measurement m = ImportMeasurement(path, {}, &report);
  EXPECT_EQ(report.format, "mbid-csv");
  EXPECT_EQ(m.units, (std::vector<std::string>{"rad", "m"}));
  EXPECT_DOUBLE_EQ(m.values(0, 0), M_PI / 2);
  EXPECT_DOUBLE_EQ(m.values(1, 0), M_PI);
  EXPECT_DOUBLE_EQ(m.values(1, 1), 2.0);
}

TEST(ImportTest, MbidCsvWithoutUnitsTakesTheModelsUnits) {
  TempDir dir;
  const std::string path = dir.File("si.csv");
  WriteText(path, "time,psi,acc\n0,0.1,0.2\n0.5,0.3,0.4\n");
  ImportOptions options;
  options.target_units = {{"acc", "m/s^2"}};  // psi: none given, radians (mbid's CSV default)
  const Measurement m = ImportMeasurement(path, options);
  EXPECT_EQ(m.units, (std::vector<std::string>{"rad", "m/s^2"}));
  EXPECT_EQ(m.values(1, 1), 0.4);  // SI by contract: not converted
}

}  // namespace
}  // namespace mbid::records
