// `mbid update`: Route 1 (eqs. 6-8) on the first record's poles, then Route 2 (Ceres output
// error) on every record, as the campaign's update step does (campaign/update_step.cc).
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cmath>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "mbid/app/commands.h"
#include "mbid/app/exit_code.h"
#include "mbid/common/error.h"
#include "mbid/common/hdf5_io.h"
#include "mbid/common/json_io.h"
#include "mbid/updating/characteristic.h"
#include "mbid/updating/output_error.h"
#include "mbid/updating/profile.h"
#include "mbid/updating/result_io.h"
#include "mbid/updating/settings.h"
#include "mbid/validation/loaded_test.h"
#include "mbid/validation/recorded_tests.h"
#include "mbid/validation/release_profile.h"
#include "mbid/validation/scenario.h"

namespace mbid::app {
using validation::ImportReportToJson;
using validation::LoadedTest;
using validation::LoadScenario;
using validation::LoadTests;
using validation::RecordedUpdate;
using validation::Scenario;
using validation::UpdateFromTests;

namespace {

std::string FormatNumber(double value) {
  return std::isfinite(value) ? fmt::format("{:.6g}", value) : std::string("-");
}

void PrintSummary(const updating::UpdateResult& result,
                  const updating::CharacteristicResult* algebraic, const std::string& start,
                  const updating::GlobalSearchResult& search) {
  if (algebraic) {
    int admissible = 0;
    for (const auto& set : algebraic->solutions) admissible += set.admissible ? 1 : 0;
    std::cout << fmt::format("route 1: {} ({} admissible sets{})\n", algebraic->status_name(),
                             admissible, algebraic->ambiguous ? ", ambiguous choice" : "");
  }
  const std::string& best_start =
      search.minima.empty() ? start : search.minima.front().starts.front();
  std::cout << fmt::format("route 2: {} after {} iterations (start: {}{}), cost {:.6g} -> {:.6g}\n",
                           result.termination_name(), result.iterations, best_start,
                           best_start == start ? "" : "; the primary start was " + start,
                           result.initial_cost, result.final_cost);
  std::cout << fmt::format("{:<12} {:>13} {:>13} {:>11} {:>9} {:>10}\n", "parameter", "value",
                           "initial", "std", "rel_std", "units");
  for (const updating::ParameterEstimate& p : result.parameters) {
    // A nuisance parameter's name already carries its test ("<test>:payload_mass_kg").
    const std::string& name = p.name;
    std::cout << fmt::format("{:<12} {:>13} {:>13} {:>11} {:>9} {:>10}{}{}\n", name,
                             FormatNumber(p.value), FormatNumber(p.initial), FormatNumber(p.std),
                             FormatNumber(p.relative_std), p.units,
                             p.determined ? "" : "  (undetermined: " + p.why_undetermined + ")",
                             p.at_bound ? "  (at bound)" : "");
  }
  for (const std::string& line : updating::DescribeProfiles(result)) {
    std::cout << line << "\n";
  }
  for (const std::string& line : updating::DescribeGlobalSearch(search)) {
    std::cout << line << "\n";
  }
  for (const std::string& reason : result.credibility) {
    std::cout << "credibility: " << reason << "\n";
  }
  if (!result.undetermined.empty()) {
    std::cout << fmt::format("undetermined by the records: {}\n",
                             fmt::join(result.undetermined, ", "));
  }
  for (const updating::TestFit& fit : result.tests) {
    for (size_t c = 0; c < fit.channels.size(); ++c) {
      const double k = fit.correlation[static_cast<Eigen::Index>(c)];
      std::cout << fmt::format(
          "correlation K({}, {}) = {}\n", fit.name, fit.channels[c],
          std::isfinite(k) ? fmt::format("{:.4f}", k) : "- (no re-simulation)");
    }
    for (const std::string& line : updating::DescribeBaseline(fit)) std::cout << line << "\n";
  }
}

}  // namespace

int RunUpdateCommand(const std::string& scenario_path, const std::vector<std::string>& data_paths,
                     const std::string& output_path, const CommonOptions& common) {
  const Scenario scenario = LoadScenario(scenario_path);
  const auto model = scenario.MakeModel();
  updating::UpdatingSettings settings = scenario.updating;
  settings.options.quiet = common.quiet;
  if (common.profile) settings.profile.enabled = true;
  const identification::IdentificationOptions identification_options = scenario.identification;

  // Every record is read and checked before any long work starts.
  std::vector<LoadedTest> tests =
      LoadTests(data_paths, scenario, *model, identification_options, common.import, !common.quiet);

  const RecordedUpdate update =
      UpdateFromTests(*model, tests, settings, [&common](const std::string& line) {
        if (!common.quiet) std::cerr << "mbid: " << line << "\n";
      });
  const auto& algebraic = update.algebraic;
  const std::string& start = update.start;
  const std::string& note = update.note;
  const updating::GlobalSearchResult& search = update.search;
  const updating::UpdateResult& result = search.best;
  validation::PlaceReleases(result, &tests);  // reported where the fit placed them

  const bool converged = result.termination == updating::UpdateResult::Termination::kConverged;
  nlohmann::json summary = updating::UpdateResultToJson(result, algebraic.get());
  updating::AddGlobalSearchToJson(search, summary);
  summary["start"] = start;
  if (!search.minima.empty()) summary["best_start"] = search.minima.front().starts.front();
  summary["import"] = nlohmann::json::array();
  summary["release"] = nlohmann::json::array();
  for (const LoadedTest& test : tests) {
    nlohmann::json item = ImportReportToJson(test.import);
    item["file"] = test.path;
    summary["import"].push_back(item);
    nlohmann::json release = test.release.ToJson();
    release["file"] = test.path;
    summary["release"].push_back(release);
  }
  // The contract's field: where the first DATA's free decay starts, in its own time (each
  // file's cut is in `release`); a forced test's starts where its forcing ends.
  const double free_decay_s = tests.front().release.free_decay_start_s();
  summary["release_time_s"] = free_decay_s;
  if (!note.empty()) summary["start_note"] = note;
  // A failed fit leaves no output file (interfaces.md); standard output still gets its JSON.
  if (common.json_path == "-" || (converged && !common.json_path.empty())) {
    WriteJson(summary, common.json_path);
  }
  if (converged && !output_path.empty()) {
    H5Writer file(output_path);
    file.WriteMeasurement(validation::AsFitted(tests.front().record, result.tests.front()));
    file.WriteScenarioYaml(scenario.yaml_text);
    updating::WriteUpdatingGroup(file, result, algebraic.get());
    file.WriteScalar("/updating", "release_time_s", free_decay_s, "s");
    updating::WriteGlobalSearchGroup(file, search);
    // Where each DATA file was cut: its release in the file's own time (t = 0 of the test).
    Eigen::VectorXd release_s(static_cast<Eigen::Index>(tests.size()));
    std::vector<std::string> how, files;
    for (size_t i = 0; i < tests.size(); ++i) {
      release_s(static_cast<Eigen::Index>(i)) = tests[i].release.free_decay_start_s();
      how.push_back(tests[i].release.how);
      files.push_back(tests[i].path);
    }
    file.WriteVector("/release", "release_time_s", release_s, "s");
    // Where a detected release was before the fit placed it (NaN: not placed).
    Eigen::VectorXd detected_s(release_s.size());
    for (size_t i = 0; i < tests.size(); ++i) {
      detected_s(static_cast<Eigen::Index>(i)) =
          tests[i].release.detected_time_s.value_or(std::nan(""));
    }
    if (detected_s.array().isFinite().any()) {
      file.WriteVector("/release", "detected_release_time_s", detected_s, "s");
    }
    file.WriteStrings("/release", "release", how);
    file.WriteStrings("/release", "file", files);
    file.Commit();
  }
  for (const std::string& warning : result.warnings) {
    std::cerr << "mbid: warning: " << warning << "\n";  // also under --quiet
  }
  if (common.json_path != "-") PrintSummary(result, algebraic.get(), start, search);
  if (!converged) {
    std::cerr << fmt::format("mbid: numerical failure: updating: {}: {}\n",
                             result.termination_name(), result.message);
  }
  return static_cast<int>(converged ? ExitCode::kSuccess : ExitCode::kNumericalFailure);
}

}  // namespace mbid::app
