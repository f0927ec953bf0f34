#include "mbid/mbid.h"

#include <fmt/format.h>

#include <iostream>
#include <memory>
#include <optional>

#include "mbid/common/output_folder.h"
#include "mbid/identification/identify.h"
#include "mbid/report/run_folder.h"
#include "mbid/simulation/simulate.h"
#include "mbid/validation/identification_settings.h"
#include "mbid/validation/loaded_test.h"
#include "mbid/validation/recorded_tests.h"

namespace mbid {
namespace {

// Progress for library calls: standard error unless quiet.
std::function<void(const std::string&)> Progress(bool quiet) {
  if (quiet) return [](const std::string&) {};
  return [](const std::string& message) { std::cerr << "mbid: " << message << "\n"; };
}

UpdateResult Summarise(const updating::GlobalSearchResult& search, const std::string& start) {
  UpdateResult result;
  result.fit = search.best;
  result.search = search;
  result.start = start;
  result.non_unique = search.non_unique;
  const updating::UpdateResult& fit = search.best;
  result.converged = fit.termination == updating::UpdateResult::Termination::kConverged;
  result.credible = fit.credible;
  result.credibility = fit.credibility;
  result.undetermined = fit.undetermined;
  result.chi_square_per_dof = fit.chi_square_per_dof;
  for (const updating::ParameterEstimate& p : fit.parameters) {
    ParameterValue& value = result.parameters[p.name];
    value.value = p.value;
    value.std = p.std;
    value.relative_std = p.relative_std;
    value.interval_lower = p.interval_lower;
    value.interval_upper = p.interval_upper;
    if (p.profile.computed) {
      value.profile_lower = p.profile.lower;
      value.profile_upper = p.profile.upper;
      value.profile_lower_open = p.profile.lower_open;
      value.profile_upper_open = p.profile.upper_open;
    }
    value.determined = p.determined;
    value.why_undetermined = p.why_undetermined;
    value.units = p.units;
    value.test = p.test;
  }
  return result;
}

Verdict ParseVerdict(const std::string& verdict) {
  if (verdict == "passed") return Verdict::kPassed;
  if (verdict == "inconclusive") return Verdict::kInconclusive;
  return Verdict::kFailed;
}

}  // namespace

Scenario LoadScenario(const std::string& path) { return validation::LoadScenario(path); }

Scenario LoadScenarioFromText(const std::string& yaml, const std::string& source) {
  return validation::LoadScenarioFromText(yaml, source);
}

std::string DefaultScenarioPath(const std::string& data_dir_hint) {
  return validation::DefaultScenarioPath(data_dir_hint);
}

Measurement Simulate(const Scenario& scenario) {
  const std::unique_ptr<model::MechanicalModel> model = scenario.MakeModel();
  return simulation::Simulate(*model, scenario.RequireExcitation(), scenario.simulation,
                              scenario.sensors)
      .measured;
}

Measurement ReadRecord(const std::string& path, const records::ImportOptions& options) {
  return records::ImportMeasurement(path, options);
}

ModalResult Identify(const Measurement& record, const IdentificationOptions& options) {
  // Identify checks the options itself; a record made in memory has not been checked yet.
  record.Validate("record");
  return identification::Identify(record, options, "record");
}

ModalResult IdentifyTest(const Measurement& record, const Scenario& test,
                         const IdentificationOptions& options) {
  if (!test.has_excitation || options.release != identification::ReleaseMode::kDetect) {
    return mbid::Identify(record, options);
  }
  return mbid::Identify(record, validation::FreeDecayOptions(options, test.excitation));
}

UpdateResult Update(const Scenario& scenario, const std::vector<Measurement>& records) {
  if (records.empty()) {
    throw InputError("Update", "records", "no record", "at least one recorded test");
  }
  return Update(scenario, records,
                std::vector<simulation::Excitation>(records.size(), scenario.RequireExcitation()));
}

UpdateResult Update(const Scenario& scenario, const std::vector<Measurement>& records,
                    const std::vector<simulation::Excitation>& excitations) {
  if (records.empty()) {
    throw InputError("Update", "records", "no record", "at least one recorded test");
  }
  if (excitations.size() != records.size()) {
    throw InputError(
        "Update", "excitations",
        fmt::format("{} excitations for {} records", excitations.size(), records.size()),
        "one excitation per record");
  }
  const std::unique_ptr<model::MechanicalModel> model = scenario.MakeModel();
  const identification::IdentificationOptions identification = scenario.identification;
  updating::UpdatingSettings settings = scenario.updating;
  settings.options.quiet = true;
  std::vector<validation::LoadedTest> tests;
  for (size_t i = 0; i < records.size(); ++i) {
    const std::string origin = fmt::format("record {}", i + 1);
    records[i].Validate(origin);
    tests.push_back(
        validation::PrepareTest(records[i], origin, excitations[i], *model, identification));
  }
  const validation::RecordedUpdate update =
      validation::UpdateFromTests(*model, tests, settings, [](const std::string&) {});
  UpdateResult result = Summarise(update.search, update.start);
  validation::PlaceReleases(update.search.best, &tests);
  for (const validation::LoadedTest& test : tests) {
    result.release_time_s.push_back(test.release.release_time_s);
    result.release.push_back(test.release.how);
  }
  return result;
}

std::string ToString(Verdict verdict) {
  switch (verdict) {
    case Verdict::kPassed:
      return "passed";
    case Verdict::kFailed:
      return "failed";
    case Verdict::kInconclusive:
      return "inconclusive";
  }
  return "failed";
}

ValidationResult RunValidationCycle(const Scenario& scenario, const ValidationOptions& options) {
  // The folder is claimed before the long work: a refused folder fails at once.
  std::unique_ptr<OutputFolder> folder;
  if (!options.output_folder.empty()) {
    folder = std::make_unique<OutputFolder>(options.output_folder, "run", options.overwrite,
                                            report::IsRunFolder);
  }
  validation::CycleOptions cycle_options;
  cycle_options.quiet = options.quiet;
  cycle_options.say = Progress(options.quiet);
  // With a folder, the record and identification figures are drawn while the tests are tuned.
  std::optional<report::EarlyRunFigures> early;
  if (folder) {
    early.emplace((*folder / "").string());
    cycle_options.identified = [&early](const validation::RunTest& test, size_t test_count) {
      early->Start(test, test_count);
    };
  }
  ValidationResult result;
  result.cycle = validation::RunCycle(scenario, cycle_options);
  result.verdict = ParseVerdict(result.cycle.verdict);
  result.reasons = result.cycle.reasons;
  result.min_correlation = result.cycle.min_correlation;
  result.correlation = validation::CalcWorstCorrelation(result.cycle.tests);
  const validation::RunTest& first = result.cycle.tests.front();
  result.identified = first.identified;
  result.updated = Summarise(first.search, first.start_note);
  if (folder) {
    report::WriteRunFolder(result.cycle, scenario, (*folder / "").string(), cycle_options.say,
                           &*early);
    folder->Commit();
  }
  return result;
}

}  // namespace mbid
