#include "test_evaluator.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <thread>

#include "mbid/common/error.h"
#include "mbid/simulation/simulate.h"

namespace mbid::updating::internal {
namespace {

using simulation::Excitation;

// Runs run_group(g) for g = 0..groups-1, group 0 on the calling thread.
template <typename Function>
void RunGroups(int groups, Function& run_group) {
  std::vector<std::thread> threads;
  for (int g = 1; g < groups; ++g) threads.emplace_back(run_group, g);
  run_group(0);
  for (std::thread& thread : threads) thread.join();
}

}  // namespace

TestEvaluator::TestEvaluator(const model::MechanicalModel& model,
                             const std::vector<Unknown>& unknowns, const PreparedTest& test,
                             const UpdateOptions& options, Work& work)
    : unknowns_(unknowns), test_(test), options_(options), work_(work) {
  const int groups =
      options.jacobian == UpdateOptions::Jacobian::kSensitivities
          ? std::max(1, std::min<int>(options.threads, static_cast<int>(test.unknowns.size())))
          : std::max(1, options.threads);
  for (int g = 0; g < groups; ++g) models_.push_back(model.Clone());
}

bool TestEvaluator::Evaluate(const double* x, double* residuals, double* jacobian) {
  const Eigen::Map<const Eigen::VectorXd> point(x, static_cast<Eigen::Index>(unknowns_.size()));
  if (!current_.At(point) && previous_.At(point)) std::swap(current_, previous_);
  const bool at_jacobian_point = current_.At(point);
  const bool at_residual_point = SamePoint(residual_x_, point);
  try {
    if (jacobian != nullptr) {
      if (SamePoint(last_trial_x_, point)) ++accepted_trials_;
      last_trial_x_.resize(0);
      if (!at_jacobian_point) ComputeWithJacobian(point);
      speculation_pending_ = false;
      current_.iterate = ++iterates_;
    } else if (!at_jacobian_point && !at_residual_point) {
      const bool speculate = ShouldSpeculate(point);
      ++trials_;
      last_trial_x_ = point;
      if (speculate) {
        ComputeWithJacobian(point);
        speculation_pending_ = true;
      } else {
        speculation_pending_ = false;  // the last speculation was not asked for: go plain once
        residuals_ = ComputeResiduals(*models_[0], point);
        residual_x_ = point;
      }
    }
  } catch (const std::exception& e) {
    Invalidate();
    work_.Fail(test_.test->name + ": " + e.what());
    return false;
  }
  const bool from_jacobian = current_.At(point);
  Eigen::Map<Eigen::VectorXd>(residuals, residual_count()) =
      from_jacobian ? current_.residuals : residuals_;
  if (jacobian != nullptr) {
    Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
        jacobian, residual_count(), static_cast<Eigen::Index>(unknowns_.size())) =
        current_.jacobian;
  }
  return true;
}

// A trial point is worth its Jacobian when Ceres is expected to ask for it: the step from the
// last iterate is to be accepted and not to end the fit. So the last iterate's linear model must
// predict a relative decrease of the cost of 10 function tolerances at least, and the trial
// points accepted so far (counted from one of one) must outnumber the break-even share
// 1 - P / S, P and S the right-hand sides of the last plain and sensitivity runs: a speculation
// Ceres takes saves P, one it rejects wastes S - P. Far starts, whose steps are often rejected,
// stay plain. After a speculation that was not asked for, the next trial point is plain.
// Decided on counts only, so the fit's path is the same on every run.
bool TestEvaluator::ShouldSpeculate(const Eigen::VectorXd& x) const {
  if (!options_.speculative_jacobians || speculation_pending_ ||
      options_.jacobian != UpdateOptions::Jacobian::kSensitivities) {
    return false;
  }
  if (plain_rhs_ > 0 && sensitivity_rhs_ > 0) {
    const double accepted = static_cast<double>(accepted_trials_ + 1) / (trials_ + 1);
    if (accepted <= 1.0 - static_cast<double>(plain_rhs_) / sensitivity_rhs_) return false;
  }
  const JacobianPoint* iterate = current_.iterate >= previous_.iterate ? &current_ : &previous_;
  if (iterate->iterate == 0) return false;
  const double cost = iterate->residuals.squaredNorm();
  if (!(cost > 0)) return false;
  const Eigen::VectorXd predicted = iterate->residuals + iterate->jacobian * (x - iterate->x);
  return (cost - predicted.squaredNorm()) > 10 * options_.function_tolerance * cost;
}

Measurement TestEvaluator::WithRecordTimes(const Measurement& exact) const {
  Measurement simulated = exact;
  simulated.start_time_s = test_.test->record.start_time_s;
  return simulated;
}

Measurement TestEvaluator::Simulate(const Eigen::VectorXd& x) {
  if (SamePoint(simulated_x_, x)) return simulated_;
  for (const JacobianPoint* point : {&current_, &previous_}) {
    if (point->At(x)) return point->simulated;
  }
  model::MechanicalModel& model = *models_[0];
  const Excitation excitation = Configure(model, x);
  const simulation::SimulationResult run =
      simulation::Simulate(model, excitation, test_.simulation, test_.sensors);
  ++work_.simulations;
  work_.Count(run.statistics);
  CheckSamples(run.exact.values);
  simulated_x_ = x;
  simulated_ = WithRecordTimes(run.exact);
  return simulated_;
}

Eigen::MatrixXd TestEvaluator::CalcBaselineRegression(const Eigen::VectorXd& x) const {
  const Baseline& baseline = *test_.baseline;
  const int m = test_.test->record.channel_count();
  const int count = static_cast<int>(unknowns_.size());
  const JacobianPoint* at = current_.At(x) ? &current_ : previous_.At(x) ? &previous_ : nullptr;
  if (baseline.terms() == 0 || at == nullptr) return Eigen::MatrixXd();
  Eigen::MatrixXd regression(baseline.terms() * m, count);
  for (int c = 0; c < m; ++c) {
    // The Jacobian's rows are dy/dx / sigma_c.
    regression.middleRows(baseline.terms() * c, baseline.terms()) =
        test_.sigma[c] *
        baseline.CalcRegression(at->unprojected.data() + c, m, residual_count(), count);
  }
  return regression;
}

void TestEvaluator::Invalidate() {
  current_ = JacobianPoint();
  previous_ = JacobianPoint();
  speculation_pending_ = false;
  residual_x_.resize(0);
}

// Sets the shared parameters of `model` from x and returns the test's excitation with its
// nuisance parameters.
Excitation TestEvaluator::Configure(model::MechanicalModel& model, const Eigen::VectorXd& x) const {
  Excitation excitation = test_.test->excitation;
  for (int k : test_.unknowns) {
    const Unknown& unknown = unknowns_[static_cast<size_t>(k)];
    const double value = unknown.ToValue(x[k]);
    switch (unknown.kind) {
      case Unknown::Kind::kModel:
        model.SetParameter(unknown.name, value);
        break;
      case Unknown::Kind::kPayloadMass:
        excitation.get<simulation::LoadDrop>().payload_mass_kg = value;
        break;
      case Unknown::Kind::kDeflection:
        excitation.get<simulation::InitialDeflection>().deflection_rad[unknown.coordinate] = value;
        break;
    }
  }
  return excitation;
}

void TestEvaluator::CheckSamples(const Eigen::MatrixXd& simulated) const {
  if (simulated.rows() != test_.test->record.samples()) {
    throw std::logic_error("the simulation has " + std::to_string(simulated.rows()) +
                           " samples, the record " + std::to_string(test_.test->record.samples()));
  }
}

// (simulated - measured) / sigma, sample-major: r[j * m + c].
Eigen::VectorXd TestEvaluator::Weigh(const Eigen::MatrixXd& simulated) const {
  CheckSamples(simulated);
  const Measurement& record = test_.test->record;
  const int m = record.channel_count();
  Eigen::VectorXd r(residual_count());
  for (int j = 0; j < record.samples(); ++j) {
    for (int c = 0; c < m; ++c) {
      r[j * m + c] = (simulated(j, c) - record.values(j, c)) / test_.sigma[c];
    }
  }
  return r;
}

// Each channel's part of `v` (sample-major) orthogonal to its baseline.
void TestEvaluator::Project(double* v) const {
  const int m = test_.test->record.channel_count();
  for (int c = 0; c < m; ++c) test_.baseline->Project(v + c, m);
}

// Residuals before the baseline's projection.
Eigen::VectorXd TestEvaluator::ComputeRawResiduals(model::MechanicalModel& model,
                                                   const Eigen::VectorXd& x,
                                                   Measurement* simulated) {
  const Excitation excitation = Configure(model, x);
  const simulation::SimulationResult run =
      simulation::Simulate(model, excitation, test_.simulation, test_.sensors);
  ++work_.simulations;
  work_.Count(run.statistics);
  if (simulated != nullptr) plain_rhs_ = TotalRhs(run.statistics);
  Eigen::VectorXd r = Weigh(run.exact.values);
  if (simulated != nullptr) *simulated = WithRecordTimes(run.exact);
  return r;
}

Eigen::VectorXd TestEvaluator::ComputeResiduals(model::MechanicalModel& model,
                                                const Eigen::VectorXd& x) {
  Eigen::VectorXd r = ComputeRawResiduals(model, x, &simulated_);
  simulated_x_ = x;
  Project(r.data());
  return r;
}

void TestEvaluator::ComputeWithJacobian(const Eigen::VectorXd& x) {
  const int columns = static_cast<int>(unknowns_.size());
  // The last iterate stays (the fit may end there after rejected trial points); the other goes.
  if (current_.iterate >= previous_.iterate) std::swap(previous_, current_);
  current_ = JacobianPoint();
  current_.jacobian = Eigen::MatrixXd::Zero(residual_count(), columns);
  if (options_.jacobian == UpdateOptions::Jacobian::kNumeric) {
    ComputeNumericJacobian(x);
  } else {
    ComputeSensitivityJacobian(x);
  }
  current_.x = x;
  if (test_.baseline->terms() == 0) return;
  // Variable projection: the basis does not depend on x, so P J is the exact Jacobian of P r.
  current_.unprojected = current_.jacobian;
  Project(current_.residuals.data());
  for (int k = 0; k < columns; ++k) Project(current_.jacobian.col(k).data());
}

// Central differences of whole simulations in Ceres' coordinates; the columns run in
// parallel on the evaluator's model copies.
void TestEvaluator::ComputeNumericJacobian(const Eigen::VectorXd& x) {
  const int groups = static_cast<int>(models_.size());
  std::vector<std::string> errors(static_cast<size_t>(groups));
  auto run_group = [&](int g) {
    try {
      if (g == 0) current_.residuals = ComputeRawResiduals(*models_[0], x, &current_.simulated);
      for (size_t i = static_cast<size_t>(g); i < test_.unknowns.size();
           i += static_cast<size_t>(groups)) {
        const int k = test_.unknowns[i];
        Eigen::VectorXd step = x;
        step[k] = x[k] + options_.numeric_step;
        const Eigen::VectorXd plus =
            ComputeRawResiduals(*models_[static_cast<size_t>(g)], step, nullptr);
        step[k] = x[k] - options_.numeric_step;
        const Eigen::VectorXd minus =
            ComputeRawResiduals(*models_[static_cast<size_t>(g)], step, nullptr);
        current_.jacobian.col(k) = (plus - minus) / (2 * options_.numeric_step);
      }
    } catch (const std::exception& e) {
      errors[static_cast<size_t>(g)] = e.what();
    }
  };
  RunGroups(groups, run_group);
  for (const std::string& error : errors) {
    if (!error.empty()) throw NumericalError("numeric Jacobian", error);
  }
}

// CVODES forward sensitivities; the unknowns are split over the model copies, each copy
// integrating the state with its share of the sensitivities.
void TestEvaluator::ComputeSensitivityJacobian(const Eigen::VectorXd& x) {
  const int groups = static_cast<int>(models_.size());
  const Measurement& record = test_.test->record;
  const int m = record.channel_count();
  std::vector<std::string> errors(static_cast<size_t>(groups));
  std::vector<long> rhs(static_cast<size_t>(groups), 0);
  auto run_group = [&](int g) {
    try {
      model::MechanicalModel& model = *models_[static_cast<size_t>(g)];
      const Excitation excitation = Configure(model, x);
      std::vector<int> columns;
      std::vector<std::string> names;
      std::vector<simulation::InitialStateDirection> directions;
      std::vector<int> direction_columns;
      for (size_t i = static_cast<size_t>(g); i < test_.unknowns.size();
           i += static_cast<size_t>(groups)) {
        const int k = test_.unknowns[i];
        const Unknown& unknown = unknowns_[static_cast<size_t>(k)];
        if (unknown.kind == Unknown::Kind::kModel) {
          columns.push_back(k);
          names.push_back(unknown.name);
        } else {
          direction_columns.push_back(k);
          directions.push_back(MakeDirection(model, excitation, unknown, x[k]));
        }
      }
      columns.insert(columns.end(), direction_columns.begin(), direction_columns.end());
      const simulation::SensitivityResult run =
          simulation::SimulateWithSensitivities(model, excitation, test_.simulation, test_.sensors,
                                                names, directions, options_.sensitivity);
      ++work_.sensitivity_simulations;
      work_.Count(run.statistics);
      rhs[static_cast<size_t>(g)] = TotalRhs(run.statistics);
      if (g == 0) {
        current_.residuals = Weigh(run.exact.values);
        current_.simulated = WithRecordTimes(run.exact);
      }
      CheckSamples(run.exact.values);
      for (size_t i = 0; i < columns.size(); ++i) {
        const int k = columns[i];
        const Unknown& unknown = unknowns_[static_cast<size_t>(k)];
        // d r / d x = (dy/dp) (dp/dx) / sigma; dp/dx = p on the log scale.
        const double dp_dx = unknown.log_scale ? unknown.ToValue(x[k]) : 1.0;
        const Eigen::MatrixXd& dy = run.output_sensitivities[i];
        for (int j = 0; j < record.samples(); ++j) {
          for (int c = 0; c < m; ++c) {
            current_.jacobian(j * m + c, k) = dy(j, c) * dp_dx / test_.sigma[c];
          }
        }
      }
    } catch (const std::exception& e) {
      errors[static_cast<size_t>(g)] = e.what();
    }
  };
  RunGroups(groups, run_group);
  for (const std::string& error : errors) {
    if (!error.empty()) throw NumericalError("sensitivities", error);
  }
  sensitivity_rhs_ = 0;
  for (long count : rhs) sensitivity_rhs_ += count;
}

// dq(0)/dp of a nuisance parameter: e_i for a deflection; central differences of the loaded
// equilibrium for the payload mass.
simulation::InitialStateDirection TestEvaluator::MakeDirection(const model::MechanicalModel& model,
                                                               const Excitation& excitation,
                                                               const Unknown& unknown,
                                                               double x) const {
  simulation::InitialStateDirection direction;
  direction.name = unknown.name;
  const int n = model.coordinate_count();
  direction.dq0_dp = Eigen::VectorXd::Zero(n);
  const double value = unknown.ToValue(x);
  if (unknown.kind == Unknown::Kind::kDeflection) {
    for (int i = 0; i < n; ++i) {
      if (model.coordinate_names()[static_cast<size_t>(i)] == unknown.coordinate) {
        direction.dq0_dp[i] = 1.0;
      }
    }
    direction.scale = std::max(std::abs(value), 1e-3);
  } else {
    const double h = 1e-4 * value;
    Excitation changed = excitation;
    double& mass = changed.get<simulation::LoadDrop>().payload_mass_kg;
    mass = value + h;
    const Eigen::VectorXd plus = simulation::CalcInitialCoordinates(model, changed);
    mass = value - h;
    const Eigen::VectorXd minus = simulation::CalcInitialCoordinates(model, changed);
    direction.dq0_dp = (plus - minus) / (2 * h);
    direction.scale = value;
  }
  return direction;
}

}  // namespace mbid::updating::internal
