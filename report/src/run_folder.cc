#include "mbid/report/run_folder.h"

#include <fmt/format.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "mbid/common/hdf5_io.h"
#include "mbid/common/json_io.h"
#include "mbid/common/output_folder.h"
#include "mbid/identification/modal_result.h"
#include "mbid/report/gnuplot.h"
#include "mbid/report/run_report.h"
#include "mbid/updating/result_io.h"
#include "mbid/validation/json_summaries.h"
#include "mbid/validation/release_profile.h"
#include "mbid/validation/result_writers.h"
#include "run_document.h"

namespace mbid::report {
namespace {

namespace fs = std::filesystem;
using validation::RunTest;

// Where a test's free decay starts (the contract's `release_time_s`): a record's release in the
// file's own time, or where the identification found it in a simulated test (after a forcing).
double ReleaseTime(const RunTest& test) {
  return test.release ? test.release->free_decay_start_s() : test.identified.release_time_s;
}

// A test's `updating` JSON: the best minimum's fit with the global search beside it.
nlohmann::json TestUpdatingJson(const RunTest& test) {
  nlohmann::json json = updating::UpdateResultToJson(test.tuned, test.algebraic.get());
  updating::AddGlobalSearchToJson(test.search, json);
  json["release_time_s"] = ReleaseTime(test);
  return json;
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
  run.WriteMeasurement(validation::AsFitted(test.measured, test.tuned.tests.front()),
                       root + "/measurement");
  if (test.release) {
    // Where the record was cut: the release in the file's own time, t = 0 of the test.
    run.WriteScalar(root + "/release", "release_time_s", test.release->free_decay_start_s(), "s");
    run.WriteStringAttribute(root + "/release", "release", test.release->how);
    if (test.release->detected_time_s) {
      run.WriteScalar(root + "/release", "detected_release_time_s", *test.release->detected_time_s,
                      "s");
      run.WriteScalar(root + "/release", "release_std_s", *test.release->std_s, "s");
    }
  }
  identification::WriteModalResult(run, test.identified, root + "/identification");
  updating::WriteUpdatingGroup(run, test.tuned, test.algebraic.get(), root + "/updating");
  run.WriteScalar(root + "/updating", "release_time_s", ReleaseTime(test), "s");
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
    if (column < fit.simulated.values.cols()) {  // none where the re-simulation failed
      run.WriteVector(validation + "/resimulation", fit.channels[c],
                      fit.simulated.values.col(column), fit.simulated.units[c]);
    }
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

int WriteRunFolder(const validation::CycleResult& cycle, const validation::Scenario& scenario,
                   const std::string& folder_path,
                   const std::function<void(const std::string&)>& say, EarlyRunFigures* early) {
  const fs::path folder(folder_path);
  const std::vector<RunTest>& tests = cycle.tests;
  const double threshold = cycle.min_correlation;
  const bool passed = cycle.verdict == "passed";
  const std::string& overall = cycle.verdict;
  const std::vector<std::string>& reasons = cycle.reasons;
  const simulation::Excitation& excitation = cycle.excitation;
  const bool several = tests.size() > 1;
  // The figures are drawn while run.h5 and summary.json are written.
  FigureBatch figures;
  const int figure_count =
      WriteRunReport((folder / "").string(), scenario, *cycle.model, cycle.exact_modes, tests,
                     cycle.verdict_line, say, early, figures);
  H5Writer run(folder / "run.h5");
  run.WriteScenarioYaml(scenario.yaml_text);
  const RunTest& first = tests.front();
  WriteTestGroups(run, first, "", threshold);
  run.WriteStringAttribute("/validation", "passed", passed ? "true" : "false");
  run.WriteStringAttribute("/validation", "verdict", overall);
  run.WriteStrings("/validation", "reasons", reasons);
  if (first.simulation) {
    validation::WriteTruth(run, *cycle.model, *first.simulation);
    validation::WriteSimulationInfo(run, excitation, scenario.simulation, *first.simulation);
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
        {"integrator", validation::IntegratorStatisticsToJson(first.simulation->statistics)}};
  }
  summary["model"] = validation::LinearModelToJson(cycle.linear, cycle.exact_modes);
  summary["identification"] = identification::ModalResultToJson(first.identified);
  if (first.release) summary["release"] = first.release->ToJson();
  summary["updating"] = TestUpdatingJson(first);
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
      if (test.import) list.back()["import"] = validation::ImportReportToJson(*test.import);
      if (test.release) list.back()["release"] = test.release->ToJson();
    }
    summary["tests"] = list;
    for (const auto& [channel, k] : validation::CalcWorstCorrelation(tests)) {
      validation["correlation"][channel] = k;
    }
  }
  if (several) {
    std::vector<const updating::UpdateResult*> results;
    for (const RunTest& test : tests) results.push_back(&test.tuned);
    nlohmann::json spread = nlohmann::json::object();
    for (const auto& [name, value] : CalcRelativeSpread(results)) {
      spread[name] = std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(nullptr);
      run.WriteScalar("/validation/spread", name, value, "1");
    }
    summary["spread"] = spread;
  }
  summary["validation"] = validation;

  WriteJson(summary, (folder / "summary.json").string());
  figures.Finish();
  if (GnuplotAvailable()) say(fmt::format("drew {} figures", figure_count));
  run.Commit();
  return figure_count;
}

}  // namespace mbid::report
