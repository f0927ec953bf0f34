#include "mbid/simulation/sensitivity.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <utility>

#include "mbid/common/error.h"
#include "mbid/model/simbody.h"
#include "mbid/simulation/cvodes_integrator.h"
#include "sample_rows.h"
#include "simulation_setup.h"

namespace mbid::simulation {
namespace {

using internal::ChannelSource;
using internal::ChooseOutputStride;
using internal::FirstRowAtOrAfter;
using internal::MakeForcedModel;
using internal::ResolveChannels;
using internal::SampleRows;

// Relative step of the central differences of the initial coordinates: the static equilibrium
// is solved to roundoff and is smooth in the parameters, so the O(h^2) error is ~1e-8.
constexpr double kInitialStateStep = 1e-4;
// Step (rad or m, rad/s or m/s) of dy/dq and dy/du: outputs are smooth on the scale of 1 rad or
// 1 m, so the truncation error h^2 ~ 1e-12 and the roundoff 1e-16 / h ~ 1e-10 stay far below
// the sensitivities' tolerance.
constexpr double kOutputStep_rad = 1e-6;
// Largest step (rad or m, and relative in a parameter) along a sensitivity direction: larger than
// kOutputStep_rad because a direction that moves one coordinate much reaches the weakly coupled
// outputs by little, whose roundoff 1e-16 |y| / h is then a larger part of their derivative;
// the truncation h^2 ~ 1e-8 of a 1 rad scale is still far below the sensitivities' tolerance.
constexpr double kDirectionalStep = 1e-4;

// dq(0)/dp for each model parameter, by central differences on a clone.
Eigen::MatrixXd CalcInitialStateSensitivity(const model::MechanicalModel& model,
                                            const Excitation& excitation,
                                            const std::vector<std::string>& names) {
  const int n = model.coordinate_count();
  Eigen::MatrixXd dq0(n, static_cast<Eigen::Index>(names.size()));
  if (!excitation.start_depends_on_model()) {
    // The other tests start from given coordinates that no model parameter moves.
    dq0.setZero();
    return dq0;
  }
  std::unique_ptr<model::MechanicalModel> clone = model.Clone();
  for (size_t k = 0; k < names.size(); ++k) {
    const double value = model.GetParameter(names[k]);
    const double h = kInitialStateStep * std::max(std::abs(value), 1e-300);
    clone->SetParameter(names[k], value + h);
    const Eigen::VectorXd plus = CalcInitialCoordinates(*clone, excitation);
    clone->SetParameter(names[k], value - h);
    const Eigen::VectorXd minus = CalcInitialCoordinates(*clone, excitation);
    clone->SetParameter(names[k], value);
    dq0.col(static_cast<Eigen::Index>(k)) = (plus - minus) / (2 * h);
  }
  return dq0;
}

// The outputs' Jacobians at `state` by central differences: dy/dY over q (and u, when an output
// is a rate) and, for accelerations, dy/dp over the model parameters.
void CalcOutputJacobians(const model::MechanicalModel& simulated, const SimTK::State& state,
                         const std::vector<double>& p, const std::vector<double>& scale,
                         const std::vector<std::string>& model_parameters, int highest_order,
                         SimTK::State* scratch, Eigen::MatrixXd* dy_dY, Eigen::MatrixXd* dy_dp) {
  const int n = state.getNQ();
  for (int i = 0; i < dy_dY->cols(); ++i) {
    for (int sign : {1, -1}) {
      scratch->updQ() = state.getQ();
      if (highest_order > 0) scratch->updU() = state.getU();
      if (i < n) {
        scratch->updQ()[i] += sign * kOutputStep_rad;
      } else {
        scratch->updU()[i - n] += sign * kOutputStep_rad;
      }
      const Eigen::VectorXd y_step = simulated.CalcOutputs(*scratch, highest_order);
      if (sign > 0) {
        dy_dY->col(i) = y_step;
      } else {
        dy_dY->col(i) = (dy_dY->col(i) - y_step) / (2 * kOutputStep_rad);
      }
    }
  }
  if (highest_order < 2) return;
  // Forces are affine in stiffness and damping: central differences are exact to roundoff.
  scratch->updQ() = state.getQ();
  scratch->updU() = state.getU();
  for (int k = 0; k < static_cast<int>(model_parameters.size()); ++k) {
    const double step = 1e-6 * scale[k];
    simulated.ApplyParameterToState(*scratch, model_parameters[k], p[k] + step);
    const Eigen::VectorXd up = simulated.CalcOutputs(*scratch, highest_order);
    simulated.ApplyParameterToState(*scratch, model_parameters[k], p[k] - step);
    dy_dp->col(k) = (up - simulated.CalcOutputs(*scratch, highest_order)) / (2 * step);
    simulated.ApplyParameterToState(*scratch, model_parameters[k], p[k]);
  }
}

// dy/dtheta_k directly, by central differences along (s_k, e_k) in (Y, p): the state moves by
// at most kDirectionalStep in any coordinate and a model parameter by at most that much of its
// scale (the forces are affine in it).
void CalcDirectionalOutputDerivatives(const model::MechanicalModel& simulated,
                                      const SimTK::State& state, const Eigen::MatrixXd& s,
                                      const std::vector<double>& p,
                                      const std::vector<double>& scale,
                                      const std::vector<std::string>& model_parameters,
                                      int highest_order, SimTK::State* scratch,
                                      Eigen::MatrixXd* dy_dtheta) {
  const int n = state.getNQ();
  const int rows = highest_order > 0 ? 2 * n : n;  // the part of Y the outputs read
  const int model_count = static_cast<int>(model_parameters.size());
  for (int k = 0; k < static_cast<int>(s.cols()); ++k) {
    const bool moves_parameter = highest_order == 2 && k < model_count;
    const double largest = s.col(k).head(rows).cwiseAbs().maxCoeff();
    double h = largest > 0 ? kDirectionalStep / largest : 0.0;
    if (moves_parameter) {
      h = h > 0 ? std::min(h, kDirectionalStep * scale[k]) : kDirectionalStep * scale[k];
    }
    if (!(h > 0)) {
      dy_dtheta->col(k).setZero();  // neither state nor parameter moves the outputs
      continue;
    }
    Eigen::VectorXd plus;
    for (int sign : {1, -1}) {
      for (int i = 0; i < n; ++i) {
        scratch->updQ()[i] = state.getQ()[i] + sign * h * s(i, k);
        if (highest_order > 0) scratch->updU()[i] = state.getU()[i] + sign * h * s(n + i, k);
      }
      if (moves_parameter) {
        simulated.ApplyParameterToState(*scratch, model_parameters[k], p[k] + sign * h);
      }
      if (sign > 0) {
        plus = simulated.CalcOutputs(*scratch, highest_order);
      } else {
        dy_dtheta->col(k) = (plus - simulated.CalcOutputs(*scratch, highest_order)) / (2 * h);
      }
    }
    if (moves_parameter) simulated.ApplyParameterToState(*scratch, model_parameters[k], p[k]);
  }
}

}  // namespace

SensitivityResult SimulateWithSensitivities(const model::MechanicalModel& model,
                                            const Excitation& excitation,
                                            const SimulationOptions& options,
                                            const SensorOptions& sensors,
                                            const std::vector<std::string>& model_parameters,
                                            const std::vector<InitialStateDirection>& directions,
                                            const SensitivityOptions& sensitivity) {
  if (!(options.duration_s > 0) || !(sensors.sample_rate_hz > 0)) {
    throw std::invalid_argument(
        "SimulateWithSensitivities: duration and sample rate must be positive");
  }
  const int n = model.coordinate_count();
  const int model_count = static_cast<int>(model_parameters.size());
  const int count = model_count + static_cast<int>(directions.size());
  if (count == 0) {
    throw std::invalid_argument("SimulateWithSensitivities: no parameter to differentiate by");
  }
  for (const InitialStateDirection& direction : directions) {
    if (direction.dq0_dp.size() != n || !(direction.scale > 0)) {
      throw std::invalid_argument("SimulateWithSensitivities: direction '" + direction.name +
                                  "' needs " + std::to_string(n) +
                                  " entries of dq0_dp and a scale > 0");
    }
  }
  const std::vector<ChannelSource> sources = ResolveChannels(model, sensors.channels);
  const double tau = sensors.sample_interval_s();
  const internal::SampleGrid grid = internal::MakeSampleGrid(options.duration_s, sensors);

  SensitivityResult result;
  result.parameters = model_parameters;
  for (const InitialStateDirection& direction : directions) {
    result.parameters.push_back(direction.name);
  }
  result.initial_q = CalcInitialCoordinates(model, excitation);
  result.initial_q_sensitivity.resize(n, count);
  result.initial_q_sensitivity.leftCols(model_count) =
      CalcInitialStateSensitivity(model, excitation, model_parameters);
  std::vector<double> p(count), scale(count);
  for (int k = 0; k < model_count; ++k) {
    p[k] = model.GetParameter(model_parameters[k]);
    scale[k] = std::abs(p[k]) > 0 ? std::abs(p[k]) : 1.0;
  }
  for (int k = model_count; k < count; ++k) {
    const InitialStateDirection& direction = directions[k - model_count];
    result.initial_q_sensitivity.col(k) = direction.dq0_dp;
    p[k] = 0.0;  // not read by the right-hand side: its sensitivity is pure J s
    scale[k] = direction.scale;
  }

  const std::unique_ptr<model::MechanicalModel> forced_model = MakeForcedModel(model, excitation);
  const model::MechanicalModel& simulated = forced_model ? *forced_model : model;
  const double forcing_end_s = excitation.CalcForcingEndTime();

  CvodesIntegrator integrator(simulated.system(), options.integrator);
  integrator.set_state_derivative(simulated.MakeStateDerivative());
  integrator.set_residual(simulated.MakeResidual());
  // The right-hand side reads the parameters CVODES perturbs; only changed ones are applied
  // (each invalidates the state's Instance stage).
  std::vector<double> applied(p.begin(), p.begin() + model_count);
  integrator.set_time_dependent_inputs([&](SimTK::State& state) {
    const std::vector<double>& current = integrator.sensitivity_parameters();
    if (current.empty()) return;
    for (int k = 0; k < model_count; ++k) {
      if (current[k] != applied[k]) {
        simulated.ApplyParameterToState(state, model_parameters[k], current[k]);
        applied[k] = current[k];
      }
    }
  });
  // The forces' derivatives in closed form where the model knows them: no right-hand side per
  // parameter. Initial-state directions are not read by the right-hand side (df/dp = 0).
  std::vector<model::MechanicalModel::ForceDerivative> force_derivatives;
  for (const std::string& name : model_parameters) {
    force_derivatives.push_back(simulated.MakeParameterForceDerivative(name));
  }
  integrator.set_parameter_force_derivative(
      [&](const SimTK::State& state, int k, Eigen::VectorXd& dforce) {
        if (k >= model_count) {
          dforce.setZero(n);
          return true;
        }
        const model::MechanicalModel::ForceDerivative& derivative =
            force_derivatives[static_cast<size_t>(k)];
        if (!derivative) return false;
        derivative(state, dforce);
        return true;
      });
  // As in Simulate: the linearization as Newton Jacobian, for the state and the sensitivities.
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(n);
  SimTK::State initial = simulated.MakeState(result.initial_q, zero);
  const Eigen::MatrixXd newton_jacobian = internal::CalcNewtonJacobian(simulated, initial);
  integrator.set_jacobian(newton_jacobian);
  integrator.Initialize(std::move(initial));
  const int ny = integrator.state().getNY();
  Eigen::MatrixXd initial_sensitivity = Eigen::MatrixXd::Zero(ny, count);
  initial_sensitivity.topRows(n) = result.initial_q_sensitivity;  // Y = [q | u | z], u(0) = 0
  integrator.InitializeSensitivities(p, scale, initial_sensitivity, sensitivity);

  Measurement& exact = result.exact;
  exact.channels = sensors.channels;
  for (const ChannelSource& source : sources) exact.units.push_back(source.units);
  exact.sample_interval_s = tau;
  exact.start_time_s = grid.first_time_s();
  exact.source = "simulation";
  const int channel_count = static_cast<int>(sources.size());

  // Position outputs depend on q alone; rate outputs (velocities, accelerations) also on u and
  // the time, and accelerations on the parameters through the forces. A scratch state of the
  // same system, carrying the nominal parameters, serves for the output Jacobians.
  const int highest_order = internal::HighestOrderRead(simulated, sources);
  const int jacobian_columns = highest_order > 0 ? 2 * n : n;
  SimTK::State scratch = simulated.MakeState(result.initial_q, zero);
  Eigen::MatrixXd dy_dY(simulated.output_count(), jacobian_columns);
  Eigen::MatrixXd dy_dp = Eigen::MatrixXd::Zero(simulated.output_count(), model_count);
  // dy/dtheta_k = dy/dY s_k + dy/dp_k takes 2 outputs per coordinate (and per parameter, for
  // accelerations) by the Jacobians, or 2 per sensitivity along s_k: the fewer wins.
  const int by_jacobians = 2 * jacobian_columns + (highest_order == 2 ? 2 * model_count : 0);
  const bool directional = 2 * count < by_jacobians;
  Eigen::MatrixXd dy_dtheta = Eigen::MatrixXd::Zero(simulated.output_count(), count);
  bool forcing_done = !(forcing_end_s > 0);
  // A row holds the channels' values, then each sensitivity's channels.
  const int width = channel_count * (1 + count);
  const Eigen::MatrixXd rows = SampleRows(
      grid, FirstRowAtOrAfter(grid, forcing_end_s),
      ChooseOutputStride(tau, newton_jacobian, options.integrator.interpolate_outputs), width,
      [&](double t, double* row) {
        if (!forcing_done && t >= forcing_end_s) {
          // Restart the multistep history at the kink of the load, sensitivities carried over.
          integrator.AdvanceTo(forcing_end_s, CvodesIntegrator::Realization::kNone);
          result.statistics += integrator.statistics();
          const Eigen::MatrixXd carried = integrator.sensitivities();
          integrator.Initialize(SimTK::State(integrator.state()));
          integrator.InitializeSensitivities(p, scale, carried, sensitivity);
          forcing_done = true;
        }
        // Outputs realize what they need themselves (the crane's: nothing). Rows before the
        // record's start are visited for the same steps as a record from t = 0.
        const SimTK::State& state =
            t == 0 ? integrator.state()
                   : integrator.AdvanceTo(t, CvodesIntegrator::Realization::kNone);
        if (row == nullptr) return;
        const Eigen::VectorXd y = simulated.CalcOutputs(state, highest_order);
        const Eigen::MatrixXd& s = integrator.sensitivities();
        scratch.setTime(state.getTime());
        if (directional) {
          CalcDirectionalOutputDerivatives(simulated, state, s, p, scale, model_parameters,
                                           highest_order, &scratch, &dy_dtheta);
        } else {
          CalcOutputJacobians(simulated, state, p, scale, model_parameters, highest_order, &scratch,
                              &dy_dY, &dy_dp);
        }
        for (int c = 0; c < channel_count; ++c) {
          const ChannelSource& source = sources[c];
          row[c] = source.is_output ? y[source.index] : state.getQ()[source.index];
          for (int k = 0; k < count; ++k) {
            double value = s(source.index, k);
            if (source.is_output && directional) {
              value = dy_dtheta(source.index, k);
            } else if (source.is_output) {
              value = dy_dY.row(source.index).dot(s.col(k).head(jacobian_columns));
              if (k < model_count) value += dy_dp(source.index, k);
            }
            row[channel_count * (1 + k) + c] = value;
          }
        }
      });
  exact.values = rows.leftCols(channel_count);
  result.output_sensitivities.clear();
  for (int k = 0; k < count; ++k) {
    result.output_sensitivities.push_back(rows.middleCols(channel_count * (1 + k), channel_count));
  }
  result.statistics += integrator.statistics();
  return result;
}

}  // namespace mbid::simulation
