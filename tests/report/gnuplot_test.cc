#include "mbid/report/gnuplot.h"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "gnuplot_standby.h"

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

// The figures of a batch, drawn alone (one fresh process each) and through `draw`, give the same
// bytes: whatever process draws them, the PNGs are the same.
void ExpectSameAsAlone(const fs::path& folder, const std::function<void(FigureBatch&)>& draw) {
  const Figure figures[] = {Sine("first", 1.0), Sine("second", 2.0), Sine("third", 3.0)};
  for (int i = 0; i < 3; ++i) {
    DrawFigure(figures[i], (folder / ("alone" + std::to_string(i) + ".png")).string());
  }
  {
    FigureBatch batch;
    for (int i = 0; i < 3; ++i) {
      DrawFigure(figures[i], (folder / ("batch" + std::to_string(i) + ".png")).string());
    }
    draw(batch);
  }
  for (int i = 0; i < 3; ++i) {
    const std::string alone = ReadBytes(folder / ("alone" + std::to_string(i) + ".png"));
    EXPECT_GT(alone.size(), 1000u);
    EXPECT_TRUE(alone == ReadBytes(folder / ("batch" + std::to_string(i) + ".png"))) << i;
  }
}

// The gnuplot processes this test process started and has not reaped.
std::vector<pid_t> GnuplotChildren() {
  std::vector<pid_t> children;
  for (const auto& entry : fs::directory_iterator("/proc")) {
    std::ifstream stat(entry.path() / "stat");
    pid_t pid = 0, parent = 0;
    std::string name, state;
    if (!(stat >> pid >> name >> state >> parent)) continue;
    if (parent == ::getpid() && name == "(gnuplot)") children.push_back(pid);
  }
  return children;
}

TEST_F(GnuplotTest, ProcessesStartedAheadDrawTheSameFigures) {
  PrepareGnuplot(2);
  EXPECT_EQ(GnuplotChildren().size(), 2u);
  PrepareGnuplot(2);  // two wait already: none more
  EXPECT_EQ(GnuplotChildren().size(), 2u);
  ExpectSameAsAlone(dir_ / "it's a folder", [](FigureBatch& batch) { batch.Draw(); });
  // Both were taken (and have ended): the batch's two halves used them.
  EXPECT_FALSE(internal::TakeStandbyGnuplot().has_value());
  EXPECT_TRUE(GnuplotChildren().empty());
}

TEST_F(GnuplotTest, AFailingFigureInAProcessStartedAheadIsReportedWithGnuplotsMessage) {
  PrepareGnuplot(1);
  Figure broken = Sine("broken", 1.0);
  broken.series[0].style = "no-such-style";
  FigureBatch batch;
  DrawFigure(broken, (dir_ / "broken.png").string());
  try {
    batch.Draw();
    ADD_FAILURE() << "no error";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("gnuplot failed on"), std::string::npos);
    EXPECT_NE(std::string(error.what()).find("no-such-style"), std::string::npos) << error.what();
  }
  EXPECT_FALSE(internal::TakeStandbyGnuplot().has_value());  // it was the one used
  for (const auto& entry : fs::recursive_directory_iterator(dir_)) {
    EXPECT_TRUE(entry.is_directory()) << entry.path() << " left behind";
  }
}

TEST_F(GnuplotTest, AProcessStartedAheadThatDiedIsReplacedByAFreshOne) {
  PrepareGnuplot(1);
  const std::vector<pid_t> started = GnuplotChildren();
  ASSERT_EQ(started.size(), 1u);
  ::kill(started[0], SIGKILL);
  // Dead, not yet reaped: the batch must notice it, draw with a fresh process and not die of
  // SIGPIPE writing to it.
  for (int i = 0; i < 100; ++i) {
    std::ifstream stat("/proc/" + std::to_string(started[0]) + "/stat");
    std::string pid, name, state;
    stat >> pid >> name >> state;
    if (state == "Z") break;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ExpectSameAsAlone(dir_, [](FigureBatch& batch) { batch.Draw(1); });
  EXPECT_TRUE(GnuplotChildren().empty());
}

TEST_F(GnuplotTest, AProcessThatDiesWhileTakingTheScriptIsReportedNotFatal) {
  PrepareGnuplot(1);
  const std::optional<internal::StandbyGnuplot> process = internal::TakeStandbyGnuplot();
  ASSERT_TRUE(process.has_value());
  ::kill(process->pid, SIGKILL);
  std::string log;
  // Its input is closed when it dies: writing to it raises SIGPIPE, which must not end us.
  EXPECT_EQ(internal::RunStandby(*process, std::string(1 << 17, '#'), &log), -1);
}

TEST_F(GnuplotTest, AStartedBatchCommitsItsFiguresOnlyAtFinish) {
  ExpectSameAsAlone(dir_, [this](FigureBatch& batch) {
    batch.Start();
    // Drawn meanwhile into temporary names: nothing under the final ones before Finish.
    EXPECT_FALSE(fs::exists(dir_ / "batch0.png"));
    batch.Finish();
    EXPECT_TRUE(fs::exists(dir_ / "batch0.png"));
    batch.Finish();  // nothing more to do
  });
}

TEST_F(GnuplotTest, AStartedBatchNotFinishedLeavesNothing) {
  {
    FigureBatch batch;
    DrawFigure(Sine("dropped", 1.0), (dir_ / "dropped.png").string());
    batch.Start();
  }  // an error unwound past the report: the drawing is waited for, its PNG dropped
  for (const auto& entry : fs::recursive_directory_iterator(dir_)) {
    EXPECT_TRUE(entry.is_directory()) << entry.path() << " left behind";
  }
}

}  // namespace
}  // namespace mbid::report
