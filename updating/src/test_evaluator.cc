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
  const bool at_jacobian_point = jacobian_x_.size() == point.size() && jacobian_x_ == point;
  const bool at_residual_point = residual_x_.size() == point.size() && residual_x_ == point;
  try {
    if (jacobian != nullptr && !at_jacobian_point) {
      ComputeWithJacobian(point);
      jacobian_x_ = point;
    } else if (jacobian == nullptr && !at_jacobian_point && !at_residual_point) {
      residuals_ = ComputeResiduals(*models_[0], point);
      residual_x_ = point;
    }
  } catch (const std::exception& e) {
    Invalidate();
    work_.Fail(test_.test->name + ": " + e.what());
    return false;
  }
  const bool from_jacobian = jacobian != nullptr || at_jacobian_point;
  Eigen::Map<Eigen::VectorXd>(residuals, residual_count()) =
      from_jacobian ? jacobian_residuals_ : residuals_;
  if (jacobian != nullptr) {
    Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
        jacobian, residual_count(), static_cast<Eigen::Index>(unknowns_.size())) = jacobian_;
  }
  return true;
}

Measurement TestEvaluator::Simulate(const Eigen::VectorXd& x) {
  model::MechanicalModel& model = *models_[0];
  const Excitation excitation = Configure(model, x);
  const simulation::SimulationResult run =
      simulation::Simulate(model, excitation, test_.simulation, test_.sensors);
  ++work_.simulations;
  work_.Count(run.statistics);
  CheckSamples(run.exact.values);
  Measurement simulated = run.exact;
  simulated.start_time_s = test_.test->record.start_time_s;
  return simulated;
}

Eigen::MatrixXd TestEvaluator::CalcBaselineRegression(const Eigen::VectorXd& x) const {
  const Baseline& baseline = *test_.baseline;
  const int m = test_.test->record.channel_count();
  const int count = static_cast<int>(unknowns_.size());
  if (baseline.terms() == 0 || jacobian_x_.size() != x.size() || jacobian_x_ != x) {
    return Eigen::MatrixXd();
  }
  Eigen::MatrixXd regression(baseline.terms() * m, count);
  for (int c = 0; c < m; ++c) {
    // The Jacobian's rows are dy/dx / sigma_c.
    regression.middleRows(baseline.terms() * c, baseline.terms()) =
        test_.sigma[c] *
        baseline.CalcRegression(unprojected_jacobian_.data() + c, m, residual_count(), count);
  }
  return regression;
}

void TestEvaluator::Invalidate() {
  jacobian_x_.resize(0);
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
                                                   const Eigen::VectorXd& x) {
  const Excitation excitation = Configure(model, x);
  const simulation::SimulationResult run =
      simulation::Simulate(model, excitation, test_.simulation, test_.sensors);
  ++work_.simulations;
  work_.Count(run.statistics);
  return Weigh(run.exact.values);
}

Eigen::VectorXd TestEvaluator::ComputeResiduals(model::MechanicalModel& model,
                                                const Eigen::VectorXd& x) {
  Eigen::VectorXd r = ComputeRawResiduals(model, x);
  Project(r.data());
  return r;
}

void TestEvaluator::ComputeWithJacobian(const Eigen::VectorXd& x) {
  const int columns = static_cast<int>(unknowns_.size());
  jacobian_ = Eigen::MatrixXd::Zero(residual_count(), columns);
  if (options_.jacobian == UpdateOptions::Jacobian::kNumeric) {
    ComputeNumericJacobian(x);
  } else {
    ComputeSensitivityJacobian(x);
  }
  if (test_.baseline->terms() == 0) return;
  // Variable projection: the basis does not depend on x, so P J is the exact Jacobian of P r.
  unprojected_jacobian_ = jacobian_;
  Project(jacobian_residuals_.data());
  for (int k = 0; k < columns; ++k) Project(jacobian_.col(k).data());
}

// Central differences of whole simulations in Ceres' coordinates; the columns run in
// parallel on the evaluator's model copies.
void TestEvaluator::ComputeNumericJacobian(const Eigen::VectorXd& x) {
  const int groups = static_cast<int>(models_.size());
  std::vector<std::string> errors(static_cast<size_t>(groups));
  auto run_group = [&](int g) {
    try {
      if (g == 0) jacobian_residuals_ = ComputeRawResiduals(*models_[0], x);
      for (size_t i = static_cast<size_t>(g); i < test_.unknowns.size();
           i += static_cast<size_t>(groups)) {
        const int k = test_.unknowns[i];
        Eigen::VectorXd step = x;
        step[k] = x[k] + options_.numeric_step;
        const Eigen::VectorXd plus = ComputeRawResiduals(*models_[static_cast<size_t>(g)], step);
        step[k] = x[k] - options_.numeric_step;
        const Eigen::VectorXd minus = ComputeRawResiduals(*models_[static_cast<size_t>(g)], step);
        jacobian_.col(k) = (plus - minus) / (2 * options_.numeric_step);
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
      if (g == 0) jacobian_residuals_ = Weigh(run.exact.values);
      CheckSamples(run.exact.values);
      for (size_t i = 0; i < columns.size(); ++i) {
        const int k = columns[i];
        const Unknown& unknown = unknowns_[static_cast<size_t>(k)];
        // d r / d x = (dy/dp) (dp/dx) / sigma; dp/dx = p on the log scale.
        const double dp_dx = unknown.log_scale ? unknown.ToValue(x[k]) : 1.0;
        const Eigen::MatrixXd& dy = run.output_sensitivities[i];
        for (int j = 0; j < record.samples(); ++j) {
          for (int c = 0; c < m; ++c) {
            jacobian_(j * m + c, k) = dy(j, c) * dp_dx / test_.sigma[c];
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
