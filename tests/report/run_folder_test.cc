// The run folder's figures drawn early (report/run_folder.h, EarlyRunFigures: the record and
// identification figures while the tests are tuned) are the figures the report draws itself.
#include "mbid/report/run_folder.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <string>

#include "mbid/report/gnuplot.h"
#include "mbid/validation/cycle.h"
#include "mbid/validation/scenario.h"

namespace mbid::report {
namespace {

namespace fs = std::filesystem;

// Every file under `folder` but the ones that carry times (run.h5, summary.json), by relative
// path.
std::map<std::string, std::string> ReadFolder(const fs::path& folder) {
  std::map<std::string, std::string> files;
  for (const fs::directory_entry& entry : fs::recursive_directory_iterator(folder)) {
    if (!entry.is_regular_file()) continue;
    const std::string name = fs::relative(entry.path(), folder).string();
    if (name == "run.h5" || name == "summary.json") continue;
    std::ifstream in(entry.path(), std::ios::binary);
    std::stringstream bytes;
    bytes << in.rdbuf();
    files[name] = bytes.str();
  }
  return files;
}

TEST(RunFolderTest, EarlyFiguresAreTheOnesTheReportDrawsItself) {
  if (!GnuplotAvailable()) GTEST_SKIP() << "gnuplot with pngcairo not installed";
  const fs::path dir = fs::temp_directory_path() / ("mbid_run_folder_" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir / "early");
  fs::create_directories(dir / "late");
  const validation::Scenario scenario =
      validation::LoadScenario(std::string(MBID_SOURCE_DIR) + "/scenarios/reference-crane.yaml");
  int started = 0;
  validation::CycleResult cycle;
  {
    EarlyRunFigures early((dir / "early" / "").string());
    validation::CycleOptions options;
    options.identified = [&](const validation::RunTest& test, size_t test_count) {
      EXPECT_FALSE(test.identified.modes.empty());  // identified, not yet tuned
      EXPECT_TRUE(test.tuned.parameters.empty());
      early.Start(test, test_count);
      ++started;
    };
    cycle = validation::RunCycle(scenario, options);
    const auto quiet = [](const std::string&) {};
    // Reference crane: record (psi, phi), spectrum, reconstruction (2), stabilization,
    // re-simulation (2), convergence.
    EXPECT_EQ(WriteRunFolder(cycle, scenario, (dir / "early" / "").string(), quiet, &early), 9);
    EXPECT_EQ(WriteRunFolder(cycle, scenario, (dir / "late" / "").string(), quiet), 9);
  }
  EXPECT_EQ(started, 1);
  // What it draws by itself, before any report: the record and identification figures, in the
  // folder it was given.
  {
    EarlyRunFigures probe((dir / "probe" / "").string());
    probe.Start(cycle.tests.front(), 1);
    const std::optional<TestFigureFiles> drawn = probe.Take(cycle.tests.front().name);
    ASSERT_TRUE(drawn.has_value());
    EXPECT_EQ(drawn->record.size(), 2u);          // psi, phi
    EXPECT_EQ(drawn->identification.size(), 4u);  // spectrum, 2 reconstructions, stabilization
    EXPECT_TRUE(drawn->updating.empty());
    for (const std::string& file : drawn->identification) {
      EXPECT_TRUE(fs::exists(dir / "probe" / file)) << file;
    }
    EXPECT_FALSE(probe.Take(cycle.tests.front().name).has_value());  // taken once
  }
  const auto early_files = ReadFolder(dir / "early");
  const auto late_files = ReadFolder(dir / "late");
  EXPECT_EQ(early_files.size(), 10u);  // 9 figures and report.md
  ASSERT_EQ(early_files.size(), late_files.size());
  for (const auto& [name, bytes] : late_files) {
    ASSERT_EQ(early_files.count(name), 1u) << name;
    EXPECT_TRUE(early_files.at(name) == bytes) << name;
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace mbid::report
