#include "run_document.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <filesystem>
#include <fstream>
#include <optional>

#include "mbid/report/gnuplot.h"
#include "mbid/report/run_report.h"

namespace mbid::report {
using validation::RecordSource;
using validation::RunTest;
using validation::Scenario;

namespace {

namespace fs = std::filesystem;

// A drawn figure's file into its section's list (nothing when no figure was drawn).
void Add(std::vector<std::string>& list, const std::string& prefix, const std::string& file) {
  if (!file.empty()) list.push_back(prefix + file);
}

}  // namespace

std::string TestFolderPrefix(const std::string& test_name, size_t test_count) {
  return test_count > 1 ? test_name + "/" : "";
}

TestFigureFiles DrawIdentificationFigures(const std::string& folder, const std::string& prefix,
                                          const RunTest& test) {
  TestFigureFiles figures;
  const Measurement* exact = test.exact ? &*test.exact : nullptr;
  const std::string exact_label = test.simulation
                                      ? "exact model output (no sensor errors)"
                                      : "noise-free record (before the noise was added)";
  if (test.recorded && test.release) {
    // The whole record as read, the release where the test was cut marked on it.
    const ReleaseMark release{test.release->release_time_s, test.release->how};
    for (int c = 0; c < test.recorded->channel_count(); ++c) {
      Add(figures.record, prefix,
          DrawRecordFigure(folder, *test.recorded, nullptr, "", c, &release));
    }
  } else {
    for (int c = 0; c < test.measured.channel_count(); ++c) {
      Add(figures.record, prefix, DrawRecordFigure(folder, test.measured, exact, exact_label, c));
    }
  }
  Add(figures.identification, prefix, DrawSpectrumFigure(folder, test.identified));
  for (int c = 0; c < static_cast<int>(test.identified.channels.size()); ++c) {
    Add(figures.identification, prefix,
        DrawReconstructionFigure(folder, test.measured, test.identified, c));
  }
  Add(figures.identification, prefix, DrawStabilizationFigure(folder, test.identified));
  for (const std::string& file : DrawBackboneFigures(folder, test.identified)) {
    Add(figures.backbone, prefix, file);
  }
  return figures;
}

namespace {

void DrawUpdatingFigures(const std::string& folder, const std::string& prefix, const RunTest& test,
                         TestFigureFiles& figures) {
  const updating::TestFit& fit = test.tuned.tests.front();
  for (int c = 0; c < static_cast<int>(fit.channels.size()); ++c) {
    Add(figures.updating, prefix, DrawResimulationFigure(folder, test.measured, fit, c));
  }
  Add(figures.updating, prefix, DrawConvergenceFigure(folder, test.tuned));
}

void Embed(std::ostream& out, const std::vector<std::string>& figures) {
  for (const std::string& figure : figures) out << "![" << figure << "](" << figure << ")\n\n";
}

// The modes the record is known to contain: the model's (simulated) or the synthetic record's.
std::vector<ReferenceMode> KnownModes(const Scenario& scenario, const RunTest& test,
                                      const std::vector<model::Mode>& exact_modes,
                                      std::string* label) {
  std::vector<ReferenceMode> known;
  if (test.simulation) {
    *label = "model's exact";
    for (const model::Mode& mode : exact_modes) {
      known.push_back({mode.frequency_hz(), mode.decay_rate_per_s(), {}});
    }
    return known;
  }
  for (const RecordSource& source : scenario.records) {
    if (source.name != test.name || !source.synthetic) continue;
    *label = "record's true";
    for (const simulation::ModalComponent& mode : source.synthetic->modes) {
      known.push_back({mode.frequency_hz, mode.decay_rate_per_s, mode.amplitude});
    }
  }
  return known;
}

}  // namespace

int WriteRunReport(const std::string& folder, const Scenario& scenario,
                   const model::MechanicalModel& model, const std::vector<model::Mode>& exact_modes,
                   const std::vector<RunTest>& tests, const std::string& verdict,
                   const std::function<void(const std::string&)>& say, EarlyRunFigures* early,
                   FigureBatch& batch) {
  const bool several = tests.size() > 1;
  const bool draw = GnuplotAvailable();
  if (!draw) say("gnuplot with pngcairo not found: the report has no figures");
  int figure_count = 0;

  std::ofstream report(fs::path(folder) / "report.md");
  report << "# mbid run: " << scenario.name << "\n\n";
  report << fmt::format("Scenario `{}`; model `{}`; excitation `{}`; ", scenario.path, model.type(),
                        scenario.RequireExcitation().type_name());
  report << (scenario.records.empty() ? std::string("the test is simulated from the model.\n\n")
                                      : fmt::format("{} recorded test(s).\n\n", tests.size()));
  const std::string heading = several ? "###" : "##";
  for (const RunTest& test : tests) {
    TestFigureFiles figures;
    if (draw) {
      const std::string prefix = TestFolderPrefix(test.name, tests.size());
      const fs::path test_folder = fs::path(folder) / prefix;
      fs::create_directories(test_folder);
      std::optional<TestFigureFiles> drawn = early ? early->Take(test.name) : std::nullopt;
      figures =
          drawn ? *drawn : DrawIdentificationFigures((test_folder / "").string(), prefix, test);
      DrawUpdatingFigures((test_folder / "").string(), prefix, test, figures);
      figure_count += static_cast<int>(figures.record.size() + figures.identification.size() +
                                       figures.backbone.size() + figures.updating.size());
    }
    if (several) report << "## Test " << test.name << "\n\n";
    report << heading << " The test record\n\n";
    report << fmt::format("{}: {} samples at {} Hz on channels {}.\n\n", test.origin,
                          test.measured.samples(), 1.0 / test.measured.sample_interval_s,
                          fmt::join(test.measured.channels, ", "));
    if (test.recorded && test.release && test.release->detected_time_s) {
      // The record figure was drawn at identification, before the fit placed the release.
      report << fmt::format(
          "The free decay starts at {:.6g} s of the record (detected at {:.6g} s{}, placed by the "
          "fit, +- {:.2g} ms): that instant is t = 0 of the test.\n\n",
          test.release->release_time_s, *test.release->detected_time_s,
          draw ? ", the dashed line on the record figure" : "", 1e3 * *test.release->std_s);
    } else if (test.recorded && test.release) {
      report << fmt::format(
          "The free decay starts at {:.6g} s of the record ({}): the record is cut there and that "
          "instant is t = 0 of the test{}.\n\n",
          test.release->release_time_s, test.release->how,
          draw ? " (the dashed line on the record figure)" : "");
    }
    Embed(report, figures.record);
    std::string label;
    const std::vector<ReferenceMode> known = KnownModes(scenario, test, exact_modes, &label);
    report << heading << " Identified modes (the paper's Table 1)"
           << (known.empty() ? "" : ", with the " + label + " modes") << "\n\n";
    report << ModalTableMarkdown(test.identified, known.empty() ? nullptr : &known, label) << "\n";
    for (const std::string& warning : test.identified.warnings) report << "> " << warning << "\n\n";
    Embed(report, figures.identification);
    const std::string backbones = BackboneMarkdown(test.identified);
    if (!backbones.empty()) {
      report << heading << " Backbones: frequency and damping ratio against amplitude\n\n"
             << backbones << "\n";
      Embed(report, figures.backbone);
    }
    report << heading << " Tuned joint parameters (the paper's Table 2)\n\n";
    report << "Start: " << test.start_note << ". "
           << TunedParametersMarkdown(test.tuned, model,
                                      test.simulation ? "model (truth of the simulated test)"
                                                      : "scenario (design values)")
           << "\n";
    if (test.algebraic) report << AlgebraicSetsMarkdown(*test.algebraic) << "\n";
    Embed(report, figures.updating);
  }
  if (several) {
    std::vector<std::string> names;
    std::vector<const updating::UpdateResult*> results;
    for (const RunTest& test : tests) {
      names.push_back(test.name);
      results.push_back(&test.tuned);
    }
    report << "## All tests (the paper's Table 2 with its spread row)\n\n"
           << TestsTableMarkdown(names, results) << "\n";
  }
  report << "## Verdict\n\n**" << verdict << "**\n";
  batch.Start();
  return figure_count;
}

}  // namespace mbid::report
