#pragma once

#include <Eigen/Core>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "mbid/model/linear_model.h"

namespace SimTK {
class MultibodySystem;
class State;
}  // namespace SimTK

namespace mbid::model {

// A tunable parameter of a model, with its unit and admissible range.
struct Parameter {
  std::string name;   // "c_alpha", "d_theta", ...
  std::string units;  // "N*m/rad", "N*m*s/rad"
  double value = 0.0;
  double lower = 0.0;
  double upper = 0.0;
};

// A static force at a named point of the machine, expressed in the ground frame (N). The crane
// names its boom tip "boom_tip"; a payload of mass m is {"boom_tip", {0, 0, -m g}}.
struct PointLoad {
  std::string point;
  Eigen::Vector3d force_G = Eigen::Vector3d::Zero();
};

// What identification and updating see of a machine: named coordinates, outputs and
// parameters; a Simbody system whose state is q = generalized coordinates (q' = u, no
// quaternions, no constraints); its static equilibrium and linearization. Each instance owns
// its system and states, so a worker thread owns its model.
class MechanicalModel {
 public:
  virtual ~MechanicalModel() = default;

  virtual std::string type() const = 0;
  virtual const std::vector<std::string>& coordinate_names() const = 0;
  virtual const std::vector<std::string>& output_names() const = 0;
  // Output units, one per output.
  virtual const std::vector<std::string>& output_units() const = 0;
  // Per output, how often q is differentiated in it: 0 for positions and angles (y = H q in the
  // linearization), 1 for velocities (y = H q'), 2 for accelerations (y = H q'').
  virtual std::vector<int> output_derivative_orders() const {
    return std::vector<int>(output_names().size(), 0);
  }
  // Per coordinate, its unit: "rad" or "m".
  virtual std::vector<std::string> coordinate_units() const {
    return std::vector<std::string>(coordinate_names().size(), "rad");
  }
  int coordinate_count() const { return static_cast<int>(coordinate_names().size()); }
  // The unit of coordinate `name` ("rad" or "m"), or "" when the model has none of that name.
  std::string coordinate_unit(const std::string& name) const;
  int output_count() const { return static_cast<int>(output_names().size()); }
  // Names of points that accept external loads.
  virtual std::vector<std::string> load_points() const = 0;
  // The static loads of a payload of `mass_kg` hanging where the machine carries loads (the
  // crane's boom tip): its weight, at rest.
  virtual std::vector<PointLoad> CalcPayloadLoads(double mass_kg) const = 0;

  // The tunable parameters with their current values.
  virtual std::vector<Parameter> parameters() const = 0;
  // Throws InputError for an unknown name or a value outside (lower, upper).
  virtual void SetParameter(const std::string& name, double value) = 0;
  double GetParameter(const std::string& name) const;
  // Sets a parameter in `state` alone (as SetParameter would for states made afterwards),
  // leaving the model unchanged: for right-hand sides that read parameters, e.g. CVODES forward
  // sensitivities. Invalidates the state's Instance stage. Same checks as SetParameter.
  virtual void ApplyParameterToState(SimTK::State& state, const std::string& name,
                                     double value) const = 0;
  // dF/dp: the derivative of the generalized applied forces (one per coordinate, N*m or N per
  // unit of p) by parameter `name` at a state's q and u, for parameters the forces are affine
  // in, resolved once per name. Empty where the model has no closed form: callers then
  // difference the right-hand side in p (forward sensitivities, simulation/sensitivity.h).
  using ForceDerivative = std::function<void(const SimTK::State& state, Eigen::VectorXd& dforce)>;
  virtual ForceDerivative MakeParameterForceDerivative(const std::string& /*name*/) const {
    return {};
  }

  // Y' = [q'; u'] of a state realized to Stage::Velocity, computed without realizing the
  // Dynamics stage: the model sums its force elements' forces itself and solves with Simbody's
  // inverse dynamics and M^-1, which saves about a fifth of a right-hand side (Simbody's force
  // subsystem and its caches). Must equal realize(Acceleration)'s Y' to round-off. Each
  // returned function has its own scratch (give each integrator its own); the model must
  // outlive it. Empty where the model has no such shortcut.
  using StateDerivative = std::function<void(const SimTK::State& state, double* y_dot)>;
  virtual StateDerivative MakeStateDerivative() const { return {}; }
  // The inverse-dynamics residual M u' + f_inertial - f_applied (one per mobility) of a state
  // realized to Stage::Velocity at given accelerations u' (NU values each): zero at the state's own
  // u', and MakeStateDerivative's u' = -M^-1 residual(0). Its derivative in Y at fixed u' gives the
  // state Jacobian's acceleration rows, du'/dY = -M^-1 dresidual/dY, without an M^-1 per
  // column (forward sensitivities). Same scratch and lifetime rules; empty where the model has
  // no StateDerivative.
  using Residual =
      std::function<void(const SimTK::State& state, const double* u_dot, double* residual)>;
  virtual Residual MakeResidual() const { return {}; }

  // The Simbody system; realized to Topology.
  virtual const SimTK::MultibodySystem& system() const = 0;
  // A state at time 0 with coordinates q and speeds u (rad, rad/s), carrying the current
  // parameters and no external load.
  virtual SimTK::State MakeState(const Eigen::VectorXd& q, const Eigen::VectorXd& u) const = 0;
  // Time-dependent external loads (excitations): called at every force evaluation with the
  // time (s); fills point loads (N, ground frame) and generalized forces (N*m, one per
  // coordinate, or left empty). An empty function removes the loads. This changes the model:
  // give each simulation that needs it its own instance (Clone()).
  using ExternalLoadFunction = std::function<void(double t_s, std::vector<PointLoad>& loads,
                                                  Eigen::VectorXd& generalized_forces)>;
  virtual void SetExternalLoad(ExternalLoadFunction load) = 0;
  // The outputs y (rad) at the state's q and u. The model realizes whatever it needs, so a
  // state whose Y was just set will do. Outputs of a derivative order above `max_order`
  // (output_derivative_orders) are NaN and cost nothing: a record of angles alone needs no
  // forward dynamics for the model's accelerometers.
  virtual Eigen::VectorXd CalcOutputs(const SimTK::State& state, int max_order) const = 0;
  Eigen::VectorXd CalcOutputs(const SimTK::State& state) const { return CalcOutputs(state, 2); }
  // Total mechanical energy (J): kinetic + gravity + spring potential.
  virtual double CalcEnergy(const SimTK::State& state) const = 0;

  // The static equilibrium q under the given static loads, at rest. Solved by Newton to
  // machine precision; a failure to converge is a NumericalError.
  virtual Eigen::VectorXd SolveStaticEquilibrium(const std::vector<PointLoad>& loads) const = 0;
  // Linearization about the unloaded equilibrium (q = 0 by construction of the preload).
  virtual LinearModel Linearize() const = 0;

  virtual std::unique_ptr<MechanicalModel> Clone() const = 0;
};

}  // namespace mbid::model
