// UpdateModel: the options, the continuation over growing windows of the records, and the
// credibility of the result. One fit is in output_error_fit.cc; the unknowns, the prepared
// records and the per-record residuals in fit_unknowns.h, prepared_test.h and test_evaluator.h.
#include "mbid/updating/output_error.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
#include <string>

#include "fit_unknowns.h"
#include "mbid/common/error.h"
#include "mbid/updating/credibility.h"
#include "output_error_fit.h"

namespace mbid::updating {
namespace {

using internal::Fit;
using internal::FormatValue;
using internal::ResolveUnknowns;
using internal::StartNuisanceAt;
using internal::Unknown;

}  // namespace

bool UpdateOptions::IsValid(std::string* why) const {
  auto fail = [why](const std::string& reason) {
    if (why != nullptr) *why = reason;
    return false;
  };
  std::string inner;
  if (!integrator.IsValid(&inner)) return fail("integrator: " + inner);
  if (!sensitivity.IsValid(&inner)) return fail("sensitivity: " + inner);
  if (!(numeric_step > 0 && numeric_step < 1)) {
    return fail("numeric_step: " + FormatValue(numeric_step) + "; expected a value in (0, 1)");
  }
  if (max_iterations < 1) {
    return fail("max_iterations: " + std::to_string(max_iterations) + "; expected >= 1");
  }
  if (!(function_tolerance > 0) || !(gradient_tolerance > 0) || !(parameter_tolerance > 0)) {
    return fail("function, gradient and parameter tolerances must be > 0");
  }
  if (!(undetermined_relative_std > 0)) {
    return fail("undetermined_relative_std: " + FormatValue(undetermined_relative_std) +
                "; expected > 0");
  }
  if (!(max_chi_square_per_dof > 1)) {
    return fail("max_chi_square_per_dof must be > 1 (1 is a fit at the noise)");
  }
  if (whiteness_lags < 1) return fail("whiteness_lags must be >= 1");
  if (!(rank_tolerance > 0 && rank_tolerance < 1)) {
    return fail("rank_tolerance: " + FormatValue(rank_tolerance) + "; expected a value in (0, 1)");
  }
  if (threads < 1) return fail("threads: " + std::to_string(threads) + "; expected >= 1");
  if (!(initial_trust_region_radius > 0) || !std::isfinite(initial_trust_region_radius)) {
    return fail("initial_trust_region_radius: " + FormatValue(initial_trust_region_radius) +
                "; expected a finite value > 0");
  }
  double previous = 0;
  for (double fraction : continuation_fractions) {
    if (!(fraction > previous && fraction < 1)) {
      return fail("continuation_fractions: " + FormatValue(fraction) +
                  "; expected ascending fractions in (0, 1)");
    }
    previous = fraction;
  }
  return true;
}

std::string UpdateResult::termination_name() const {
  switch (termination) {
    case Termination::kConverged:
      return "converged";
    case Termination::kNoConvergence:
      return "no_convergence";
    case Termination::kFailure:
      return "failure";
  }
  return "failure";
}

const ParameterEstimate& UpdateResult::Find(const std::string& name) const {
  for (const ParameterEstimate& estimate : parameters) {
    if (estimate.name == name) return estimate;
  }
  throw std::out_of_range("UpdateResult::Find: no parameter '" + name + "'");
}

void SetInterval(ParameterEstimate& p, double std_inflation) {
  const double relative = p.relative_std * std_inflation;
  if (!std::isfinite(relative)) return;
  if (p.log_scale) {
    p.interval_lower = p.value * std::exp(-2 * relative);
    p.interval_upper = p.value * std::exp(2 * relative);
  } else {
    p.interval_lower = p.value - 2 * p.std * std_inflation;
    p.interval_upper = p.value + 2 * p.std * std_inflation;
  }
}

void ApplyEstimates(const UpdateResult& result, model::MechanicalModel& model) {
  for (const ParameterEstimate& estimate : result.parameters) {
    if (estimate.test.empty()) model.SetParameter(estimate.name, estimate.value);
  }
}

namespace {

// UpdateModel before its credibility check.
UpdateResult FitStages(const model::MechanicalModel& model, const std::vector<TestRecord>& tests,
                       const UpdateOptions& options) {
  const auto start_time = std::chrono::steady_clock::now();
  std::string why;
  if (!options.IsValid(&why)) {
    throw InputError("updating", "options", why, "valid updating options (docs/scenarios.md)");
  }
  if (tests.empty()) {
    throw InputError("updating", "records", "no test record", "at least one record");
  }
  if (options.continuation_fractions.empty()) {
    return Fit(model, tests, options, 1, "update", nullptr);
  }
  // Continuation: the starts and bounds made explicit once, so that every stage keeps the
  // original bounds while its start moves.
  const std::vector<Unknown> unknowns = ResolveUnknowns(model, tests, options);
  std::vector<double> original_start;
  for (const Unknown& unknown : unknowns) original_start.push_back(unknown.initial);
  UpdateOptions staged = options;
  staged.continuation_fractions.clear();
  staged.parameters.clear();
  for (const Unknown& unknown : unknowns) {
    if (unknown.kind != Unknown::Kind::kModel) continue;
    staged.parameters.push_back(
        {unknown.name, unknown.initial, unknown.lower, unknown.upper, unknown.log_scale});
  }
  std::vector<TestRecord> current = tests;
  std::vector<IterationRecord> history;
  int iterations = 0;
  long simulations = 0, sensitivity_simulations = 0, rhs_evaluations = 0;
  int stage = 1;
  for (double fraction : options.continuation_fractions) {
    std::vector<TestRecord> window = current;
    for (TestRecord& test : window) {
      const int samples = std::max(test.fit_drift ? 3 : 2,
                                   static_cast<int>(std::ceil(fraction * test.record.samples())));
      test.record.values = test.record.values.topRows(samples).eval();
    }
    std::ostringstream label;
    label << "window " << std::lround(100 * fraction) << "%";
    const UpdateResult part = Fit(model, window, staged, stage, label.str(), nullptr);
    history.insert(history.end(), part.history.begin(), part.history.end());
    iterations += part.iterations;
    simulations += part.simulations;
    sensitivity_simulations += part.sensitivity_simulations;
    rhs_evaluations += part.rhs_evaluations;
    stage = (part.history.empty() ? stage : part.history.back().stage) + 1;
    if (part.termination == UpdateResult::Termination::kFailure) continue;
    for (ParameterSetting& setting : staged.parameters) {
      setting.initial = std::clamp(part.Find(setting.name).value, setting.lower, setting.upper);
    }
    StartNuisanceAt(part, current);
  }
  UpdateResult result = Fit(model, current, staged, stage, "update", &original_start);
  history.insert(history.end(), result.history.begin(), result.history.end());
  result.history = history;
  result.iterations += iterations;
  result.simulations += simulations;
  result.sensitivity_simulations += sensitivity_simulations;
  result.rhs_evaluations += rhs_evaluations;
  for (size_t k = 0; k < result.parameters.size(); ++k) {
    result.parameters[k].initial = original_start[k];
  }
  result.wall_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_time).count();
  return result;
}

}  // namespace

UpdateResult UpdateModel(const model::MechanicalModel& model, const std::vector<TestRecord>& tests,
                         const UpdateOptions& options) {
  UpdateResult result = FitStages(model, tests, options);
  AssessCredibility(result, tests, options);
  return result;
}

std::vector<ParameterSetting> ResolveParameterSettings(const model::MechanicalModel& model,
                                                       const UpdateOptions& options) {
  std::vector<ParameterSetting> settings;
  for (const Unknown& unknown : ResolveUnknowns(model, {}, options)) {
    settings.push_back(
        {unknown.name, unknown.initial, unknown.lower, unknown.upper, unknown.log_scale});
  }
  return settings;
}

}  // namespace mbid::updating
