#include "mbid/app/run_cycle.h"

#include <fmt/format.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "mbid/app/gnuplot.h"
#include "mbid/app/identification_settings.h"
#include "mbid/app/json_summaries.h"
#include "mbid/app/result_writers.h"
#include "mbid/app/run_report.h"
#include "mbid/app/scenario.h"
#include "mbid/app/updating_glue.h"
#include "mbid/common/error.h"
#include "mbid/common/hdf5_io.h"
#include "mbid/common/json_io.h"
#include "mbid/identification/identify.h"
#include "mbid/identification/updating/characteristic.h"
#include "mbid/identification/updating/output_error.h"
#include "mbid/identification/updating/result_io.h"
#include "mbid/identification/updating/settings.h"

namespace mbid::app {
namespace {

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

// A results folder built under a temporary name and renamed over `final` on Commit().
class StagingFolder {
 public:
  explicit StagingFolder(fs::path final_path) : final_(std::move(final_path)) {
    const fs::path parent = final_.has_parent_path() ? final_.parent_path() : fs::path(".");
    std::error_code error;
    fs::create_directories(parent, error);
    if (error || !fs::is_directory(parent)) {
      throw InputError(final_.string(), "", "cannot create the parent folder",
                       "a writable location for the results");
    }
    staging_ = parent / fmt::format(".{}.tmp-{}", final_.filename().string(), ::getpid());
    fs::remove_all(staging_);
    fs::create_directories(staging_);
  }
  ~StagingFolder() {
    std::error_code ignored;
    if (!committed_) fs::remove_all(staging_, ignored);
  }
  fs::path operator/(const std::string& name) const { return staging_ / name; }
  void Commit() {
    fs::remove_all(final_);
    fs::rename(staging_, final_);
    committed_ = true;
  }

 private:
  fs::path final_;
  fs::path staging_;
  bool committed_ = false;
};

}  // namespace

int RunValidationCycle(const std::string& scenario_path, const std::string& output_dir,
                       const CommonOptions& common) {
  const Progress progress(common.quiet);
  const Scenario scenario = LoadScenario(scenario_path);
  const fs::path final_dir =
      output_dir.empty() ? fs::path("results") / scenario.name : fs::path(output_dir);
  progress.Say(fmt::format("scenario {} ({})", scenario.name, scenario_path));
  StagingFolder folder(final_dir);

  const auto model = scenario.MakeModel();
  const model::LinearModel linear = model->Linearize();
  const std::vector<model::Mode> exact_modes = model::CalcModes(linear);
  progress.Say(fmt::format("model {}: {} coordinates, {} exact modes", model->type(),
                           model->coordinate_count(), exact_modes.size()));

  const simulation::Excitation& excitation = scenario.RequireExcitation();
  const simulation::SimulationResult test =
      simulation::Simulate(*model, excitation, scenario.simulation, scenario.sensors);
  progress.Say(fmt::format("simulated the test: {} ({} samples x {} channels, {} CVODES steps)",
                           excitation.type_name(), test.measured.samples(),
                           test.measured.channel_count(), test.statistics.steps));

  H5Writer run(folder / "run.h5");
  run.WriteMeasurement(test.measured);
  run.WriteScenarioYaml(scenario.yaml_text);
  WriteTruth(run, *model, test);
  WriteSimulationInfo(run, excitation, scenario.simulation, test);

  const identification::IdentificationOptions identify_options =
      scenario.root.Has("identification")
          ? ReadIdentificationSettings(scenario.root.Child("identification"))
          : identification::IdentificationOptions();
  const identification::ModalResult identified =
      identification::Identify(test.measured, identify_options, scenario_path);
  identification::WriteModalResult(run, identified);
  progress.Say(fmt::format("identified {} modes ({}), K = {:.3f}", identified.modes.size(),
                           identified.method, identified.correlation.minCoeff()));

  // Route 1 (eqs. 6-8) from the identified poles when there is one per coordinate; Route 2 (Ceres,
  // time domain) from its chosen set, else from the scenario's values; then the re-simulation.
  updating::UpdatingSettings settings =
      scenario.root.Has("updating")
          ? updating::ReadUpdatingSettings(scenario.root.Child("updating"), *model,
                                           scenario.simulation.integrator)
          : updating::MakeDefaultUpdatingSettings(*model, scenario.simulation.integrator);
  settings.options.quiet = common.quiet;
  std::string start_note = "the scenario's values";
  std::string note;
  const auto algebraic =
      SolveAlgebraicRoute(*model, identified, test.measured, excitation, settings, &note);
  if (algebraic && updating::ApplyAlgebraicStart(*algebraic, settings.options, &note)) {
    start_note = "Route 1 (eq. 7)";
  }
  progress.Say(fmt::format("Route 1 (eq. 7): {}{}",
                           algebraic ? algebraic->status_name() : "skipped",
                           note.empty() ? "" : "; " + note));
  updating::TestRecord record =
      updating::MakeTestRecord(scenario.name, test.measured, excitation, settings);
  WeighByIdentifiedNoise(identified, record);
  progress.Say(fmt::format("Route 2 (Ceres, output error) from {}", start_note));
  updating::UpdateResult tuned = updating::UpdateModel(*model, {record}, settings.options);
  if (algebraic) updating::MarkAlgebraicAmbiguity(*algebraic, tuned);
  updating::WriteUpdatingGroup(run, tuned, algebraic.get());
  progress.Say(fmt::format("updating: {} after {} iterations, cost {:.3g} -> {:.3g}",
                           tuned.termination_name(), tuned.iterations, tuned.initial_cost,
                           tuned.final_cost));
  if (tuned.termination != updating::UpdateResult::Termination::kConverged) {
    throw NumericalError("updating", tuned.termination_name() + ": " + tuned.message);
  }

  // The verdict: the re-simulation with the tuned values against the record.
  const updating::TestFit& fit = tuned.tests.front();
  const double threshold = scenario.validation_min_correlation;
  nlohmann::json validation_correlation;
  bool passed = true;
  for (size_t c = 0; c < fit.channels.size(); ++c) {
    const double k = fit.correlation[static_cast<Eigen::Index>(c)];
    validation_correlation[fit.channels[c]] = k;
    passed = passed && k >= threshold;
  }
  run.WriteStringAttribute("/validation", "passed", passed ? "true" : "false");
  run.WriteScalar("/validation", "threshold", threshold, "1");
  for (size_t c = 0; c < fit.channels.size(); ++c) {
    run.WriteScalar("/validation/correlation", fit.channels[c],
                    fit.correlation[static_cast<Eigen::Index>(c)], "1");
    run.WriteVector("/validation/resimulation", fit.channels[c],
                    fit.simulated.values.col(static_cast<Eigen::Index>(c)), fit.simulated.units[c]);
  }
  const std::string verdict = fmt::format(
      "re-simulation vs record: {}; threshold {} -> {}",
      fmt::join(
          [&] {
            std::vector<std::string> parts;
            for (size_t c = 0; c < fit.channels.size(); ++c) {
              parts.push_back(fmt::format("K({}) = {:.4f}", fit.channels[c],
                                          fit.correlation[static_cast<Eigen::Index>(c)]));
            }
            return parts;
          }(),
          ", "),
      threshold, passed ? "PASSED" : "FAILED");
  progress.Say(verdict);
  nlohmann::json summary{
      {"scenario", scenario.name},
      {"simulation",
       {{"excitation", excitation.type_name()},
        {"samples", test.measured.samples()},
        {"sample_interval_s", test.measured.sample_interval_s},
        {"channels", test.measured.channels},
        {"integrator", IntegratorStatisticsToJson(test.statistics)}}},
      {"model", LinearModelToJson(linear, exact_modes)},
      {"identification", identification::ModalResultToJson(identified)},
      {"updating", updating::UpdateResultToJson(tuned, algebraic.get())},
      {"validation",
       {{"correlation", validation_correlation}, {"threshold", threshold}, {"passed", passed}}}};

  std::vector<std::string> record_figures, identification_figures, updating_figures;
  if (GnuplotAvailable()) {
    const std::string dir = (folder / "").string();
    for (int c = 0; c < test.measured.channel_count(); ++c) {
      record_figures.push_back(DrawRecordFigure(dir, test.measured, &test.exact, c));
    }
    identification_figures.push_back(DrawSpectrumFigure(dir, identified));
    for (int c = 0; c < static_cast<int>(identified.channels.size()); ++c) {
      identification_figures.push_back(DrawReconstructionFigure(dir, test.measured, identified, c));
    }
    const std::string stabilization = DrawStabilizationFigure(dir, identified);
    if (!stabilization.empty()) identification_figures.push_back(stabilization);
    for (int c = 0; c < static_cast<int>(fit.channels.size()); ++c) {
      updating_figures.push_back(DrawResimulationFigure(dir, test.measured, fit, c));
    }
    updating_figures.push_back(DrawConvergenceFigure(dir, tuned));
    progress.Say(fmt::format(
        "drew {} figures",
        record_figures.size() + identification_figures.size() + updating_figures.size()));
  } else {
    progress.Say("gnuplot with pngcairo not found: the report has no figures");
  }
  const size_t figure_count =
      record_figures.size() + identification_figures.size() + updating_figures.size();

  {
    std::ofstream report(folder / "report.md");
    report << "# mbid run: " << scenario.name << "\n\n";
    report << fmt::format(
        "Scenario `{}`; model `{}`; excitation `{}`; {} samples at {} Hz on "
        "channels {}.\n\n",
        scenario_path, model->type(), excitation.type_name(), test.measured.samples(),
        1.0 / test.measured.sample_interval_s, fmt::join(test.measured.channels, ", "));
    report << "## The test record\n\n";
    for (const std::string& figure : record_figures) {
      report << "![" << figure << "](" << figure << ")\n\n";
    }
    report << "## Identified modes (the paper's Table 1), with the model's exact modes\n\n";
    report << ModalTableMarkdown(identified, &exact_modes) << "\n";
    for (const std::string& warning : identified.warnings) report << "> " << warning << "\n\n";
    for (const std::string& figure : identification_figures) {
      report << "![" << figure << "](" << figure << ")\n\n";
    }
    report << "## Tuned joint parameters (the paper's Table 2)\n\n";
    report << "Start: " << start_note << ". " << TunedParametersMarkdown(tuned, *model) << "\n";
    if (algebraic) report << AlgebraicSetsMarkdown(*algebraic) << "\n";
    for (const std::string& figure : updating_figures) {
      report << "![" << figure << "](" << figure << ")\n\n";
    }
    report << "## Verdict\n\n**" << verdict << "**\n";
  }
  WriteJson(summary, (folder / "summary.json").string());
  run.Commit();
  folder.Commit();
  progress.Say(fmt::format("wrote {}/ (run.h5, summary.json, report.md, {} figures)",
                           final_dir.string(), figure_count));
  return 0;
}

}  // namespace mbid::app
