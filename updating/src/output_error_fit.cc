#include "output_error_fit.h"

#include <ceres/ceres.h>

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <mutex>

#include "fit_unknowns.h"
#include "mbid/common/eigen_decompositions.h"
#include "mbid/common/error.h"
#include "mbid/common/stop.h"
#include "nan.h"
#include "prepared_test.h"
#include "statistics.h"
#include "test_evaluator.h"

namespace mbid::updating::internal {
namespace {

class ProgressCallback final : public ceres::IterationCallback {
 public:
  ProgressCallback(std::vector<IterationRecord>& history, int stage, std::string label, bool quiet)
      : history_(history), stage_(stage), label_(std::move(label)), quiet_(quiet) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& summary) override {
    IterationRecord record;
    record.iteration = summary.iteration;
    record.cost = summary.cost;
    record.step_norm = summary.step_norm;
    record.gradient_max_norm = summary.gradient_max_norm;
    record.trust_region_radius = summary.trust_region_radius;
    record.successful = summary.step_is_successful;
    record.cumulative_time_s = summary.cumulative_time_in_seconds;
    record.stage = stage_;
    history_.push_back(record);
    if (!quiet_) {
      std::fprintf(stderr, "mbid: Route 2 (%s) iteration %3d  cost %.6e  step %.3e%s\n",
                   label_.c_str(), summary.iteration, summary.cost, summary.step_norm,
                   summary.iteration > 0 && !summary.step_is_successful ? " (rejected)" : "");
    }
    return StopRequested() ? ceres::SOLVER_ABORT : ceres::SOLVER_CONTINUE;
  }

 private:
  std::vector<IterationRecord>& history_;
  int stage_;
  std::string label_;
  bool quiet_;
};

UpdateResult::Termination ToTermination(ceres::TerminationType type) {
  switch (type) {
    case ceres::CONVERGENCE:
      return UpdateResult::Termination::kConverged;
    case ceres::NO_CONVERGENCE:
      return UpdateResult::Termination::kNoConvergence;
    default:
      return UpdateResult::Termination::kFailure;
  }
}

// The problem one Fit solves: the unknowns, the prepared tests with their evaluators, Ceres'
// parameter vector (in its coordinates) and problem with the bounds. Not copyable: the
// evaluators point at the unknowns and tests, Ceres at x.
struct FitProblem {
  FitProblem(const model::MechanicalModel& model, const std::vector<TestRecord>& tests,
             const UpdateOptions& options)
      : unknowns(ResolveUnknowns(model, tests, options)),
        count(static_cast<int>(unknowns.size())),
        problem(MakeProblemOptions()) {
    for (size_t t = 0; t < tests.size(); ++t) {
      prepared.push_back(PrepareTest(model, tests[t], static_cast<int>(t), unknowns, options));
    }
    for (const PreparedTest& test : prepared) {
      evaluators.push_back(std::make_unique<TestEvaluator>(model, unknowns, test, options, work));
    }
    x.resize(count);
    for (int k = 0; k < count; ++k)
      x[k] = unknowns[static_cast<size_t>(k)].ToInternal(unknowns[static_cast<size_t>(k)].initial);
    x_initial = x;
    for (auto& evaluator : evaluators) {
      problem.AddResidualBlock(new TestCost(*evaluator, count), nullptr, x.data());
    }
    for (int k = 0; k < count; ++k) {
      const Unknown& unknown = unknowns[static_cast<size_t>(k)];
      problem.SetParameterLowerBound(x.data(), k, unknown.ToInternal(unknown.lower));
      problem.SetParameterUpperBound(x.data(), k, unknown.ToInternal(unknown.upper));
    }
  }
  FitProblem(const FitProblem&) = delete;
  FitProblem& operator=(const FitProblem&) = delete;

  static ceres::Problem::Options MakeProblemOptions() {
    ceres::Problem::Options options;
    options.cost_function_ownership = ceres::TAKE_OWNERSHIP;
    return options;
  }

  const std::vector<Unknown> unknowns;
  const int count;
  std::vector<PreparedTest> prepared;
  Work work;
  std::vector<std::unique_ptr<TestEvaluator>> evaluators;
  Eigen::VectorXd x, x_initial;
  ceres::Problem problem;
};

ceres::Solver::Options MakeSolverOptions(const UpdateOptions& options, int tests) {
  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::DENSE_QR;
  solver.max_num_iterations = options.max_iterations;
  solver.function_tolerance = options.function_tolerance;
  solver.gradient_tolerance = options.gradient_tolerance;
  solver.parameter_tolerance = options.parameter_tolerance;
  solver.num_threads = std::min<int>(options.threads, tests);
  solver.logging_type = ceres::SILENT;
  solver.minimizer_progress_to_stdout = false;
  // No projected line search at the bounds: it asks for the gradient (a sensitivity run) at
  // every trial point. Steps are projected onto the box instead.
  solver.max_num_line_search_step_size_iterations = 0;
  solver.initial_trust_region_radius = options.initial_trust_region_radius;
  return solver;
}

// Noise from the residual at this fit: sigma_c^2 = SS_c / (N_c - B - P N_c / N), the
// parameters' degrees of freedom shared out by sample count, B the channel's baseline terms.
void EstimateNoise(FitProblem& fit) {
  long total = 0;
  for (const PreparedTest& test : fit.prepared)
    total += test.test->record.samples() * test.test->record.channel_count();
  for (size_t t = 0; t < fit.prepared.size(); ++t) {
    PreparedTest& test = fit.prepared[t];
    const Measurement simulated = fit.evaluators[t]->Simulate(fit.x);
    const Measurement& record = test.test->record;
    for (int c = 0; c < record.channel_count(); ++c) {
      if (test.sigma_given[static_cast<size_t>(c)]) continue;
      Eigen::VectorXd difference = simulated.values.col(c) - record.values.col(c);
      test.baseline->Project(difference.data(), 1);
      const double squares = difference.squaredNorm();
      const double samples = record.samples();
      const double dof = std::max(
          1.0, samples - test.baseline->terms() - fit.count * samples / static_cast<double>(total));
      test.sigma[c] = std::max(std::sqrt(squares / dof), 1e-300);
    }
  }
  // New weights: the cached residuals no longer apply.
  for (auto& evaluator : fit.evaluators) evaluator->Invalidate();
}

// Ceres on the problem; where some channel's noise is estimated, once more in the weights of
// the noise the first solution leaves (refit_after_noise_estimate). Fills the result's
// iterations, history, termination, message and costs; returns the number of passes.
int Solve(FitProblem& fit, const UpdateOptions& options, int tests, int first_stage,
          const std::string& stage_label, UpdateResult* result) {
  const ceres::Solver::Options base = MakeSolverOptions(options, tests);
  bool any_estimated = false;
  for (const PreparedTest& test : fit.prepared) {
    for (bool given : test.sigma_given) any_estimated = any_estimated || !given;
  }
  const int passes = any_estimated && options.refit_after_noise_estimate ? 2 : 1;
  ceres::Solver::Summary summary;
  double first_initial_cost = kNaN;
  std::vector<IterationRecord> all_history;
  for (int pass = 1; pass <= passes; ++pass) {
    std::vector<IterationRecord> history;
    ProgressCallback progress(history, first_stage + pass - 1,
                              stage_label + (pass > 1 ? " refit" : " fit"), options.quiet);
    ceres::Solver::Options solver = base;
    solver.callbacks = {&progress};
    ceres::Solve(solver, &fit.problem, &summary);
    ThrowIfStopRequested();
    if (pass == 1) first_initial_cost = summary.initial_cost;
    result->iterations += summary.num_successful_steps + summary.num_unsuccessful_steps;
    all_history.insert(all_history.end(), history.begin(), history.end());
    if (!any_estimated || summary.termination_type == ceres::FAILURE ||
        summary.termination_type == ceres::USER_FAILURE) {
      break;
    }
    EstimateNoise(fit);
  }
  result->history = all_history;
  result->termination = ToTermination(summary.termination_type);
  result->message = summary.message;
  {
    std::lock_guard<std::mutex> lock(fit.work.mutex);
    if (!fit.work.last_error.empty() &&
        result->termination != UpdateResult::Termination::kConverged) {
      result->message += "; last simulation failure: " + fit.work.last_error;
    }
  }
  result->final_cost = summary.final_cost;
  result->initial_cost = first_initial_cost;
  return passes;
}

// The covariance of the unknowns (Ceres' coordinates) from the Jacobian at the estimate, with
// the rank and singular values in `result`; rows of unknowns in the null space are NaN.
Eigen::MatrixXd CalcCovariance(FitProblem& fit, const ceres::CRSMatrix& crs,
                               const UpdateOptions& options, UpdateResult* result) {
  const int count = fit.count;
  Eigen::MatrixXd covariance = Eigen::MatrixXd::Constant(count, count, kNaN);
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(crs.num_rows, crs.num_cols);
  for (int r = 0; r < crs.num_rows; ++r) {
    for (int i = crs.rows[static_cast<size_t>(r)]; i < crs.rows[static_cast<size_t>(r) + 1]; ++i) {
      J(r, crs.cols[static_cast<size_t>(i)]) = crs.values[static_cast<size_t>(i)];
    }
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(J, Eigen::ComputeThinV);
  result->singular_values = svd.singularValues();
  const double largest = result->singular_values.size() > 0 ? result->singular_values[0] : 0.0;
  result->rank = 0;
  std::vector<bool> in_null_space(static_cast<size_t>(count), false);
  for (int i = 0; i < result->singular_values.size(); ++i) {
    if (result->singular_values[i] > options.rank_tolerance * largest) {
      ++result->rank;
      continue;
    }
    for (int k = 0; k < count; ++k) {
      if (std::abs(svd.matrixV()(k, i)) > 0.1) in_null_space[static_cast<size_t>(k)] = true;
    }
  }
  ceres::Covariance::Options covariance_options;
  covariance_options.algorithm_type = ceres::DENSE_SVD;
  // A rank-deficient Jacobian: the pseudo-inverse without the null space, whose parameters
  // are marked undefined below, gives the others their std (with the null space fixed).
  covariance_options.null_space_rank = count - result->rank;
  ceres::Covariance ceres_covariance(covariance_options);
  const std::vector<std::pair<const double*, const double*>> blocks{{fit.x.data(), fit.x.data()}};
  if (ceres_covariance.Compute(blocks, &fit.problem)) {
    ceres_covariance.GetCovarianceBlock(fit.x.data(), fit.x.data(), covariance.data());
    covariance = covariance.transpose().eval();  // Ceres fills row-major
  }
  for (int k = 0; k < count; ++k) {
    if (in_null_space[static_cast<size_t>(k)]) covariance.row(k).setConstant(kNaN);
  }
  return covariance;
}

Eigen::MatrixXd CalcCorrelation(const Eigen::MatrixXd& covariance) {
  const Eigen::Index count = covariance.rows();
  Eigen::MatrixXd correlation = Eigen::MatrixXd::Constant(count, count, kNaN);
  for (Eigen::Index i = 0; i < count; ++i) {
    for (Eigen::Index j = 0; j < count; ++j) {
      const double denominator = std::sqrt(covariance(i, i) * covariance(j, j));
      if (denominator > 0 && std::isfinite(denominator)) {
        correlation(i, j) = covariance(i, j) / denominator;
      }
    }
  }
  return correlation;
}

// The largest relative uncertainty of the tests' sample intervals (Measurement's).
double TimeBaseUncertainty(const std::vector<TestRecord>& tests) {
  double u = 0;
  for (const TestRecord& test : tests) u = std::max(u, test.record.sample_interval_uncertainty);
  return u;
}

// How a model parameter scales with the record's time base: a stiffness c_ as omega^2 (2), a
// damping d_ as the decay rate (1); 0 for any other unknown.
double TimeScaleExponent(const Unknown& unknown) {
  const std::string& name = unknown.name;
  if (unknown.kind != Unknown::Kind::kModel || name.size() <= 2 || name[1] != '_') return 0;
  return name[0] == 'c' ? 2.0 : name[0] == 'd' ? 1.0 : 0.0;
}

// Each unknown's estimate with its std, whether it is determined and at a bound; warnings for
// the undetermined ones and for strongly correlated pairs.
void AddEstimates(const FitProblem& fit, const std::vector<TestRecord>& tests,
                  const UpdateOptions& options, UpdateResult* result) {
  const int count = fit.count;
  const Eigen::VectorXd& x = fit.x;
  const double time_base = TimeBaseUncertainty(tests);
  for (int k = 0; k < count; ++k) {
    const Unknown& unknown = fit.unknowns[static_cast<size_t>(k)];
    ParameterEstimate estimate;
    estimate.name = unknown.name;
    estimate.units = unknown.units;
    estimate.test = unknown.test >= 0 ? tests[static_cast<size_t>(unknown.test)].name : "";
    estimate.log_scale = unknown.log_scale;
    estimate.value = unknown.ToValue(x[k]);
    estimate.initial = unknown.initial;
    estimate.lower = unknown.lower;
    estimate.upper = unknown.upper;
    const double variance = result->covariance(k, k);
    if (variance >= 0 && std::isfinite(variance)) {
      const double std_internal = std::sqrt(variance);
      estimate.std = unknown.log_scale ? estimate.value * std_internal : std_internal;
      estimate.relative_std =
          unknown.log_scale
              ? std_internal
              : std_internal / std::max({std::abs(estimate.value), unknown.scale, 1e-6});
    }
    // A record's time base known to +-u (a sample interval printed to few digits) scales the
    // frequencies by up to u: a stiffness (omega^2) by 2 u, a damping (decay) by u, as a uniform
    // error's std u / sqrt(3).
    const double time_scale = TimeScaleExponent(unknown) * time_base;
    if (time_scale > 0 && std::isfinite(estimate.relative_std)) {
      estimate.relative_std = std::hypot(estimate.relative_std, time_scale / std::sqrt(3.0));
      estimate.std = estimate.relative_std * std::abs(estimate.value);
    }
    estimate.determined = estimate.relative_std <= options.undetermined_relative_std;
    const double x_lower = unknown.ToInternal(unknown.lower);
    const double x_upper = unknown.ToInternal(unknown.upper);
    const double margin = 1e-6 * std::max(1.0, std::abs(x[k]));
    estimate.at_bound = x[k] - x_lower <= margin || x_upper - x[k] <= margin;
    if (!estimate.determined) result->undetermined.push_back(estimate.name);
    if (estimate.at_bound) {
      result->warnings.push_back(estimate.name + " ends at a bound (" +
                                 FormatValue(estimate.value) + " " + estimate.units + ")");
    }
    result->parameters.push_back(estimate);
  }
  if (!result->undetermined.empty()) {
    std::string list;
    for (const std::string& name : result->undetermined) {
      list += (list.empty() ? "" : ", ") + name;
    }
    result->warnings.push_back("the records leave undetermined: " + list + " (rank " +
                               std::to_string(result->rank) + " of " + std::to_string(count) + ")");
  }
  for (int i = 0; i < count; ++i) {
    for (int j = i + 1; j < count; ++j) {
      if (std::abs(result->correlation(i, j)) > kCombinationCorrelation) {
        result->warnings.push_back(fit.unknowns[static_cast<size_t>(i)].name + " and " +
                                   fit.unknowns[static_cast<size_t>(j)].name + " are correlated " +
                                   FormatValue(result->correlation(i, j)));
      }
    }
  }
}

// The tuned model re-simulated against each record.
void AddTestFits(FitProblem& fit, const std::vector<Eigen::MatrixXd>& regressions,
                 UpdateResult* result) {
  for (size_t t = 0; t < fit.prepared.size(); ++t) {
    const PreparedTest& test = fit.prepared[t];
    const Measurement& record = test.test->record;
    TestFit test_fit;
    test_fit.name = test.test->name;
    test_fit.channels = record.channels;
    test_fit.noise_std = test.sigma;
    for (bool given : test.sigma_given) test_fit.noise_estimated.push_back(!given);
    // NaN until the re-simulation gives them: every reader finds one entry per channel (a failed
    // re-simulation left them empty, and `mbid update` read past their end: SIGSEGV).
    test_fit.residual_rms = Eigen::VectorXd::Constant(record.channel_count(), NAN);
    test_fit.correlation = Eigen::VectorXd::Constant(record.channel_count(), NAN);
    try {
      test_fit.simulated = fit.evaluators[t]->Simulate(fit.x);
      if (test.baseline->terms() > 0) {
        AddBaseline(test, regressions[t], result->covariance, test_fit);
      }
      test_fit.residual_rms.resize(record.channel_count());
      test_fit.correlation.resize(record.channel_count());
      for (int c = 0; c < record.channel_count(); ++c) {
        const Eigen::VectorXd difference = test_fit.simulated.values.col(c) - record.values.col(c);
        test_fit.residual_rms[c] = std::sqrt(difference.squaredNorm() / record.samples());
        test_fit.correlation[c] =
            CalcPearson(record.values.col(c), test_fit.simulated.values.col(c));
      }
    } catch (const std::exception& e) {
      result->warnings.push_back(test_fit.name + ": re-simulation failed: " + e.what());
    }
    result->tests.push_back(test_fit);
  }
}

// The initial cost in the final weights (the noise estimate changed them after pass 1), at
// the first stage's start. Copies keep the buffer Ceres points to.
double CalcInitialCost(FitProblem& fit, const std::vector<double>* report_start) {
  const Eigen::VectorXd estimate = fit.x;
  fit.x = fit.x_initial;
  if (report_start != nullptr) {
    for (int k = 0; k < fit.count; ++k) {
      fit.x[k] =
          fit.unknowns[static_cast<size_t>(k)].ToInternal((*report_start)[static_cast<size_t>(k)]);
    }
  }
  double cost = 0;
  const double initial_cost =
      fit.problem.Evaluate(ceres::Problem::EvaluateOptions(), &cost, nullptr, nullptr, nullptr)
          ? cost
          : kNaN;
  fit.x = estimate;
  return initial_cost;
}

}  // namespace

double CalcStartCost(const model::MechanicalModel& model, const std::vector<TestRecord>& tests,
                     const UpdateOptions& options) {
  FitProblem fit(model, tests, options);
  double cost = 0;
  // No Jacobian asked: the evaluators simulate without sensitivities.
  if (!fit.problem.Evaluate(ceres::Problem::EvaluateOptions(), &cost, nullptr, nullptr, nullptr)) {
    throw NumericalError("updating", "no cost at the start: " + fit.work.last_error);
  }
  return cost;
}

std::vector<Eigen::MatrixXd> CalcCovarianceAt(const model::MechanicalModel& model,
                                              const std::vector<TestRecord>& tests,
                                              const UpdateOptions& options,
                                              const std::vector<Eigen::VectorXd>& points) {
  FitProblem fit(model, tests, options);
  std::vector<Eigen::MatrixXd> covariances;
  for (const Eigen::VectorXd& point : points) {
    fit.x = point;
    ceres::CRSMatrix crs;
    UpdateResult scratch;
    if (fit.problem.Evaluate(ceres::Problem::EvaluateOptions(), nullptr, nullptr, nullptr, &crs)) {
      covariances.push_back(CalcCovariance(fit, crs, options, &scratch));
    } else {
      covariances.push_back(Eigen::MatrixXd::Constant(fit.count, fit.count, kNaN));
    }
  }
  return covariances;
}

UpdateResult Fit(const model::MechanicalModel& model, const std::vector<TestRecord>& tests,
                 const UpdateOptions& options, int first_stage, const std::string& stage_label,
                 const std::vector<double>* report_start) {
  const auto start_time = std::chrono::steady_clock::now();
  FitProblem fit(model, tests, options);
  UpdateResult result;
  result.jacobian =
      options.jacobian == UpdateOptions::Jacobian::kSensitivities ? "sensitivities" : "numeric";
  const int passes =
      Solve(fit, options, static_cast<int>(tests.size()), first_stage, stage_label, &result);

  // Jacobian at the estimate (cached by the evaluators) for the covariance and the rank.
  std::vector<double> residuals;
  ceres::CRSMatrix crs;
  ceres::Problem::EvaluateOptions evaluate;
  const bool have_jacobian = fit.problem.Evaluate(evaluate, nullptr, &residuals, nullptr, &crs);
  // How each test's baseline moves with the unknowns, from the Jacobians just evaluated at x.
  std::vector<Eigen::MatrixXd> regressions;
  for (auto& evaluator : fit.evaluators) {
    regressions.push_back(evaluator->CalcBaselineRegression(fit.x));
  }
  if (have_jacobian) {
    result.covariance = CalcCovariance(fit, crs, options, &result);
  } else {
    result.covariance = Eigen::MatrixXd::Constant(fit.count, fit.count, kNaN);
    result.warnings.push_back("no Jacobian at the estimate: " + fit.work.last_error);
  }
  result.correlation = CalcCorrelation(result.covariance);
  AddEstimates(fit, tests, options, &result);
  AddTestFits(fit, regressions, &result);
  if (passes > 1 || report_start != nullptr)
    result.initial_cost = CalcInitialCost(fit, report_start);
  result.simulations = fit.work.simulations;
  result.sensitivity_simulations = fit.work.sensitivity_simulations;
  result.rhs_evaluations = fit.work.rhs_evaluations;
  result.wall_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_time).count();
  return result;
}

}  // namespace mbid::updating::internal
