// Logger files through the mbid command: --channel, --unit and --fill-gaps on identify, update
// and run, the scenario's record keys, and exit 2 with one line naming the file and the place.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "command_test.h"
#include "mbid/common/hdf5_io.h"

namespace {

using mbid::testing::CommandResult;
using mbid::testing::ReadText;
namespace fs = std::filesystem;

const std::string kScenarios = std::string(MBID_SOURCE_DIR) + "/scenarios/";

// y = A e^{-zeta w t} cos(w_d t): 1.5 Hz, 2 % damping, 2 deg (a crane's first mode).
double Decay(double t) {
  const double w = 2 * M_PI * 1.5;
  return 2.0 * std::exp(-0.02 * w * t) * std::cos(w * std::sqrt(1 - 0.02 * 0.02) * t);
}

class RecordsCliTest : public mbid::testing::CommandTest {
 protected:
  // A German logger's export: preamble, ';', decimal comma, units row, ms, degrees; 801 rows
  // at 100 Hz (8 s, 12 periods); the row of `gap_row` (if >= 0) has an empty cell.
  fs::path WriteLogger(const std::string& name, int gap_row = -1) const {
    std::string text = "Logger: XYZ-200\nZeit;Boom angle;Slew\nms;deg;deg\n";
    for (int j = 0; j < 801; ++j) {
      const double t = j * 0.01;
      std::string a = j == gap_row ? "" : fmt::format("{:.9g}", Decay(t));
      std::string b = fmt::format("{:.9g}", 0.5 * Decay(t));
      for (std::string* s : {&a, &b}) {
        for (char& c : *s) c = c == '.' ? ',' : c;
      }
      text += fmt::format("{};{};{}\n", 10 * j, a, b);
    }
    return Write(name, text);
  }

  void ExpectOneErrorLine(const CommandResult& result, const std::string& phrase) const {
    EXPECT_EQ(result.exit_code, 2) << result.err;
    EXPECT_EQ(result.err.rfind("mbid: error: ", 0), 0u) << result.err;
    EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << result.err;
    EXPECT_NE(result.err.find(phrase), std::string::npos) << result.err;
    EXPECT_TRUE(result.out.empty()) << result.out;
  }
};

TEST_F(RecordsCliTest, IdentifyRefusesAGapNamingLineAndColumnAndWritesNothing) {
  const fs::path data = WriteLogger("logger.csv", 100);  // row 100 is file line 104
  const fs::path out = dir_ / "out.h5";
  const CommandResult result = Run("identify " + data.string() + " -o " + out.string() +
                                   " --json " + (dir_ / "s.json").string());
  ExpectOneErrorLine(result, data.string() + ":line 104, column 2 (Boom angle): empty or NaN cell");
  EXPECT_NE(result.err.find("--fill-gaps linear"), std::string::npos) << result.err;
  EXPECT_FALSE(fs::exists(out));
  EXPECT_FALSE(fs::exists(dir_ / "s.json"));
}

// --backbone always gives the logger's one linear mode its backbone (both estimators) and
// --remove-drift reports the drift it removed; without them neither field is there.
TEST_F(RecordsCliTest, BackboneAndDriftFlags) {
  const fs::path data = WriteLogger("logger.csv");
  const CommandResult plain = Run("identify " + data.string() + " --json -");
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  const nlohmann::json without = nlohmann::json::parse(plain.out);
  ASSERT_GE(without["modes"].size(), 1u);
  EXPECT_FALSE(without["modes"][0].contains("backbone"));
  EXPECT_FALSE(without.contains("drift_per_s"));
  const CommandResult flagged =
      Run("identify " + data.string() + " --json - --backbone always --remove-drift");
  ASSERT_EQ(flagged.exit_code, 0) << flagged.err;
  const nlohmann::json with = nlohmann::json::parse(flagged.out);
  ASSERT_GE(with["modes"].size(), 1u);
  const nlohmann::json& backbone = with["modes"][0]["backbone"];
  ASSERT_TRUE(backbone.contains("hilbert")) << backbone.dump();
  // 8 s of a 1.5 Hz decay: sliding windows of 8 periods (5.3 s), at least one; the Hilbert
  // transform's windows of 4 periods (2.7 s) every 2 periods between the 3 periods (2 s) left
  // out at each end: 2.
  EXPECT_GE(backbone["frequency_hz"].size(), 1u);
  EXPECT_EQ(backbone["hilbert"]["frequency_hz"].size(), 2u);
  for (const auto& f : backbone["hilbert"]["frequency_hz"]) {
    // The damped frequency 1.5 sqrt(1 - 0.02^2) Hz; a linear mode, printed to 9 digits: 1e-3.
    EXPECT_NEAR(f.get<double>(), 1.5 * std::sqrt(1 - 0.02 * 0.02), 1e-3);
  }
  // The logger has no drift: what is removed is within the noise of 9 printed digits.
  ASSERT_TRUE(with.contains("drift_per_s"));
  for (const auto& [channel, drift] : with["drift_per_s"].items()) {
    EXPECT_LT(std::abs(drift.get<double>()), 1e-6) << channel;
  }
  ExpectOneErrorLine(Run("identify " + data.string() + " --backbone sometimes"), "--backbone");
}

TEST_F(RecordsCliTest, IdentifyFillsGapsAndReportsTheImport) {
  const fs::path data = WriteLogger("logger.csv", 100);
  const CommandResult result = Run("identify " + data.string() +
                                   " --fill-gaps linear --json - --progress --channel psi=\"Boom "
                                   "angle\" --channel phi=2");
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_NE(result.err.find("1 gap sample filled linearly"), std::string::npos) << result.err;
  const nlohmann::json summary = nlohmann::json::parse(result.out);
  const nlohmann::json& import = summary["import"];
  EXPECT_EQ(import["format"], "csv");
  EXPECT_EQ(import["filled_samples"], 1);
  EXPECT_EQ(import["mapping"][0], "psi <- column 2 (Boom angle)");
  EXPECT_NE(import["conversions"].dump().find("psi: deg -> rad"), std::string::npos);
  ASSERT_GE(summary["modes"].size(), 1u) << summary.dump();
  // One mode in the record: its frequency to 1e-3 Hz (a clean 8 s record gives far better;
  // the one interpolated sample moves it by less).
  EXPECT_NEAR(summary["modes"][0]["frequency_hz"].get<double>(), 1.5, 1e-3);
  EXPECT_EQ(summary["channels"], nlohmann::json({"psi", "phi"}));
}

// --sample-rate-hz gives a file without a time column its time base, --time-unit overrides the
// time column's unit: the 1.5 Hz decay comes out at the frequency the stated time base makes of
// it (x rate / 100 Hz; x 1000 when the logger's ms are read as us).
// A unitless `time` column in ms (read in s by the contract) is doubted even under --quiet, as
// every warning is (interfaces.md: --quiet drops progress lines, not warnings); the doubt is in
// the JSON's import item too, and makes the result unreliable.
TEST_F(RecordsCliTest, AMillisecondClockReadAsSecondsIsDoubtedEvenWhenQuiet) {
  std::string text = "time,x [m]\n";
  for (int j = 0; j < 801; ++j) text += fmt::format("{},{:.9g}\n", 10 * j, Decay(j * 0.01));
  const fs::path data = Write("ms_clock.csv", text);
  const CommandResult quiet = Run("identify " + data.string() + " -q --json -");
  ASSERT_EQ(quiet.exit_code, 0) << quiet.err;
  EXPECT_NE(quiet.err.find("mbid: warning: " + data.string() +
                           ": the time column 'time' has no "
                           "unit and is read in s"),
            std::string::npos)
      << quiet.err;
  const nlohmann::json summary = nlohmann::json::parse(quiet.out);
  ASSERT_EQ(summary["import"]["warnings"].size(), 1u) << summary["import"].dump();
  // Every frequency may be 1000 times off: the result is not to be relied on, and says why.
  EXPECT_FALSE(summary["reliable"].get<bool>());
  ASSERT_FALSE(summary["reasons"].empty());
  EXPECT_EQ(
      summary["reasons"][0].get<std::string>().rfind("reading the record: the time column", 0), 0u)
      << summary["reasons"].dump();
}

TEST_F(RecordsCliTest, TimeBaseFlagsSetTheSampleRateAndTheTimeUnit) {
  std::string text = "Boom angle;Slew\ndeg;deg\n";
  for (int j = 0; j < 801; ++j) {
    text += fmt::format("{:.9g};{:.9g}\n", Decay(j * 0.01), 0.5 * Decay(j * 0.01));
  }
  const fs::path data = Write("no_time.csv", text);
  auto frequency = [&](const std::string& flags) {
    const CommandResult result =
        Run("identify " + data.string() + " --release none --json - " + flags);
    EXPECT_EQ(result.exit_code, 0) << result.err;
    const nlohmann::json summary = nlohmann::json::parse(result.out);
    return summary["modes"].empty() ? 0.0 : summary["modes"][0]["frequency_hz"].get<double>();
  };
  // The damped frequency, 1.5 sqrt(1 - 0.02^2) Hz; 9 significant digits in the file: 1e-5.
  const double damped_hz = 1.5 * std::sqrt(1 - 0.02 * 0.02);
  EXPECT_NEAR(frequency("--sample-rate-hz 100"), damped_hz, 1e-5);
  EXPECT_NEAR(frequency("--sample-rate-hz 200"), 2 * damped_hz, 2e-5);
  ExpectOneErrorLine(Run("identify " + data.string()), "--sample-rate-hz");
  ExpectOneErrorLine(Run("identify " + data.string() + " --sample-rate-hz 0"), "--sample-rate-hz");
  const fs::path logger = WriteLogger("logger.csv");
  const CommandResult us = Run("identify " + logger.string() + " --json - --time-unit us");
  ASSERT_EQ(us.exit_code, 0) << us.err;
  EXPECT_NEAR(nlohmann::json::parse(us.out)["modes"][0]["frequency_hz"].get<double>(), 1500.0, 1.0);
}

TEST_F(RecordsCliTest, BadFlagsAndUnknownColumnsAreInvalidInput) {
  const fs::path data = WriteLogger("logger.csv");
  ExpectOneErrorLine(Run("identify " + data.string() + " --channel psi"), "--channel");
  ExpectOneErrorLine(Run("identify " + data.string() + " --channel psi=Nope"),
                     data.string() + ":channels.psi: no column 'Nope'");
  ExpectOneErrorLine(Run("identify " + data.string() + " --unit Slew=blorp"),
                     data.string() + ":column 3 (Slew): unknown unit 'blorp'");
  ExpectOneErrorLine(Run("identify " + data.string() + " --fill-gaps cubic"), "--fill-gaps");
  // update checks the mapping before any work: the model's psi is an angle, mm is not.
  const fs::path scenario = WriteVariant(kScenarios + "reference-crane.yaml", "s.yaml");
  ExpectOneErrorLine(Run("update " + scenario.string() + " " + data.string() +
                         " --channel psi=2 --unit Slew=mm -o " + (dir_ / "u.h5").string()),
                     data.string() + ":column 3 (Slew): unit 'mm'");
  EXPECT_FALSE(fs::exists(dir_ / "u.h5"));
}

TEST_F(RecordsCliTest, RunReadsALoggerFileThroughTheRecordKeys) {
  // The reference crane's own virtual test (5 s), exported as a logger would: degrees, ms,
  // ';' and decimal comma, other column names, one gap, the second column's unit left to the
  // scenario. The run must tune the model to it as to the original.
  const fs::path base = WriteVariant(kScenarios + "reference-crane.yaml", "base.yaml",
                                     "  duration_s: 8", "  duration_s: 5");
  ASSERT_EQ(Run("simulate " + base.string() + " -o " + (dir_ / "sim.h5").string()).exit_code, 0);
  const mbid::Measurement sim = mbid::ReadMeasurementH5((dir_ / "sim.h5").string());
  ASSERT_EQ(sim.channels, (std::vector<std::string>{"psi", "phi"}));
  std::string text = "Exported by XYZ-200\nZeit;Boom angle;Slew\nms;deg;\n";
  const Eigen::VectorXd t = sim.CalcTime();
  for (Eigen::Index j = 0; j < sim.samples(); ++j) {
    // 9 digits of degrees: 1e-9 relative, far below the 1e-5 rad sensor noise.
    std::string a = j == 200 ? "" : fmt::format("{:.9g}", sim.values(j, 0) * 180 / M_PI);
    std::string b = fmt::format("{:.9g}", sim.values(j, 1) * 180 / M_PI);
    for (std::string* s : {&a, &b}) {
      for (char& c : *s) c = c == '.' ? ',' : c;
    }
    text += fmt::format("{:.6g};{};{}\n", t[j] * 1000, a, b);
  }
  Write("logger.csv", text);
  std::ofstream(base, std::ios::app)
      << "record: {file: logger.csv, channels: {psi: Boom angle, phi: 2}, units: {Slew: deg}, "
         "fill_gaps: linear}\n";
  const fs::path out = dir_ / "run";
  const CommandResult result = Run("run " + base.string() + " -o " + out.string() + " --progress");
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_NE(result.err.find("psi: deg -> rad"), std::string::npos) << result.err;
  EXPECT_NE(result.err.find("1 gap sample filled linearly"), std::string::npos) << result.err;
  const nlohmann::json summary = nlohmann::json::parse(ReadText(out / "summary.json"));
  EXPECT_TRUE(summary["validation"]["passed"].get<bool>()) << summary["validation"].dump();
  EXPECT_EQ(summary["tests"][0]["import"]["filled_samples"], 1);  // the one empty cell
  for (const char* channel : {"psi", "phi"}) {
    // As from the original file: 1e-5 rad noise on ~1e-3 rad outputs gives K > 0.999.
    EXPECT_GT(summary["validation"]["correlation"][channel].get<double>(), 0.999) << channel;
  }
}

}  // namespace
