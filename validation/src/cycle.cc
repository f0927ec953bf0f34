#include "mbid/validation/cycle.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>

#include "mbid/common/output_folder.h"
#include "mbid/common/stop.h"
#include "mbid/validation/identification_settings.h"
#include "mbid/validation/record_source.h"
#include "mbid/validation/release_cut.h"

namespace mbid::validation {
namespace {

using Say = std::function<void(const std::string&)>;

// The tests of the run: the scenario's records, or one test simulated from the model.
std::vector<RunTest> AcquireTests(const Scenario& scenario, const model::MechanicalModel& model,
                                  const simulation::Excitation& excitation, const Say& say,
                                  const ImportOverrides& overrides) {
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
    test.simulation_warnings = simulation::FindStartFarFromRest(model, excitation);
    say(fmt::format("simulated the test: {} ({} samples x {} channels, {} CVODES {} steps)",
                    excitation.type_name(), test.measured.samples(), test.measured.channel_count(),
                    test.simulation->statistics.steps,
                    simulation::MethodName(test.simulation->statistics.method)));
    tests.push_back(std::move(test));
    return tests;
  }
  for (const RecordSource& source : scenario.records) {
    LoadedRecord loaded = LoadRecord(source, model, overrides);
    if (loaded.import) {
      say(fmt::format("test {}: {}: {}", source.name, loaded.origin,
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
      say(fmt::format("test {}: excitation {} from {}", test.name, test.excitation->type_name(),
                      loaded.excitation_origin));
    }
    if (!source.synthetic) {
      Measurement recorded = test.measured;
      test.release = CutRecordAtRelease(&test.measured, test.origin,
                                        OverrideRelease(source.release, overrides),
                                        test.excitation ? *test.excitation : excitation);
      if (test.release->how == "detected" || test.release->how == "given") {
        test.recorded = std::move(recorded);
      }
      say(
          fmt::format("test {}: free decay from {:.6g} s of the record ({}); that is "
                      "t = 0 of the test",
                      test.name, test.release->release_time_s, test.release->how));
      if (test.release->clipped_until_s) {
        say(fmt::format("test {}: {}", test.name, test.release->DescribeClipped()));
      }
      if (test.release->next_excitation_s) {
        say(fmt::format("test {}: {}", test.name, test.release->next_excitation));
      }
    }
    say(fmt::format("test {}: {} ({} samples x {} channels)", test.name, test.origin,
                    test.measured.samples(), test.measured.channel_count()));
    tests.push_back(std::move(test));
  }
  return tests;
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

}  // namespace

std::map<std::string, double> CalcWorstCorrelation(const std::vector<RunTest>& tests) {
  std::map<std::string, double> worst;
  for (const RunTest& test : tests) {
    const updating::TestFit& fit = test.tuned.tests.front();
    for (size_t c = 0; c < fit.channels.size(); ++c) {
      const double k = fit.correlation[static_cast<Eigen::Index>(c)];
      const auto found = worst.find(fit.channels[c]);
      if (found == worst.end() || k < found->second) worst[fit.channels[c]] = k;
    }
  }
  return worst;
}

CycleResult RunCycle(const Scenario& scenario, const CycleOptions& options) {
  const Say say = options.say ? options.say : [](const std::string&) {};
  CycleResult result;
  std::shared_ptr<const model::MechanicalModel> model = scenario.MakeModel();
  result.model = model;
  result.linear = model->Linearize();
  result.exact_modes = model::CalcModes(result.linear);
  say(fmt::format("model {}: {} coordinates, {} exact modes", model->type(),
                  model->coordinate_count(), result.exact_modes.size()));
  // Recorded tests may each carry their own excitation; the scenario's is needed otherwise.
  const bool every_test_has_its_own =
      !scenario.records.empty() &&
      std::all_of(scenario.records.begin(), scenario.records.end(),
                  [](const RecordSource& r) { return r.excitation.has_value(); });
  result.excitation = every_test_has_its_own && !scenario.has_excitation
                          ? *scenario.records.front().excitation
                          : scenario.RequireExcitation();

  RunSettings settings;
  settings.identification = scenario.identification;
  settings.updating = scenario.updating;
  if (options.profile) settings.updating.profile.enabled = true;
  settings.updating.options.quiet = options.quiet;
  settings.min_correlation = scenario.validation_min_correlation;
  result.min_correlation = settings.min_correlation;

  result.tests = AcquireTests(scenario, *model, result.excitation, say, options.import);
  const bool several = result.tests.size() > 1;
  std::vector<std::string> verdicts;
  for (RunTest& test : result.tests) {
    ThrowIfStopRequested();  // between tests too, where no simulation runs
    const std::string prefix = several ? "test " + test.name + ": " : "";
    const size_t test_count = result.tests.size();
    AnalyseTest(
        test, *model, test.excitation ? *test.excitation : result.excitation, settings,
        [&](const std::string& message) { say(prefix + message); },
        [&](const RunTest& identified) {
          if (options.identified) options.identified(identified, test_count);
        });
    verdicts.push_back(test.verdict);
    for (const std::string& reason : test.reasons) {
      result.reasons.push_back(prefix + reason);
    }
  }
  ThrowIfStopRequested();  // a stopped test's failures are no verdict
  result.verdict = CombineVerdicts(verdicts);
  result.verdict_line = VerdictLine(result.tests, result.min_correlation, result.verdict);
  return result;
}

std::vector<std::string> CollectWarnings(const CycleResult& cycle, bool with_import) {
  std::vector<std::string> seen, warnings;
  for (const RunTest& test : cycle.tests) {
    const std::string prefix = cycle.tests.size() > 1 ? "test " + test.name + ": " : "";
    std::vector<std::string> lines = test.simulation_warnings;
    if (test.import && with_import) {
      lines.insert(lines.end(), test.import->warnings.begin(), test.import->warnings.end());
    }
    lines.insert(lines.end(), test.identified.warnings.begin(), test.identified.warnings.end());
    lines.insert(lines.end(), test.tuned.warnings.begin(), test.tuned.warnings.end());
    for (const std::string& line : lines) {
      if (std::find(seen.begin(), seen.end(), line) != seen.end()) continue;
      seen.push_back(line);
      warnings.push_back(prefix + line);
    }
  }
  return warnings;
}

}  // namespace mbid::validation
