#pragma once

#include <functional>
#include <string>
#include <vector>

#include "mbid/model/linear_model.h"
#include "mbid/model/mechanical_model.h"
#include "mbid/report/gnuplot.h"
#include "mbid/report/run_folder.h"
#include "mbid/validation/scenario.h"
#include "mbid/validation/test_analysis.h"

namespace mbid::report {

// Writes report.md into `folder` and starts drawing its figures (gnuplot PNGs; a test's own
// subfolder when there are several) through `batch`, whose Finish the caller calls: per test
// the record, Table 1 with the known modes beside it, Route 1's sets, Table 2 and the
// re-simulation; for several tests the Table 2 spread; the verdict. Returns the number of
// figures. `early`, if given, has drawn some tests' record and identification figures already.
int WriteRunReport(const std::string& folder, const validation::Scenario& scenario,
                   const model::MechanicalModel& model, const std::vector<model::Mode>& exact_modes,
                   const std::vector<validation::RunTest>& tests, const std::string& verdict,
                   const std::function<void(const std::string&)>& say, EarlyRunFigures* early,
                   FigureBatch& batch);

// Where a test's figures go, relative to the run folder: "" for a run of one test, else its
// own subfolder "<name>/".
std::string TestFolderPrefix(const std::string& test_name, size_t test_count);

// A test's record and identification figures into `folder` (the test's own: the run folder or
// its subfolder), file names prefixed with `prefix` in the lists. Through the calling thread's
// FigureBatch, if one is active.
TestFigureFiles DrawIdentificationFigures(const std::string& folder, const std::string& prefix,
                                          const validation::RunTest& test);

}  // namespace mbid::report
