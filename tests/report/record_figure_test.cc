// The record figure of a run marks the release where the test was cut (issue 13): the gnuplot
// commands carry a vertical line at the release instant with its label, and the data the whole
// record as read.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

#include "mbid/identification/release.h"
#include "mbid/report/gnuplot.h"
#include "mbid/report/run_report.h"

namespace mbid::report {
namespace {

namespace fs = std::filesystem;

constexpr double kPi = 3.14159265358979323846;
constexpr double kTau = 0.01;         // 100 Hz
constexpr double kRelease = 1.2;      // s: at rest before, released from rest at this instant
constexpr double kDeflection = 0.01;  // rad

// One channel held at a deflection, then released from rest: a damped oscillator's free decay
// x0 e^{-b t} (cos w t + b/w sin w t), continuous with zero velocity at the release; noise
// 1e-5 rad (a thousandth of the deflection).
Measurement PullRelease() {
  Measurement record;
  record.channels = {"psi"};
  record.units = {"rad"};
  record.sample_interval_s = kTau;
  record.source = "import";
  const int samples = 500;
  record.values.resize(samples, 1);
  std::mt19937_64 rng(3);
  std::normal_distribution<double> noise(0.0, 1e-5);
  const double b = 0.8, w = 2 * kPi * 1.5;
  for (int j = 0; j < samples; ++j) {
    const double t = j * kTau - kRelease;
    record.values(j, 0) =
        (t <= 0 ? kDeflection
                : kDeflection * std::exp(-b * t) * (std::cos(w * t) + b / w * std::sin(w * t))) +
        noise(rng);
  }
  return record;
}

std::string ReadBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream bytes;
  bytes << in.rdbuf();
  return bytes.str();
}

TEST(RecordFigureTest, TheDetectedReleaseIsMarkedAtItsInstant) {
  const Measurement record = PullRelease();
  const identification::ReleaseDetection detection = identification::DetectRelease(record);
  ASSERT_TRUE(detection.detected);
  // The onset fit places it within a sample of the closed form's instant.
  EXPECT_NEAR(detection.release_time_s, kRelease, kTau);
  const ReleaseMark mark{detection.release_time_s, "detected"};
  const Figure figure = MakeRecordFigure(record, nullptr, "", 0, &mark);
  ASSERT_EQ(figure.marks.size(), 1u);
  const std::string commands = GnuplotCommands(figure, "data.dat", "record.png");
  // A line across the plot at the release, in data coordinates on x...
  const std::string at = fmt::format("first {:.10g}", detection.release_time_s);
  EXPECT_NE(commands.find("set arrow from " + at + ", graph 0 to " + at + ", graph 1 nohead"),
            std::string::npos)
      << commands;
  // ...with its label: the instant and how it was found.
  EXPECT_NE(commands.find(
                fmt::format("set label 'release (detected) at {:.6g} s", detection.release_time_s)),
            std::string::npos)
      << commands;
  // The data are the whole record as read (from t = 0, before the release), not the cut one.
  const std::string data = GnuplotData(figure);
  EXPECT_EQ(data.rfind("0 ", 0), 0u) << data.substr(0, 40);
  EXPECT_NE(data.find(fmt::format("\n{:.10g} ", (record.samples() - 1) * kTau)), std::string::npos);
}

TEST(RecordFigureTest, NoReleaseNoMark) {
  const Figure figure = MakeRecordFigure(PullRelease(), nullptr, "", 0, nullptr);
  EXPECT_TRUE(figure.marks.empty());
  EXPECT_EQ(GnuplotCommands(figure, "data.dat", "record.png").find("set arrow"), std::string::npos);
}

TEST(RecordFigureTest, TheMarkIsDrawn) {
  if (!GnuplotAvailable()) GTEST_SKIP() << "gnuplot with pngcairo not installed";
  const fs::path dir =
      fs::temp_directory_path() / ("mbid_record_figure_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const Measurement record = PullRelease();
  const ReleaseMark mark{kRelease, "given"};
  DrawRecordFigure(dir.string(), record, nullptr, "", 0, nullptr);
  const std::string plain = ReadBytes(dir / "record_psi.png");
  DrawRecordFigure(dir.string(), record, nullptr, "", 0, &mark);
  const std::string marked = ReadBytes(dir / "record_psi.png");
  fs::remove_all(dir);
  EXPECT_GT(marked.size(), 1000u);
  EXPECT_NE(plain, marked);  // gnuplot accepted the mark's commands and drew something more
}

// A mode with a backbone in closed form: f(a) = 10 (1 + 0.03 a^2) Hz at a = e^{-0.5 t}, the
// damping ratio 0.008, each with a standard deviation of 1e-3 of the value.
identification::ModalResult ResultWithBackbone() {
  identification::ModalResult result;
  result.channels = {"psi", "phi"};
  result.units = {"rad", "rad"};
  identification::IdentifiedMode mode;
  mode.SetPole({-0.5, 2 * kPi * 10.1});
  mode.amplitude = Eigen::Vector2d(0.2, 1.0);  // largest in phi
  identification::Backbone backbone;
  for (int i = 0; i < 5; ++i) {
    const double a = std::exp(-0.5 * i);
    backbone.time_s.push_back(i);
    backbone.amplitude.push_back(a);
    backbone.frequency_hz.push_back(10 * (1 + 0.03 * a * a));
    backbone.std_frequency_hz.push_back(1e-3 * backbone.frequency_hz.back());
    backbone.damping_ratio.push_back(0.008);
    backbone.std_damping_ratio.push_back(8e-6);
  }
  backbone.hilbert = static_cast<identification::BackboneCurve>(backbone);
  mode.backbone = backbone;
  result.modes = {identification::IdentifiedMode(), mode};
  result.modes[0].SetPole({-0.3, 2 * kPi * 2.0});
  result.modes[0].amplitude = Eigen::Vector2d(1.0, 0.1);
  return result;
}

TEST(BackboneFigureTest, FrequencyAndDampingWithErrorBarsForTheModesThatHaveOne) {
  const identification::ModalResult result = ResultWithBackbone();
  const Figure frequency = MakeBackboneFigure(result, 1, false);
  // Two estimators, each a series with one error bar per point.
  ASSERT_EQ(frequency.series.size(), 2u);
  EXPECT_EQ(frequency.x_label, "amplitude, rad");
  EXPECT_EQ(frequency.y_label, "frequency, Hz");
  const std::string commands = GnuplotCommands(frequency, "d.dat", "f.png");
  EXPECT_NE(commands.find("index 0 using 1:2:3 with yerrorbars"), std::string::npos) << commands;
  EXPECT_NE(commands.find("index 1 using 1:2:3 with yerrorbars"), std::string::npos) << commands;
  // The data: amplitude, value and std per point; the first point is a = 1, f = 10.3 Hz.
  const std::string data = GnuplotData(frequency);
  EXPECT_EQ(data.rfind("1 10.3 0.0103\n", 0), 0u) << data.substr(0, 60);
  const Figure damping = MakeBackboneFigure(result, 1, true);
  EXPECT_EQ(damping.y_label, "damping ratio, 1");
  EXPECT_EQ(GnuplotData(damping).rfind("1 0.008 8e-06\n", 0), 0u);
  // Only mode 2 has a backbone: its line in the report, and no line for mode 1.
  const std::string markdown = BackboneMarkdown(result);
  EXPECT_EQ(markdown.find("- Mode 1 "), std::string::npos) << markdown;
  EXPECT_NE(markdown.find("- Mode 2 (10.1 Hz): 5 windows"), std::string::npos) << markdown;
  // From a = e^{-2}: 10 (1 + 0.03 e^{-4}) = 10.0055 Hz (4 digits), to a = 1: 10.3 Hz.
  EXPECT_NE(markdown.find("frequency 10.01 to 10.3 Hz"), std::string::npos) << markdown;
  if (!GnuplotAvailable()) GTEST_SKIP() << "gnuplot with pngcairo not installed";
  const fs::path dir =
      fs::temp_directory_path() / ("mbid_backbone_figure_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::vector<std::string> files = DrawBackboneFigures(dir.string(), result);
  EXPECT_EQ(files,
            (std::vector<std::string>{"backbone_frequency_2.png", "backbone_damping_2.png"}));
  for (const std::string& file : files) EXPECT_GT(fs::file_size(dir / file), 1000u) << file;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace mbid::report
