#include "mbid/app/run_cycle.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "mbid/app/gnuplot.h"
#include "mbid/app/identification_settings.h"
#include "mbid/app/json_summaries.h"
#include "mbid/app/record_source.h"
#include "mbid/app/result_writers.h"
#include "mbid/app/run_report.h"
#include "mbid/app/scenario.h"
#include "mbid/common/error.h"
#include "mbid/common/hdf5_io.h"
#include "mbid/common/json_io.h"
#include "mbid/common/output_folder.h"
#include "mbid/identification/identify.h"
#include "mbid/identification/updating/result_io.h"
#include "mbid/identification/updating/settings.h"
#include "run_document.h"
#include "run_test.h"

namespace mbid::app {
namespace {

// A test's `updating` JSON: the best minimum's fit with the global search beside it.
nlohmann::json TestUpdatingJson(const RunTest& test) {
  nlohmann::json json = updating::UpdateResultToJson(test.tuned, test.algebraic.get());
  updating::AddGlobalSearchToJson(test.search, json);
  return json;
}

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

// The tests of the run: the scenario's records, or one test simulated from the model.
std::vector<RunTest> AcquireTests(const Scenario& scenario, const model::MechanicalModel& model,
                                  const simulation::Excitation& excitation,
                                  const Progress& progress, const ImportOverrides& overrides) {
  std::vector<RunTest> tests;
  if (scenario.records.empty()) {
    RunTest test;
    // An HDF5 group name (/updating/tests/<name>): "." or "a/b" would be a path there.
    test.name = SafeFileName(scenario.name, scenario.path, "name");
    test.origin = "simulation";
    test.simulation =
        simulation::Simulate(model, excitation, scenario.simulation, scenario.sensors);
    test.measured = test.simulation->measured;
    test.exact = test.simulation->exact;
    progress.Say(
        fmt::format("simulated the test: {} ({} samples x {} channels, {} CVODES {} steps)",
                    excitation.type_name(), test.measured.samples(), test.measured.channel_count(),
                    test.simulation->statistics.steps,
                    simulation::MethodName(test.simulation->statistics.method)));
    tests.push_back(std::move(test));
    return tests;
  }
  for (const RecordSource& source : scenario.records) {
    LoadedRecord loaded = LoadRecord(source, model, overrides);
    if (loaded.import) {
      progress.Say(fmt::format("test {}: {}: {}", source.name, loaded.origin,
                               DescribeImport(*loaded.import)));
    }
    RunTest test;
    test.name = source.name;
    test.origin = loaded.origin;
    test.measured = std::move(loaded.measured);
    test.exact = std::move(loaded.exact);
    test.import = std::move(loaded.import);
    test.excitation = std::move(loaded.excitation);
    if (test.excitation) {
      progress.Say(fmt::format("test {}: excitation {} from {}", test.name,
                               test.excitation->type_name(), loaded.excitation_origin));
    }
    if (!source.synthetic) {
      test.release = CutRecordAtRelease(&test.measured, test.origin,
                                        OverrideRelease(source.release, overrides),
                                        test.excitation ? *test.excitation : excitation);
      progress.Say(
          fmt::format("test {}: free decay from {:.6g} s of the record ({}); that is "
                      "t = 0 of the test",
                      test.name, test.release->release_time_s, test.release->how));
    }
    progress.Say(fmt::format("test {}: {} ({} samples x {} channels)", test.name, test.origin,
                             test.measured.samples(), test.measured.channel_count()));
    tests.push_back(std::move(test));
  }
  return tests;
}

nlohmann::json ChannelValues(const std::vector<std::string>& channels, const Eigen::VectorXd& v) {
  nlohmann::json object = nlohmann::json::object();
  for (size_t c = 0; c < channels.size(); ++c)
    object[channels[c]] = v[static_cast<Eigen::Index>(c)];
  return object;
}

// One test's results in run.h5 under `root` ("" for the top-level groups of the contract).
void WriteTestGroups(H5Writer& run, const RunTest& test, const std::string& root,
                     double threshold) {
  run.WriteMeasurement(test.measured, root + "/measurement");
  if (test.release) {
    // Where the record was cut: the release in the file's own time, t = 0 of the test.
    run.WriteScalar(root + "/release", "release_time_s", test.release->release_time_s, "s");
    run.WriteStringAttribute(root + "/release", "release", test.release->how);
  }
  identification::WriteModalResult(run, test.identified, root + "/identification");
  updating::WriteUpdatingGroup(run, test.tuned, test.algebraic.get(), root + "/updating");
  updating::WriteGlobalSearchGroup(run, test.search, root + "/updating/search");
  const updating::TestFit& fit = test.tuned.tests.front();
  const std::string validation = root + "/validation";
  run.WriteStringAttribute(validation, "passed", test.passed ? "true" : "false");
  run.WriteStringAttribute(validation, "verdict", test.verdict);
  run.WriteStrings(validation, "reasons", test.reasons);
  run.WriteScalar(validation, "threshold", threshold, "1");
  for (size_t c = 0; c < fit.channels.size(); ++c) {
    const auto column = static_cast<Eigen::Index>(c);
    run.WriteScalar(validation + "/correlation", fit.channels[c], fit.correlation[column], "1");
    run.WriteVector(validation + "/resimulation", fit.channels[c], fit.simulated.values.col(column),
                    fit.simulated.units[c]);
  }
  if (!root.empty()) {
    run.WriteStringAttribute(root, "origin", test.origin);
    if (test.exact) {
      for (int c = 0; c < test.exact->channel_count(); ++c) {
        run.WriteVector(root + "/exact", test.exact->channels[c], test.exact->values.col(c),
                        test.exact->units[c]);
      }
    }
  }
}

nlohmann::json TestValidationJson(const RunTest& test, double threshold) {
  const updating::TestFit& fit = test.tuned.tests.front();
  return {{"correlation", ChannelValues(fit.channels, fit.correlation)},
          {"threshold", threshold},
          {"verdict", test.verdict},
          {"reasons", test.reasons},
          {"passed", test.passed}};
}

std::string VerdictLine(const std::vector<RunTest>& tests, double threshold,
                        const std::string& verdict) {
  std::vector<std::string> parts;
  for (const RunTest& test : tests) {
    const updating::TestFit& fit = test.tuned.tests.front();
    for (size_t c = 0; c < fit.channels.size(); ++c) {
      parts.push_back(fmt::format("K({}{}) = {:.4f}", tests.size() > 1 ? test.name + ", " : "",
                                  fit.channels[c], fit.correlation[static_cast<Eigen::Index>(c)]));
    }
  }
  std::string upper = verdict;
  for (char& c : upper) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return fmt::format("re-simulation vs record: {}; threshold {} -> {}", fmt::join(parts, ", "),
                     threshold, upper);
}

bool IsHdf5File(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::string signature(8, '\0');
  in.read(signature.data(), 8);
  return in && signature == "\x89HDF\r\n\x1a\n";
}

bool IsRunSummary(const fs::path& path) {
  std::ifstream in(path);
  const nlohmann::json summary = nlohmann::json::parse(in, nullptr, false);
  return summary.is_object() && summary.contains("scenario") && summary.contains("validation");
}

bool IsFigure(const fs::directory_entry& entry) {
  std::error_code error;
  return entry.is_regular_file(error) && !entry.is_symlink(error) &&
         entry.path().extension() == ".png";
}

}  // namespace

bool IsRunFolder(const std::string& folder) {
  std::error_code error;
  bool has_run_h5 = false;
  bool has_summary = false;
  for (const auto& entry : fs::directory_iterator(folder, error)) {
    const std::string name = entry.path().filename().string();
    if (entry.is_symlink(error)) return false;
    if (entry.is_directory(error)) {
      // The figures of one test, when the run had several.
      for (const auto& figure : fs::directory_iterator(entry.path(), error)) {
        if (!IsFigure(figure)) return false;
      }
      if (error) return false;
      continue;
    }
    if (!entry.is_regular_file(error)) return false;
    if (name == "run.h5") {
      has_run_h5 = IsHdf5File(entry.path());
    } else if (name == "summary.json") {
      has_summary = IsRunSummary(entry.path());
    } else if (name != "report.md" && name != OutputFolder::kMarkerFile && !IsFigure(entry)) {
      return false;
    }
  }
  if (error) return false;
  return (has_run_h5 && has_summary) || OutputFolder::HasMarker(folder, "run");
}

int RunValidationCycle(const std::string& scenario_path, const std::string& output_dir,
                       const CommonOptions& common) {
  const Progress progress(common.quiet);
  const Scenario scenario = LoadScenario(scenario_path);
  // The name may hold anything YAML allows ("..", "a/b", "$(x)"): it must not choose the place.
  const fs::path final_dir =
      output_dir.empty() ? fs::path("results") / SafeFileName(scenario.name, scenario_path, "name")
                         : fs::path(output_dir);
  progress.Say(fmt::format("scenario {} ({})", scenario.name, scenario_path));
  OutputFolder folder(final_dir, "run", common.overwrite, IsRunFolder);

  const auto model = scenario.MakeModel();
  const model::LinearModel linear = model->Linearize();
  const std::vector<model::Mode> exact_modes = model::CalcModes(linear);
  progress.Say(fmt::format("model {}: {} coordinates, {} exact modes", model->type(),
                           model->coordinate_count(), exact_modes.size()));
  // Recorded tests may each carry their own excitation; the scenario's is needed otherwise.
  const bool every_test_has_its_own =
      !scenario.records.empty() &&
      std::all_of(scenario.records.begin(), scenario.records.end(),
                  [](const RecordSource& r) { return r.excitation.has_value(); });
  const simulation::Excitation& excitation = every_test_has_its_own && !scenario.has_excitation
                                                 ? *scenario.records.front().excitation
                                                 : scenario.RequireExcitation();

  RunSettings settings;
  settings.identification = scenario.ReadIdentification();
  settings.updating = scenario.ReadUpdating(*model);
  settings.updating.options.quiet = common.quiet;
  settings.min_correlation = scenario.validation_min_correlation;

  std::vector<RunTest> tests = AcquireTests(scenario, *model, excitation, progress, common.import);
  const bool several = tests.size() > 1;
  for (RunTest& test : tests) {
    const std::string prefix = several ? "test " + test.name + ": " : "";
    AnalyseTest(test, *model, test.excitation ? *test.excitation : excitation, settings,
                [&](const std::string& message) { progress.Say(prefix + message); });
  }
  std::vector<std::string> verdicts;
  std::vector<std::string> reasons;
  for (const RunTest& test : tests) {
    verdicts.push_back(test.verdict);
    for (const std::string& reason : test.reasons) {
      reasons.push_back(several ? "test " + test.name + ": " + reason : reason);
    }
  }
  const std::string overall = CombineVerdicts(verdicts);
  const bool passed = overall == "passed";
  const double threshold = settings.min_correlation;
  const std::string verdict = VerdictLine(tests, threshold, overall);
  progress.Say(verdict);
  for (const std::string& reason : reasons) {
    // Said even with --quiet: a run that did not pass says why.
    std::cerr << "mbid: " << (overall == "failed" ? "failed" : "inconclusive") << ": " << reason
              << "\n";
  }

  H5Writer run(folder / "run.h5");
  run.WriteScenarioYaml(scenario.yaml_text);
  const RunTest& first = tests.front();
  WriteTestGroups(run, first, "", threshold);
  run.WriteStringAttribute("/validation", "passed", passed ? "true" : "false");
  run.WriteStringAttribute("/validation", "verdict", overall);
  run.WriteStrings("/validation", "reasons", reasons);
  if (first.simulation) {
    WriteTruth(run, *model, *first.simulation);
    WriteSimulationInfo(run, excitation, scenario.simulation, *first.simulation);
  }
  if (!scenario.records.empty()) {
    for (const RunTest& test : tests) WriteTestGroups(run, test, "/tests/" + test.name, threshold);
  }

  // The top level holds the first test (interfaces.md); with several tests the verdict is the
  // worst correlation per channel and passes only if every test does.
  nlohmann::json validation = TestValidationJson(first, threshold);
  validation["passed"] = passed;
  validation["verdict"] = overall;
  validation["reasons"] = reasons;
  nlohmann::json summary{{"scenario", scenario.name}};
  if (first.simulation) {
    summary["simulation"] = {
        {"excitation", excitation.type_name()},
        {"samples", first.measured.samples()},
        {"sample_interval_s", first.measured.sample_interval_s},
        {"channels", first.measured.channels},
        {"integrator", IntegratorStatisticsToJson(first.simulation->statistics)}};
  }
  summary["model"] = LinearModelToJson(linear, exact_modes);
  summary["identification"] = identification::ModalResultToJson(first.identified);
  if (first.release) summary["release"] = first.release->ToJson();
  summary["updating"] = updating::UpdateResultToJson(first.tuned, first.algebraic.get());
  updating::AddGlobalSearchToJson(first.search, summary["updating"]);
  if (!scenario.records.empty()) {
    nlohmann::json list = nlohmann::json::array();
    for (const RunTest& test : tests) {
      list.push_back({{"name", test.name},
                      {"origin", test.origin},
                      {"samples", test.measured.samples()},
                      {"sample_interval_s", test.measured.sample_interval_s},
                      {"channels", test.measured.channels},
                      {"identification", identification::ModalResultToJson(test.identified)},
                      {"updating", TestUpdatingJson(test)},
                      {"validation", TestValidationJson(test, threshold)}});
      if (test.import) list.back()["import"] = ImportReportToJson(*test.import);
      if (test.release) list.back()["release"] = test.release->ToJson();
      const updating::TestFit& fit = test.tuned.tests.front();
      for (size_t c = 0; c < fit.channels.size(); ++c) {
        const double k = fit.correlation[static_cast<Eigen::Index>(c)];
        auto& worst = validation["correlation"][fit.channels[c]];
        if (k < worst.get<double>()) worst = k;
      }
    }
    summary["tests"] = list;
  }
  if (several) {
    std::vector<const updating::UpdateResult*> results;
    for (const RunTest& test : tests) results.push_back(&test.tuned);
    nlohmann::json spread = nlohmann::json::object();
    for (const auto& [name, value] : CalcRelativeSpread(results)) {
      spread[name] = value;
      run.WriteScalar("/validation/spread", name, value, "1");
    }
    summary["spread"] = spread;
  }
  summary["validation"] = validation;

  const int figure_count =
      WriteRunReport((folder / "").string(), scenario, *model, exact_modes, tests, verdict,
                     [&](const std::string& m) { progress.Say(m); });
  WriteJson(summary, (folder / "summary.json").string());
  run.Commit();
  folder.Commit();
  progress.Say(fmt::format("wrote {}/ (run.h5, summary.json, report.md, {} figures)",
                           final_dir.string(), figure_count));
  return 0;
}

}  // namespace mbid::app
