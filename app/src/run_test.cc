#include "run_test.h"

#include <fmt/format.h>

#include <cmath>

#include "mbid/app/identification_settings.h"
#include "mbid/app/updating_glue.h"
#include "mbid/common/error.h"
#include "mbid/identification/identify.h"
#include "mbid/identification/updating/result_io.h"

namespace mbid::app {

void AnalyseTest(RunTest& test, const model::MechanicalModel& model,
                 const simulation::Excitation& excitation, const RunSettings& settings,
                 const std::function<void(const std::string&)>& say) {
  test.identified = identification::Identify(
      test.measured, FreeDecayOptions(settings.identification, excitation), test.origin);
  say(fmt::format("identified {} modes ({}), K = {:.3f}", test.identified.modes.size(),
                  test.identified.method, test.identified.correlation.minCoeff()));

  // Route 1 (eqs. 6-8) when there are enough identified poles (SolveAlgebraicRoute); Route 2
  // starts from its chosen set, else from the scenario's values.
  updating::UpdatingSettings updating = settings.updating;
  test.start_note = "the scenario's values";
  std::string note;
  test.algebraic =
      SolveAlgebraicRoute(model, test.identified, test.measured, excitation, updating, &note);
  if (test.algebraic && updating::ApplyAlgebraicStart(*test.algebraic, updating.options, &note)) {
    test.start_note = "Route 1 (eq. 7)";
  }
  say(fmt::format("Route 1 (eq. 7): {}{}",
                  test.algebraic ? test.algebraic->status_name() : "skipped",
                  note.empty() ? "" : "; " + note));
  updating::TestRecord record =
      updating::MakeTestRecord(test.name, test.measured, excitation, updating);
  WeighByIdentifiedNoise(test.identified, record);
  say(fmt::format("Route 2 (Ceres, output error) from {}", test.start_note));
  test.tuned = updating::UpdateModel(model, {record}, updating.options);
  if (test.algebraic) updating::MarkAlgebraicAmbiguity(*test.algebraic, test.tuned);
  say(fmt::format("updating: {} after {} iterations, cost {:.3g} -> {:.3g}",
                  test.tuned.termination_name(), test.tuned.iterations, test.tuned.initial_cost,
                  test.tuned.final_cost));
  if (test.tuned.termination != updating::UpdateResult::Termination::kConverged) {
    throw NumericalError("updating of test " + test.name,
                         test.tuned.termination_name() + ": " + test.tuned.message);
  }
  for (const std::string& line : updating::DescribeBaseline(test.tuned.tests.front())) say(line);
  const updating::TestFit& fit = test.tuned.tests.front();
  const Eigen::VectorXd& k = fit.correlation;
  test.reasons.clear();
  for (Eigen::Index c = 0; c < k.size(); ++c) {
    if (!(k(c) >= settings.min_correlation)) {
      test.reasons.push_back(fmt::format("K({}) = {:.4f} is below the threshold {}",
                                         fit.channels[static_cast<size_t>(c)], k(c),
                                         settings.min_correlation));
    }
  }
  const bool correlates = k.size() > 0 && test.reasons.empty();
  for (const std::string& reason : test.identified.reasons) {
    test.reasons.push_back("identification unreliable: " + reason);
  }
  test.verdict = !correlates ? "failed" : test.identified.reliable ? "passed" : "inconclusive";
  test.passed = test.verdict == "passed";
}

std::string CombineVerdicts(const std::vector<std::string>& verdicts) {
  std::string combined = "passed";
  for (const std::string& verdict : verdicts) {
    if (verdict == "failed") return "failed";
    if (verdict == "inconclusive") combined = verdict;
  }
  return combined;
}

}  // namespace mbid::app
