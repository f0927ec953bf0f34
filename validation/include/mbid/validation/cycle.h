#pragma once

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "mbid/model/linear_model.h"
#include "mbid/model/mechanical_model.h"
#include "mbid/simulation/excitation.h"
#include "mbid/validation/record_import.h"
#include "mbid/validation/scenario.h"
#include "mbid/validation/test_analysis.h"

namespace mbid::validation {

struct CycleOptions {
  // --channel, --unit, --fill-gaps, --release for the scenario's measured files.
  ImportOverrides import;
  bool quiet = true;  // no progress of the fits on standard error
  // Profile-likelihood intervals of the tuned parameters even where the scenario's
  // updating.profile.enabled does not ask for them (updating/profile.h).
  bool profile = false;
  // Progress lines ("simulated the test: ...", "Route 2: ..."); empty: none.
  std::function<void(const std::string&)> say;
  // Called with each test as soon as it is identified (its record, release and modes final),
  // before Routes 1 and 2, and the run's number of tests: e.g. to draw its figures meanwhile.
  std::function<void(const RunTest&, size_t)> identified;
};

// The validation cycle of one scenario, in memory: its tests (the scenario's records, or one
// test simulated from the model), each identified, tuned (Route 1 -> Route 2) and re-simulated,
// and the verdict over all of them.
struct CycleResult {
  std::shared_ptr<const model::MechanicalModel> model;
  model::LinearModel linear;
  std::vector<model::Mode> exact_modes;  // of the scenario's model before tuning
  simulation::Excitation excitation;     // the scenario's, or the first test's own
  std::vector<RunTest> tests;
  // "passed", "failed" or "inconclusive": the worst of the tests' verdicts (CombineVerdicts).
  std::string verdict = "failed";
  std::vector<std::string> reasons;  // prefixed "test NAME: " when there are several tests
  std::string verdict_line;          // "re-simulation vs record: K(x) = ...; threshold ... -> ..."
  double min_correlation = 0.95;     // the threshold the verdict used
};

// Per channel, the smallest re-simulation correlation K over the tests: what the verdict of
// several tests is judged on.
std::map<std::string, double> CalcWorstCorrelation(const std::vector<RunTest>& tests);

// The tests' warnings: the simulation's, the reading's (with `with_import`), the
// identification's and the fits', each prefixed "test NAME: " when there are several tests; a
// line shared by jointly tuned tests once.
std::vector<std::string> CollectWarnings(const CycleResult& cycle, bool with_import);

// Runs the cycle on `scenario`. Throws InputError on bad input (records, settings) and
// NumericalError when a fit does not converge.
CycleResult RunCycle(const Scenario& scenario, const CycleOptions& options = {});

}  // namespace mbid::validation
