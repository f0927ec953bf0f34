#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "mbid/common/measurement.h"
#include "mbid/model/mechanical_model.h"
#include "mbid/simulation/excitation.h"
#include "mbid/simulation/integrator_options.h"
#include "mbid/simulation/sensor.h"
#include "mbid/simulation/simulate.h"

namespace mbid::simulation {

// A quantity that acts on a test only through its initial coordinates, e.g. the payload mass
// of a load drop or an initial deflection: the outputs are differentiated along dq(0)/dp.
struct InitialStateDirection {
  std::string name;
  Eigen::VectorXd dq0_dp;  // n entries, rad per unit of the quantity
  double scale = 1.0;      // its typical magnitude (> 0): sets CVODES' perturbation size
};

struct SensitivityResult {
  Measurement exact;                    // outputs as Simulate's `exact`
  std::vector<std::string> parameters;  // model parameters, then initial-state directions
  // Per parameter, samples x channels: dy_c(t_j)/dp (channel unit per parameter unit).
  std::vector<Eigen::MatrixXd> output_sensitivities;
  Eigen::VectorXd initial_q;              // rad
  Eigen::MatrixXd initial_q_sensitivity;  // n x parameters: dq(0)/dp
  IntegratorStatistics statistics;
};

// Simulates a test like Simulate() (same samples, channels, restart at the end of a forcing; no
// sensor effects) and integrates the forward sensitivities of the outputs with respect to the
// model's parameters `model_parameters` (at their current values) and the initial-state
// `directions`:
//   s_i = dY/dp_i from CVODES (CvodesIntegrator::InitializeSensitivities; the right-hand side
//         reads p through the input hook and MechanicalModel::ApplyParameterToState),
//   s_i(0) = dq(0)/dp_i: central differences of CalcInitialCoordinates on a clone of the model
//         (a load drop's loaded equilibrium moves with the stiffnesses), or the direction's own,
//   dy/dp_i = (dy/dq) (dq/dp_i), dy/dq by central differences of CalcOutputs (step 1e-6 rad).
// Errors as Simulate(); an unknown parameter name is an InputError.
SensitivityResult SimulateWithSensitivities(const model::MechanicalModel& model,
                                            const Excitation& excitation,
                                            const SimulationOptions& options,
                                            const SensorOptions& sensors,
                                            const std::vector<std::string>& model_parameters,
                                            const std::vector<InitialStateDirection>& directions,
                                            const SensitivityOptions& sensitivity);

}  // namespace mbid::simulation
