// `mbid structure`: which degrees of freedom the records support (the paper's sub-problem 4).
// Candidates: the scenario's model, its variants with up to K compliant coordinates rigid, and
// the scenario's alternative descriptions; each fitted by Route 2 and ranked by BIC
// (updating/structure.h, docs/structure.md).
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "mbid/app/commands.h"
#include "mbid/common/error.h"
#include "mbid/common/hdf5_io.h"
#include "mbid/common/json_io.h"
#include "mbid/model/multibody_model.h"
#include "mbid/model/rigid_coordinates.h"
#include "mbid/report/structure_report.h"
#include "mbid/updating/settings.h"
#include "mbid/updating/structure.h"
#include "mbid/validation/loaded_test.h"
#include "mbid/validation/recorded_tests.h"
#include "mbid/validation/release_profile.h"
#include "mbid/validation/scenario.h"
#include "mbid/validation/two_route_update.h"

namespace mbid::app {
using report::CheckReportPaths;
using report::ReportPathsBeside;
using report::StructureRankingToJson;
using report::StructureReportPaths;
using report::StructureTable;
using report::WriteStructureGroup;
using report::WriteStructureReport;
using validation::LoadedTest;
using validation::LoadScenario;
using validation::LoadTests;
using validation::MakeWeightedRecords;
using validation::Scenario;
using validation::SolveAlgebraicRoute;
using validation::StartFromAlgebraicRoute;

namespace {

// Route 2's settings and starts for a model as `mbid update` takes them: Route 1 on the first
// record gives the primary start when admissible and its other sets as the global search's
// further starts.
struct StartedSettings {
  updating::UpdatingSettings settings;
  std::vector<updating::SearchStart> starts;
  std::string start;  // "route1" or "scenario"
};

StartedSettings StartFromRoute1(const model::MechanicalModel& model,
                                const updating::UpdatingSettings& settings,
                                const LoadedTest& first) {
  StartedSettings started{settings, {}, ""};
  std::string note;
  const auto algebraic =
      SolveAlgebraicRoute(model, first.identified, first.record, first.excitation, settings, &note);
  started.starts =
      StartFromAlgebraicRoute(algebraic.get(), &started.settings, &started.start, &note);
  return started;
}

}  // namespace

int RunStructureCommand(const std::string& scenario_path,
                        const std::vector<std::string>& data_paths,
                        std::optional<int> given_max_rigid, int threads,
                        const std::string& output_path, const CommonOptions& common) {
  const Scenario scenario = LoadScenario(scenario_path);
  const auto model = scenario.MakeModel();
  const auto* multibody = dynamic_cast<const model::MultibodyModel*>(model.get());
  if (multibody == nullptr) {
    throw InputError(scenario_path, "model.type", model->type(),
                     "a machine described by bodies and joints (multibody, truck_crane)");
  }
  const std::vector<std::string> compliant = model::CompliantCoordinates(multibody->description());
  // A machine with every coordinate rigid cannot move: at least one stays.
  const int most = static_cast<int>(compliant.size()) -
                   (static_cast<int>(compliant.size()) == multibody->coordinate_count() ? 1 : 0);
  const int max_rigid = given_max_rigid.value_or(std::min(1, most));
  if (max_rigid < 0 || max_rigid > most) {
    throw InputError("command line", "--max-rigid", std::to_string(max_rigid),
                     fmt::format("0 to {} (the compliant coordinates: {}; one must move)", most,
                                 fmt::join(compliant, ", ")));
  }
  if (threads < 0) {
    throw InputError("command line", "--threads", std::to_string(threads), "0 (all cores) or more");
  }
  if (threads == 0) threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));

  // Outputs are checked before the long work: the folder must exist, nothing of the user's is
  // overwritten.
  std::optional<H5Writer> file;
  std::optional<StructureReportPaths> report;
  if (!output_path.empty()) {
    report = ReportPathsBeside(output_path);
    CheckReportPaths(*report);
    file.emplace(output_path);
  }

  const updating::UpdatingSettings& settings = scenario.updating;
  const identification::IdentificationOptions identification_options = scenario.identification;
  std::vector<LoadedTest> tests =
      LoadTests(data_paths, scenario, *model, identification_options, common.import, !common.quiet);
  const std::vector<updating::TestRecord> records = MakeWeightedRecords(tests, settings);

  // The candidates: the full model first (its fit's noise weighs all), then each set of rigid
  // coordinates, then the alternatives.
  std::vector<updating::StructureCandidate> candidates;
  const StartedSettings full = StartFromRoute1(*model, settings, tests.front());
  const std::string& start = full.start;
  candidates.push_back({"full",
                        {},
                        "",
                        std::shared_ptr<const model::MechanicalModel>(model->Clone()),
                        full.settings.options,
                        false});
  for (const std::vector<std::string>& rigid : updating::EnumerateRigidSets(compliant, max_rigid)) {
    // Starts at the full fit's estimates (settings.options: no Route 1 values in it).
    candidates.push_back({fmt::format("rigid {}", fmt::join(rigid, ",")), rigid, "",
                          std::make_shared<const model::MultibodyModel>(
                              model::MakeCoordinatesRigid(*multibody, rigid)),
                          settings.options, true});
  }
  for (size_t i = 0; i < scenario.structure_alternatives.size(); ++i) {
    std::shared_ptr<const model::MechanicalModel> alternative = scenario.MakeAlternativeModel(i);
    updating::UpdatingSettings own;
    try {
      own = scenario.ReadUpdating(*alternative);
    } catch (const InputError& error) {
      // The updating section names the scenario model's parameters; the alternative's are its
      // own: it is fitted with the defaults.
      own = updating::MakeDefaultUpdatingSettings(*alternative, scenario.simulation.integrator);
      if (!common.quiet) {
        std::cerr << fmt::format(
            "mbid: {}: the updating section does not fit it ({}); default "
            "updating settings\n",
            scenario.structure_alternatives[i], error.what());
      }
    }
    // A local fit from its own Route 1 set (the global search is the reference's).
    candidates.push_back({scenario.structure_alternatives[i],
                          {},
                          scenario.structure_alternatives[i],
                          alternative,
                          StartFromRoute1(*alternative, own, tests.front()).settings.options,
                          false});
  }
  if (!common.quiet) {
    std::cerr << fmt::format(
        "mbid: {} candidate structures ({} compliant coordinates, up to {} "
        "rigid), {} records, {} threads; the full model starts from {}\n",
        candidates.size(), compliant.size(), max_rigid, records.size(), threads, start);
  }

  updating::StructureOptions options;
  options.threads = threads;
  // The reference is fitted as `mbid update` fits it: the same starts, the same search.
  options.search = full.settings.global_search;
  options.search.threads = threads;  // the reference's search too (it took every core)
  options.reference_starts = full.starts;
  options.reference_start = full.start;
  options.quiet = common.quiet;
  // Detected releases are placed by the full model's fit, as `mbid update` places them; every
  // candidate is fitted to the placed records.
  // Asked by the reference's search first too, as in TuneModel (release_profile.h).
  options.after_reference = validation::PlaceReleasesEarly(*model, &options.search);
  const updating::StructureRanking ranking = updating::RankStructures(candidates, records, options);
  const updating::UpdateResult& reference = ranking.reference_search.best;
  validation::PlaceReleases(reference, &tests);

  nlohmann::json summary = StructureRankingToJson(ranking, data_paths);
  summary["max_rigid"] = max_rigid;
  summary["start"] = start;
  summary["release"] = nlohmann::json::array();
  for (const LoadedTest& test : tests) {
    nlohmann::json release = test.release.ToJson();
    release["file"] = test.path;
    summary["release"].push_back(release);
  }
  if (!common.json_path.empty()) WriteJson(summary, common.json_path);
  if (file) {
    file->WriteMeasurement(validation::AsFitted(tests.front().record, reference.tests.front()));
    file->WriteScenarioYaml(scenario.yaml_text);
    WriteStructureGroup(*file, ranking);
    WriteStructureReport(ranking, scenario.name, data_paths, *report);
    file->Commit();
  }
  // The full model's fit says what `mbid update` would (also under --quiet).
  for (const std::string& warning : reference.warnings) {
    std::cerr << "mbid: warning: " << warning << "\n";
  }
  if (common.json_path != "-") {
    std::cout << StructureTable(ranking);
    std::cout << fmt::format("{:.1f} s\n", ranking.wall_time_s);
  }
  return 0;
}

}  // namespace mbid::app
