#pragma once

// mbid for library users: the whole chain (scenario -> simulated or recorded test -> modal
// identification -> model updating -> validation verdict) as a handful of calls on plain
// results, in memory. The capability libraries behind it (mbid/<library>/*.h) stay available
// for finer control; each result here keeps its detailed counterpart beside the summary.
//
// Errors are exceptions with the command line's one-line messages: mbid::InputError for bad
// input (a file, key path, line or column and what was expected; the command's exit 2) and
// mbid::NumericalError for a fit or integration that failed (exit 3).

#include <limits>
#include <map>
#include <string>
#include <vector>

#include "mbid/common/error.h"
#include "mbid/common/measurement.h"
#include "mbid/common/stop.h"
#include "mbid/identification/modal_result.h"
#include "mbid/identification/options.h"
#include "mbid/records/records.h"
#include "mbid/updating/global_search.h"
#include "mbid/updating/output_error.h"
#include "mbid/validation/cycle.h"
#include "mbid/validation/scenario.h"

namespace mbid {

// A scenario file (docs/scenarios.md): the machine, the test, identification and updating
// settings. Read strictly: unknown keys are errors.
using Scenario = validation::Scenario;

// Identified modes, ascending in frequency: `modes[k].frequency_hz` (damped),
// `decay_rate_per_s`, `damping_ratio`, their standard deviations (`std_frequency_hz`,
// `std_decay_rate_per_s`), amplitudes and phases per channel; `reliable` and `reasons` say
// whether the record supports them.
using ModalResult = identification::ModalResult;
using IdentificationOptions = identification::IdentificationOptions;

// Reads a scenario file.
Scenario LoadScenario(const std::string& path);

// The same from YAML text in memory; `source` names it in error messages.
Scenario LoadScenarioFromText(const std::string& yaml, const std::string& source = "scenario");

// The built-in reference scenario (the truck crane): scenarios/reference-crane.yaml of
// $MBID_DATA_DIR, of the installation whose CMake package the program was built with, of
// <program>/../share/mbid, or of the source tree of a build.
std::string DefaultScenarioPath(const std::string& data_dir_hint);
inline std::string DefaultScenarioPath() {
#ifdef MBID_PACKAGE_DATA_DIR  // set by find_package(mbid): the package's share/mbid
  return DefaultScenarioPath(MBID_PACKAGE_DATA_DIR);
#else
  return DefaultScenarioPath(std::string());
#endif
}

// Simulates the scenario's test: the record its sensors would give (noise included, seeded by
// the scenario), sampled as the scenario says.
Measurement Simulate(const Scenario& scenario);

// Reads a record file (CSV/TSV, HDF5, MAT, UFF58, LVM; docs/records-formats.md), converting
// its units to SI. `options`: channel mapping, units, gap filling for files that need them.
Measurement ReadRecord(const std::string& path, const records::ImportOptions& options = {});

// Identifies the modes of a free-decay record (from its release on, when the record shows one).
ModalResult Identify(const Measurement& record, const IdentificationOptions& options = {});

// The same for a record of `test`'s excitation (Simulate(test), or a measured record of that
// test): after a forcing (an impulse, a burst) its free decay is analysed from where the forcing
// ends, as RunValidationCycle does; a pulse at the record's very start is no release the record
// could show. `options`' own release or window win.
ModalResult IdentifyTest(const Measurement& record, const Scenario& test,
                         const IdentificationOptions& options = {});

// One tuned parameter.
struct ParameterValue {
  double value = 0;
  double std = 0;           // one standard deviation (NaN: undefined)
  double relative_std = 0;  // std / value
  // Approximate 95% interval, widened by the credibility check's inflation.
  double interval_lower = 0;
  double interval_upper = 0;
  // Profile-likelihood interval (the scenario's updating.profile.enabled); NaN when not computed.
  // An open side ends at the last value reached (the bound): the records do not bound it there.
  double profile_lower = std::numeric_limits<double>::quiet_NaN();
  double profile_upper = std::numeric_limits<double>::quiet_NaN();
  bool profile_lower_open = false;
  bool profile_upper_open = false;
  bool determined = true;        // false: the records do not fix it (why_undetermined says why)
  std::string why_undetermined;  // empty when determined
  std::string units;
  std::string test;  // a nuisance parameter's test (offset, initial state); empty for shared ones
};

// Model updating on recorded tests: Route 1 (eq. 7) on the identified poles where it applies,
// then Route 2 (output-error fit) from many starts.
struct UpdateResult {
  std::map<std::string, ParameterValue> parameters;  // by name, e.g. "c_alpha"
  bool converged = false;
  // The fit's numbers are to be taken as they are: chi^2/dof within bounds, residuals white
  // enough (credibility lists why not).
  bool credible = true;
  std::vector<std::string> credibility;
  // Another minimum of the cost fits the records as well (statistically): see search.minima.
  bool non_unique = false;
  std::vector<std::string> undetermined;  // parameters the records leave open
  std::string start;                      // where the best minimum was reached from
  double chi_square_per_dof = 0;
  // Per record, where its free decay starts in its own time and how that was found ("detected",
  // "record start", "none", ...): a detected release where the fit placed it.
  std::vector<double> release_time_s;
  std::vector<std::string> release;
  updating::UpdateResult fit;           // the best minimum in full (covariance, history, fits)
  updating::GlobalSearchResult search;  // every minimum the search found
};

// Tunes the scenario's model (its `updating:` section says which parameters) to `records`, each
// one test of the scenario's excitation, cut at its release.
UpdateResult Update(const Scenario& scenario, const std::vector<Measurement>& records);
// The same with each record's own test, `excitations[i]` for `records[i]` (e.g. drops of
// different payloads, which the scenario's one excitation would tune as the same drop). An
// InputError unless there is one excitation per record.
UpdateResult Update(const Scenario& scenario, const std::vector<Measurement>& records,
                    const std::vector<simulation::Excitation>& excitations);

enum class Verdict { kPassed, kFailed, kInconclusive };

// "passed", "failed", "inconclusive".
std::string ToString(Verdict verdict);

struct ValidationOptions {
  // Non-empty: also write the run folder there (run.h5, summary.json, report.md, figures), as
  // `mbid run -o` does; an existing folder is replaced only if it is empty, or holds an earlier
  // run and `overwrite` is set.
  std::string output_folder;
  bool overwrite = false;
  bool quiet = true;  // false: progress lines on standard error
};

// The validation cycle: the scenario's tests (its records, or one simulated), each identified,
// tuned and re-simulated, with the verdict.
struct ValidationResult {
  // kPassed: every re-simulation correlates with its record at least at min_correlation on
  // every channel, the identification is reliable, every tuned joint parameter is determined
  // and the minimum unique; kFailed: a channel below the threshold; kInconclusive: otherwise.
  Verdict verdict = Verdict::kFailed;
  std::vector<std::string> reasons;  // why it did not pass
  double min_correlation = 0;
  std::map<std::string, double> correlation;  // per channel, the worst over the tests
  ModalResult identified;                     // of the first test
  UpdateResult updated;                       // of the first test
  validation::CycleResult cycle;              // every test in full
};

ValidationResult RunValidationCycle(const Scenario& scenario,
                                    const ValidationOptions& options = {});

}  // namespace mbid
