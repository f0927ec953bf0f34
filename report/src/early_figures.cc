// Record and identification figures drawn while the run's updating goes on (run_folder.h).
#include <filesystem>
#include <utility>

#include "mbid/report/gnuplot.h"
#include "mbid/report/run_folder.h"
#include "run_document.h"

namespace mbid::report {

EarlyRunFigures::EarlyRunFigures(std::string folder) : folder_(std::move(folder)) {}

EarlyRunFigures::~EarlyRunFigures() {
  for (auto& [name, drawing] : drawing_) {
    if (drawing.valid()) drawing.wait();
  }
}

void EarlyRunFigures::Start(const validation::RunTest& test, size_t test_count) {
  if (drawing_.count(test.name)) return;
  const std::string prefix = TestFolderPrefix(test.name, test_count);
  const std::string test_folder = (std::filesystem::path(folder_) / prefix / "").string();
  // The gnuplot check starts a process too: on this thread it would delay the updating.
  drawing_[test.name] = std::async(
      std::launch::async, [test, prefix, test_folder]() -> std::optional<TestFigureFiles> {
        if (!GnuplotAvailable()) return std::nullopt;
        std::filesystem::create_directories(test_folder);
        FigureBatch batch;  // this thread's own
        TestFigureFiles files = DrawIdentificationFigures(test_folder, prefix, test);
        batch.Draw(1);  // one gnuplot process: the updating runs on the other core
        // The last figures wait for the updating's end; their two processes start meanwhile.
        PrepareGnuplot(2);
        return files;
      });
}

std::optional<TestFigureFiles> EarlyRunFigures::Take(const std::string& test_name) {
  const auto found = drawing_.find(test_name);
  if (found == drawing_.end() || !found->second.valid()) return std::nullopt;
  return found->second.get();
}

}  // namespace mbid::report
