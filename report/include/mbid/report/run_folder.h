#pragma once

#include <functional>
#include <future>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "mbid/validation/cycle.h"
#include "mbid/validation/scenario.h"

namespace mbid::report {

// The PNG files of one test's figures in the run report, by section (paths relative to the run
// folder).
struct TestFigureFiles {
  std::vector<std::string> record, identification, backbone, updating;
};

// Each test's record and identification figures (record, spectrum, reconstruction,
// stabilization, backbones), drawn by a thread of their own from the moment the test is
// identified (validation::CycleOptions::identified), while Route 1 and 2 run on the other core;
// WriteRunFolder then draws only the updating figures. The PNGs are the ones WriteRunFolder
// would draw itself.
class EarlyRunFigures {
 public:
  explicit EarlyRunFigures(std::string folder);
  ~EarlyRunFigures();  // waits for the drawings still running
  EarlyRunFigures(const EarlyRunFigures&) = delete;
  EarlyRunFigures& operator=(const EarlyRunFigures&) = delete;

  // Starts drawing `test`'s figures (it is copied) into the run folder, in the test's subfolder
  // when the run has several tests (`test_count`). Draws nothing without gnuplot.
  void Start(const validation::RunTest& test, size_t test_count);
  // The files of the test's figures once drawn (waits); nullopt if none were started for it or
  // gnuplot is missing. Rethrows a drawing error.
  std::optional<TestFigureFiles> Take(const std::string& test_name);

 private:
  std::string folder_;
  std::map<std::string, std::future<std::optional<TestFigureFiles>>> drawing_;
};

// Writes the results of a validation cycle into `folder` (an existing, empty folder, normally
// OutputFolder's temporary one): run.h5, summary.json (layout: docs/interfaces.md), report.md
// and its figures, those not drawn already by `early`. Returns the number of figures.
int WriteRunFolder(const validation::CycleResult& cycle, const validation::Scenario& scenario,
                   const std::string& folder, const std::function<void(const std::string&)>& say,
                   EarlyRunFigures* early = nullptr);

// Whether `folder` holds the results of an earlier `mbid run` and nothing else: run.h5 and
// summary.json (or the marker file of this version), report.md, PNG figures, and subfolders of
// figures for several tests.
bool IsRunFolder(const std::string& folder);

}  // namespace mbid::report
