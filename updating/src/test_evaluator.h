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

// Counters shared by all cost functions (evaluated from several threads by Ceres).
struct Work {
  std::atomic<long> simulations{0};
  std::atomic<long> sensitivity_simulations{0};
  std::atomic<long> rhs_evaluations{0};
  std::mutex mutex;
  std::string last_error;

  void Count(const simulation::IntegratorStatistics& s) {
    rhs_evaluations +=
        s.rhs_evaluations + s.rhs_evaluations_for_jacobian + s.rhs_evaluations_for_sensitivities;
  }
  void Fail(const std::string& what) {
    std::lock_guard<std::mutex> lock(mutex);
    last_error = what;
  }
};

class TestEvaluator {
 public:
  TestEvaluator(const model::MechanicalModel& model, const std::vector<Unknown>& unknowns,
                const PreparedTest& test, const UpdateOptions& options, Work& work);

  int residual_count() const {
    return test_.test->record.samples() * test_.test->record.channel_count();
  }

  // Residuals (and, if `jacobian` is not null, the row-major residuals x unknowns Jacobian in
  // Ceres' coordinates) at x. Two caches: Ceres asks for the Jacobian at a point whose residuals
  // it has just evaluated, and the covariance asks again at the solution after rejected trial
  // points.
  bool Evaluate(const double* x, double* residuals, double* jacobian);
  // The simulated record at x (channels x samples of the record) without weights.
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
  Eigen::VectorXd ComputeRawResiduals(model::MechanicalModel& model, const Eigen::VectorXd& x);
  Eigen::VectorXd ComputeResiduals(model::MechanicalModel& model, const Eigen::VectorXd& x);
  void ComputeWithJacobian(const Eigen::VectorXd& x);
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
  Eigen::VectorXd jacobian_x_;  // where jacobian_ and jacobian_residuals_ were computed
  Eigen::VectorXd jacobian_residuals_;
  Eigen::MatrixXd jacobian_;
  Eigen::MatrixXd unprojected_jacobian_;  // with a baseline: before the projection
  Eigen::VectorXd residual_x_;            // the last residual-only evaluation
  Eigen::VectorXd residuals_;
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
