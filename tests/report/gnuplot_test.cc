#include "mbid/report/gnuplot.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace mbid::report {
namespace {

namespace fs = std::filesystem;

std::string ReadBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream bytes;
  bytes << in.rdbuf();
  return bytes.str();
}

Figure Sine(const std::string& title, double frequency_hz) {
  Figure figure;
  figure.title = title;
  figure.x_label = "time, s";
  figure.y_label = "angle, rad";
  PlotSeries series{"sine", Eigen::VectorXd::LinSpaced(200, 0.0, 2.0), {}, "lines"};
  series.y = (2 * M_PI * frequency_hz * series.x.array()).sin().matrix();
  figure.series.push_back(series);
  return figure;
}

class GnuplotTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!GnuplotAvailable()) GTEST_SKIP() << "gnuplot with pngcairo not installed";
    dir_ = fs::temp_directory_path() / ("mbid_gnuplot_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "it's a folder");
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

TEST_F(GnuplotTest, ABatchDrawsTheSameFiguresAsSeparateProcesses) {
  // `reset` between the figures of one script: the second (log y) must not change the third.
  Figure logarithmic = Sine("second", 2.0);
  logarithmic.log_y = true;
  logarithmic.series[0].y = logarithmic.series[0].y.array().abs() + 1e-3;
  const Figure figures[] = {Sine("first", 1.0), logarithmic, Sine("third", 3.0)};
  const fs::path folder = dir_ / "it's a folder";  // a quote in the path
  for (int i = 0; i < 3; ++i) {
    DrawFigure(figures[i], (folder / ("alone" + std::to_string(i) + ".png")).string());
  }
  {
    FigureBatch batch;
    for (int i = 0; i < 3; ++i) {
      DrawFigure(figures[i], (folder / ("batch" + std::to_string(i) + ".png")).string());
    }
    EXPECT_FALSE(fs::exists(folder / "batch0.png"));  // collected, not drawn yet
    batch.Draw();
  }
  for (int i = 0; i < 3; ++i) {
    const std::string alone = ReadBytes(folder / ("alone" + std::to_string(i) + ".png"));
    EXPECT_GT(alone.size(), 1000u);
    EXPECT_TRUE(alone == ReadBytes(folder / ("batch" + std::to_string(i) + ".png"))) << i;
  }
}

TEST_F(GnuplotTest, AFailingFigureLeavesNoFileOfItsBatch) {
  Figure broken = Sine("broken", 1.0);
  broken.series[0].style = "no-such-style";
  FigureBatch batch;
  DrawFigure(Sine("fine", 1.0), (dir_ / "fine.png").string());
  DrawFigure(broken, (dir_ / "broken.png").string());
  EXPECT_THROW(batch.Draw(), std::runtime_error);
  EXPECT_FALSE(fs::exists(dir_ / "fine.png"));
  EXPECT_FALSE(fs::exists(dir_ / "broken.png"));
  for (const auto& entry : fs::recursive_directory_iterator(dir_)) {
    EXPECT_TRUE(entry.is_directory()) << entry.path() << " left behind";
  }
}

}  // namespace
}  // namespace mbid::report
