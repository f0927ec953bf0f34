#include "mbid/app/run_cycle.h"

#include <fmt/format.h>

#include <chrono>
#include <filesystem>
#include <iostream>

#include "mbid/common/output_folder.h"
#include "mbid/report/run_folder.h"
#include "mbid/validation/cycle.h"
#include "mbid/validation/scenario.h"

namespace mbid::app {
namespace {

namespace fs = std::filesystem;

// Progress lines on standard error, with the time since the start.
class Progress {
 public:
  explicit Progress(bool quiet) : quiet_(quiet), start_(std::chrono::steady_clock::now()) {}
  void Say(const std::string& message) const {
    if (quiet_) return;
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    std::cerr << fmt::format("mbid: [{:6.2f} s] {}\n", elapsed, message);
  }

 private:
  bool quiet_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace

int RunValidationCycle(const std::string& scenario_path, const std::string& output_dir,
                       const CommonOptions& common) {
  const Progress progress(common.quiet);
  const auto say = [&](const std::string& message) { progress.Say(message); };
  const validation::Scenario scenario = validation::LoadScenario(scenario_path);
  // The name may hold anything YAML allows ("..", "a/b", "$(x)"): it must not choose the place.
  const fs::path final_dir =
      output_dir.empty() ? fs::path("results") / SafeFileName(scenario.name, scenario_path, "name")
                         : fs::path(output_dir);
  progress.Say(fmt::format("scenario {} ({})", scenario.name, scenario_path));
  OutputFolder folder(final_dir, "run", common.overwrite, report::IsRunFolder);

  validation::CycleOptions options;
  options.import = common.import;
  options.quiet = common.quiet;
  options.profile = common.profile;
  options.say = say;
  // The record and identification figures are drawn while the tests are tuned.
  report::EarlyRunFigures early((folder / "").string());
  options.identified = [&early](const validation::RunTest& test, size_t test_count) {
    early.Start(test, test_count);
  };
  const validation::CycleResult cycle = validation::RunCycle(scenario, options);
  // Said even with --quiet, as `mbid update` says them (the reading's are in the progress).
  for (const std::string& line : validation::CollectWarnings(cycle, common.quiet)) {
    std::cerr << "mbid: warning: " << line << "\n";
  }
  progress.Say(cycle.verdict_line);
  for (const std::string& reason : cycle.reasons) {
    // Said even with --quiet: a run that did not pass says why.
    std::cerr << "mbid: " << (cycle.verdict == "failed" ? "failed" : "inconclusive") << ": "
              << reason << "\n";
  }
  const int figure_count =
      report::WriteRunFolder(cycle, scenario, (folder / "").string(), say, &early);
  folder.Commit();
  progress.Say(fmt::format("wrote {}/ (run.h5, summary.json, report.md, {} figures)",
                           final_dir.string(), figure_count));
  return 0;
}

}  // namespace mbid::app
