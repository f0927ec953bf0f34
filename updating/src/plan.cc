#include "mbid/updating/plan.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <exception>
#include <set>
#include <thread>

#include "mbid/common/eigen_decompositions.h"
#include "mbid/common/error.h"
#include "mbid/updating/credibility.h"
#include "plan_internal.h"

namespace mbid::updating {

namespace internal {

std::unique_ptr<model::MechanicalModel> MakeCandidateModel(
    const model::MechanicalModel& model, const PlanCandidate& candidate,
    const std::vector<std::pair<std::string, double>>& values) {
  std::unique_ptr<model::MechanicalModel> copy =
      candidate.model ? candidate.model->Clone() : model.Clone();
  for (const auto& [name, value] : values) {
    try {
      copy->SetParameter(name, value);
    } catch (const InputError& e) {
      throw InputError(candidate.name, "model", e.what(),
                       "a model with the tuned parameters of the scenario's");
    }
  }
  return copy;
}

}  // namespace internal

double CalcLogDetWithRidge(const Eigen::MatrixXd& fisher, double ridge, double* added) {
  const Eigen::Index n = fisher.rows();
  const double mean_diagonal = n > 0 ? fisher.diagonal().mean() : 0.0;
  const double r = ridge * mean_diagonal;
  if (added != nullptr) *added = r;
  if (n == 0) return 0.0;
  if (!(mean_diagonal > 0)) return -std::numeric_limits<double>::infinity();
  // Eigenvalues rather than a Cholesky factor: F may be singular to round-off, and its
  // eigenvalues below zero by round-off count as zero.
  const Eigen::VectorXd lambda =
      Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(fisher, Eigen::EigenvaluesOnly).eigenvalues();
  double sum = 0;
  for (Eigen::Index i = 0; i < n; ++i) sum += std::log(std::max(lambda[i], 0.0) + r);
  return sum;
}

namespace {

// One sensitivity run: a test on its model.
struct Job {
  const model::MechanicalModel* model = nullptr;  // this job's own copy
  const TestDesign* test = nullptr;
  FisherInformation result;
  std::exception_ptr error;
};

void RunJobs(std::vector<Job>& jobs, const std::vector<std::string>& parameters,
             const PlanOptions& options) {
  std::atomic<size_t> next{0};
  auto work = [&]() {
    for (size_t i = next++; i < jobs.size(); i = next++) {
      Job& job = jobs[i];
      try {
        job.result = CalcFisherInformation(*job.model, *job.test, parameters, options.sensitivity);
      } catch (const NumericalError& e) {
        job.error =
            std::make_exception_ptr(NumericalError(e.stage(), job.test->name + ": " + e.reason()));
      } catch (...) {
        job.error = std::current_exception();
      }
    }
  };
  const int threads = std::max(1, std::min<int>(options.threads, static_cast<int>(jobs.size())));
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(work);
  work();
  for (std::thread& thread : pool) thread.join();
  for (const Job& job : jobs) {
    if (job.error) std::rethrow_exception(job.error);
  }
}

}  // namespace

TestPlan PlanNextTest(const model::MechanicalModel& model, const std::vector<TestDesign>& recorded,
                      const std::vector<PlanCandidate>& candidates, const PlanOptions& options) {
  const auto start_time = std::chrono::steady_clock::now();
  if (candidates.empty()) {
    throw InputError("plan", "candidates", "no candidate test", "at least one candidate");
  }
  TestPlan plan;
  plan.parameters = options.parameters;
  if (plan.parameters.empty()) {
    for (const model::Parameter& parameter : model.parameters()) {
      plan.parameters.push_back(parameter.name);
    }
  }
  const Eigen::Index n = static_cast<Eigen::Index>(plan.parameters.size());
  plan.values.resize(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    plan.values[k] = model.GetParameter(plan.parameters[static_cast<size_t>(k)]);
  }
  // Every test on a model of its own: simulations change a model's internal state (loads,
  // caches), so tests in parallel must not share one. A candidate's own model gets the plan's
  // values of the tuned parameters.
  std::vector<std::unique_ptr<model::MechanicalModel>> models;
  std::vector<Job> jobs;
  for (const TestDesign& test : recorded) {
    models.push_back(model.Clone());
    jobs.push_back({models.back().get(), &test, {}, nullptr});
  }
  std::vector<std::pair<std::string, double>> values;
  for (Eigen::Index k = 0; k < n; ++k) {
    values.emplace_back(plan.parameters[static_cast<size_t>(k)], plan.values[k]);
  }
  for (const PlanCandidate& candidate : candidates) {
    // The plan's own model already carries the values.
    models.push_back(candidate.model ? internal::MakeCandidateModel(model, candidate, values)
                                     : model.Clone());
    jobs.push_back({models.back().get(), &candidate.test, {}, nullptr});
  }
  RunJobs(jobs, plan.parameters, options);

  plan.recorded_tests = static_cast<int>(recorded.size());
  plan.recorded_fisher = Eigen::MatrixXd::Zero(n, n);
  for (size_t i = 0; i < recorded.size(); ++i) plan.recorded_fisher += jobs[i].result.matrix;
  plan.current_relative_std =
      CalcExpectedUncertainty(plan.recorded_fisher, options.rank_tolerance).relative_std;
  if (!recorded.empty()) {
    plan.recorded_score = CalcLogDetWithRidge(plan.recorded_fisher, options.ridge);
  }
  for (size_t i = 0; i < candidates.size(); ++i) {
    const FisherInformation& information = jobs[recorded.size() + i].result;
    CandidateScore score;
    score.name = candidates[i].name;
    score.statistics = information.statistics;
    // A candidate whose channels do not see a parameter's modes (a roll deflected, recorded
    // without a lateral sensor) still has Fisher information on it, from the model's nonlinear
    // coupling: a trial's plan promised c_roll to 2 % and ranked the test second; run, it found
    // no mode at all. That information is no fit's to use: its rows and columns are left out.
    score.fisher = information.matrix;
    const TestDesign& test = candidates[i].test;
    const std::set<std::string> channels(test.sensors.channels.begin(),
                                         test.sensors.channels.end());
    for (const UnseenParameter& found :
         FindUnseenParameters(*models[recorded.size() + i], channels, plan.parameters)) {
      const Eigen::Index k = std::find(plan.parameters.begin(), plan.parameters.end(), found.name) -
                             plan.parameters.begin();
      score.fisher.row(k).setZero();
      score.fisher.col(k).setZero();
      score.unseen.push_back(found.name);
    }
    if (!(information.largest_swing_to_noise >= 1)) {
      score.moves_nothing = true;
      score.fisher.setZero();
    }
    const Eigen::MatrixXd total = plan.recorded_fisher + score.fisher;
    score.score = CalcLogDetWithRidge(total, options.ridge, &score.ridge);
    if (!recorded.empty()) {
      // The recorded tests' log det with the same ridge: the difference is the candidate's.
      const Eigen::VectorXd lambda = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(
                                         plan.recorded_fisher, Eigen::EigenvaluesOnly)
                                         .eigenvalues();
      double recorded_log_det = 0;
      for (Eigen::Index k = 0; k < n; ++k) {
        recorded_log_det += std::log(std::max(lambda[k], 0.0) + score.ridge);
      }
      score.gain = score.score - recorded_log_det;
    }
    const ExpectedUncertainty expected = CalcExpectedUncertainty(total, options.rank_tolerance);
    score.relative_std = expected.relative_std;
    score.rank = expected.rank;
    for (Eigen::Index k = 0; k < n; ++k) {
      score.determined.push_back(score.relative_std[k] <= options.undetermined_relative_std);
    }
    plan.candidates.push_back(std::move(score));
  }
  std::stable_sort(
      plan.candidates.begin(), plan.candidates.end(),
      [](const CandidateScore& a, const CandidateScore& b) { return a.score > b.score; });
  plan.wall_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_time).count();
  return plan;
}

}  // namespace mbid::updating
