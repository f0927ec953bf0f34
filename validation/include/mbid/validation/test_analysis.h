#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "mbid/common/measurement.h"
#include "mbid/identification/modal_result.h"
#include "mbid/identification/options.h"
#include "mbid/model/mechanical_model.h"
#include "mbid/records/records.h"
#include "mbid/simulation/excitation.h"
#include "mbid/simulation/simulate.h"
#include "mbid/updating/characteristic.h"
#include "mbid/updating/global_search.h"
#include "mbid/updating/output_error.h"
#include "mbid/updating/settings.h"
#include "mbid/validation/release_cut.h"

namespace mbid::validation {

// One test of `mbid run` and everything the cycle derives from it.
struct RunTest {
  std::string name;
  std::string origin;  // "simulation", the record's file, or "synthetic modes"
  Measurement measured;
  std::optional<Measurement> exact;             // the noise-free record, when known
  std::optional<records::ImportReport> import;  // what reading the record's file did
  // The test's own excitation (record_source.h); unset: the scenario's.
  std::optional<simulation::Excitation> excitation;
  std::optional<AppliedRelease> release;  // where a recorded test was cut (release_cut.h)
  // The record as read, before the cut at a detected or given release (the record figure marks
  // the release on it); unset when the record was not cut.
  std::optional<Measurement> recorded;
  std::optional<simulation::SimulationResult> simulation;  // a simulated test's integration
  std::vector<std::string> simulation_warnings;  // of the test as simulated (FindStartFarFromRest)
  identification::ModalResult identified;
  std::shared_ptr<const updating::CharacteristicResult> algebraic;  // Route 1, if it ran
  std::string start_note;                                           // where Route 2 started
  updating::GlobalSearchResult search;  // Route 2 from many starts (global_search.h)
  updating::UpdateResult tuned;         // its best minimum
  bool passed = false;                  // verdict == "passed"
  // "passed": the re-simulation correlates at least at the threshold on every channel, the
  // identification is reliable, every tuned joint parameter is determined (on the standard
  // deviations its credibility check inflated) and the minimum is unique; "failed": some channel
  // below the threshold;
  // "inconclusive": the correlations pass but something else is missing. `reasons` says why.
  std::string verdict = "failed";
  std::vector<std::string> reasons;
};

// The worst of the tests' verdicts: failed before inconclusive before passed.
std::string CombineVerdicts(const std::vector<std::string>& verdicts);

// What every test of a run shares.
struct RunSettings {
  identification::IdentificationOptions identification;
  updating::UpdatingSettings updating;
  double min_correlation = 0.95;
};

// The cycle after the record: identify the modes (the free decay after any forcing), Route 1
// (eq. 7) on their poles, Route 2 (Ceres) from Route 1's set or the scenario's values, and the
// verdict on the re-simulation. `identified`, if set, hears the test once its modes are
// identified. Throws NumericalError when Route 2 does not converge.
void AnalyseTest(RunTest& test, const model::MechanicalModel& model,
                 const simulation::Excitation& excitation, const RunSettings& settings,
                 const std::function<void(const std::string&)>& say,
                 const std::function<void(const RunTest&)>& identified = {});

}  // namespace mbid::validation
