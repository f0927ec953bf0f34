#pragma once

// The residuals and Jacobian of one test record for the output-error fit (Ceres' cost function
// of one residual block). Not part of the public API.

#include <ceres/ceres.h>

#include <Eigen/Core>
#include <atomic>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "fit_unknowns.h"
#include "mbid/common/measurement.h"
#include "mbid/model/mechanical_model.h"
#include "mbid/simulation/excitation.h"
#include "mbid/simulation/sensitivity.h"
#include "mbid/updating/output_error.h"
#include "prepared_test.h"

namespace mbid::updating::internal {

// A run's right-hand sides, the difference quotients' and the Jacobians' included.
inline long TotalRhs(const simulation::IntegratorStatistics& s) {
  return s.rhs_evaluations + s.rhs_evaluations_for_jacobian + s.rhs_evaluations_for_sensitivities;
}

// Counters shared by all cost functions (evaluated from several threads by Ceres).
struct Work {
  std::atomic<long> simulations{0};
  std::atomic<long> sensitivity_simulations{0};
  std::atomic<long> rhs_evaluations{0};
  std::mutex mutex;
  std::string last_error;

  void Count(const simulation::IntegratorStatistics& s) { rhs_evaluations += TotalRhs(s); }
  void Fail(const std::string& what) {
    std::lock_guard<std::mutex> lock(mutex);
    last_error = what;
  }
};

// Whether `cached` (empty: none) is the point `x`.
inline bool SamePoint(const Eigen::VectorXd& cached, const Eigen::Ref<const Eigen::VectorXd>& x) {
  return cached.size() == x.size() && cached == x;
}

class TestEvaluator {
 public:
  TestEvaluator(const model::MechanicalModel& model, const std::vector<Unknown>& unknowns,
                const PreparedTest& test, const UpdateOptions& options, Work& work);

  int residual_count() const {
    return test_.test->record.samples() * test_.test->record.channel_count();
  }

  // Residuals (and, if `jacobian` is not null, the row-major residuals x unknowns Jacobian in
  // Ceres' coordinates) at x. Caches: Ceres asks for the Jacobian at a point whose residuals it
  // has just evaluated, and the covariance asks again at the solution after rejected trial
  // points (the last iterate's Jacobian and the newest are kept). With
  // UpdateOptions::speculative_jacobians a trial point that the last iterate's linear model expects
  // to be accepted is evaluated with its Jacobian at once: a sensitivity run yields the residuals
  // too, so the plain run is saved.
  bool Evaluate(const double* x, double* residuals, double* jacobian);
  // The simulated record at x (channels x samples of the record) without weights: the last
  // evaluation's when it was at x, else a new simulation.
  Measurement Simulate(const Eigen::VectorXd& x);
  // d(baseline coefficients)/dx of each channel at the last Jacobian's point `x`: rows
  // terms * c .. terms * (c + 1) - 1 for channel c, one column per unknown; empty elsewhere.
  Eigen::MatrixXd CalcBaselineRegression(const Eigen::VectorXd& x) const;
  // Forgets the cached evaluation (the weights changed).
  void Invalidate();

 private:
  simulation::Excitation Configure(model::MechanicalModel& model, const Eigen::VectorXd& x) const;
  void CheckSamples(const Eigen::MatrixXd& simulated) const;
  Eigen::VectorXd Weigh(const Eigen::MatrixXd& simulated) const;
  void Project(double* v) const;
  // simulated: where to keep the simulated record for Simulate, if not null (the calling
  // thread's runs only, which also record a plain run's right-hand sides for ShouldSpeculate).
  Eigen::VectorXd ComputeRawResiduals(model::MechanicalModel& model, const Eigen::VectorXd& x,
                                      Measurement* simulated);
  Eigen::VectorXd ComputeResiduals(model::MechanicalModel& model, const Eigen::VectorXd& x);
  void ComputeWithJacobian(const Eigen::VectorXd& x);
  bool ShouldSpeculate(const Eigen::VectorXd& x) const;
  Measurement WithRecordTimes(const Measurement& exact) const;
  void ComputeNumericJacobian(const Eigen::VectorXd& x);
  void ComputeSensitivityJacobian(const Eigen::VectorXd& x);
  simulation::InitialStateDirection MakeDirection(const model::MechanicalModel& model,
                                                  const simulation::Excitation& excitation,
                                                  const Unknown& unknown, double x) const;

  const std::vector<Unknown>& unknowns_;
  const PreparedTest& test_;
  const UpdateOptions& options_;
  Work& work_;
  std::vector<std::unique_ptr<model::MechanicalModel>> models_;  // one per thread
  // A point evaluated with its Jacobian.
  struct JacobianPoint {
    Eigen::VectorXd x;  // empty: none
    Eigen::VectorXd residuals;
    Eigen::MatrixXd jacobian;
    Eigen::MatrixXd unprojected;  // with a baseline: before the projection
    Measurement simulated;        // the exact outputs (channels x samples)
    long iterate = 0;             // > 0: Ceres asked for the Jacobian here, the n-th time
    bool At(const Eigen::Ref<const Eigen::VectorXd>& point) const { return SamePoint(x, point); }
  };
  JacobianPoint current_, previous_;  // current_: the newest, or the one last asked for
  long iterates_ = 0;
  bool speculation_pending_ = false;  // the newest Jacobian was speculative, not yet asked for
  // Trial points (residuals asked for at a new point) and those Ceres accepted (asked for the
  // Jacobian there next), and the right-hand sides of the last plain and sensitivity runs.
  long trials_ = 0, accepted_trials_ = 0;
  Eigen::VectorXd last_trial_x_;
  long plain_rhs_ = 0, sensitivity_rhs_ = 0;
  Eigen::VectorXd residual_x_;  // the last residual-only evaluation
  Eigen::VectorXd residuals_;
  Eigen::VectorXd simulated_x_;  // the last plain simulation's point and exact outputs
  Measurement simulated_;
};

// One test's residual block.
class TestCost final : public ceres::CostFunction {
 public:
  TestCost(TestEvaluator& evaluator, int unknown_count) : evaluator_(evaluator) {
    set_num_residuals(evaluator.residual_count());
    mutable_parameter_block_sizes()->push_back(unknown_count);
  }
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    return evaluator_.Evaluate(parameters[0], residuals,
                               jacobians != nullptr ? jacobians[0] : nullptr);
  }

 private:
  TestEvaluator& evaluator_;
};

}  // namespace mbid::updating::internal
