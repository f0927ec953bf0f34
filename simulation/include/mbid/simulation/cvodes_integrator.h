#pragma once

#include <Eigen/Core>
#include <functional>
#include <memory>
#include <vector>

#include "mbid/simulation/integrator_options.h"

namespace SimTK {
class MultibodySystem;
class State;
class System;
}  // namespace SimTK

namespace mbid::simulation {

// Integrates the equations of motion of a Simbody system with SUNDIALS CVODES.
//
// CVODES sees the ODE  Y' = f(t, Y)  with  Y = [q | u | z]  (Simbody's continuous state:
// generalized coordinates, speeds and auxiliary variables). f is Simbody's own: set t and Y,
// realize(Stage::Acceleration), read getYDot(). The kinematic equation q' = N(q) u is
// therefore Simbody's, not assumed to be q' = u. For a MultibodySystem without z, f is the
// same computation without the Acceleration stage's cache bookkeeping: realize(Stage::Dynamics)
// (q' and the applied forces), then Simbody's forward-dynamics operator
// calcAccelerationIgnoringConstraints on those forces (6% fewer instructions per crane
// simulation, the same trajectory to roundoff: tests/simulation/cvodes_integrator_test.cc).
//
// Supported systems: no constraints and no quaternions (Pin, Universal, Slider, Gimbal ...).
// Nothing here projects onto a constraint manifold or normalizes quaternions, so a system
// with either is rejected by Initialize(). Simbody event handlers are not run.
//
// One integrator owns one working State and one CVODES memory: do not share it between
// threads. The system must outlive the integrator.
class CvodesIntegrator {
 public:
  // Called on the working state at every right-hand-side evaluation, after time and Y are set
  // and before realize(): the place to set time-dependent inputs (e.g. DiscreteForces).
  using TimeDependentInputs = std::function<void(SimTK::State&)>;

  // `system` must be realized to Topology. Throws std::invalid_argument for invalid options
  // or an unrealized system.
  CvodesIntegrator(const SimTK::System& system, const IntegratorOptions& options);
  // The same, with Simbody's forward-dynamics operator as right-hand side (above).
  CvodesIntegrator(const SimTK::MultibodySystem& system, const IntegratorOptions& options);
  ~CvodesIntegrator();
  CvodesIntegrator(CvodesIntegrator&&) noexcept;
  CvodesIntegrator& operator=(CvodesIntegrator&&) noexcept;
  CvodesIntegrator(const CvodesIntegrator&) = delete;
  CvodesIntegrator& operator=(const CvodesIntegrator&) = delete;

  // Replaces the input hook (an empty function removes it). Takes effect at the next
  // evaluation; after a discontinuous change call Initialize(state()) to restart the
  // multistep history at the discontinuity.
  void set_time_dependent_inputs(TimeDependentInputs hook);

  // Y' of a state realized to Stage::Velocity, in place of realizing the Dynamics stage and
  // calling Simbody's forward-dynamics operator (MechanicalModel::MakeStateDerivative). Used
  // with the MultibodySystem constructor on systems without auxiliary states; empty (the
  // default) realizes the force subsystem.
  using StateDerivative = std::function<void(const SimTK::State& state, double* y_dot)>;
  void set_state_derivative(StateDerivative derivative);
  // The inverse-dynamics residual of the same forces (MechanicalModel::MakeResidual): with it,
  // the forward-difference state Jacobian of the sensitivities (kStateJacobian, kForward)
  // differences the residual at fixed u' and applies M^-1 once per mobility, not per column.
  using Residual =
      std::function<void(const SimTK::State& state, const double* u_dot, double* residual)>;
  void set_residual(Residual residual);

  // A constant approximation of the Jacobian df/dY (NY x NY), e.g. the model's linearization,
  // for the Newton iteration; empty (the default) forms it from difference quotients of f (NY
  // right-hand sides each time CVODES refreshes it). Newton with an approximate Jacobian only
  // converges more slowly; the error test, not the Jacobian, controls the accuracy. With a
  // Jacobian, Adams also iterates with Newton instead of fixed-point iteration, which takes
  // fewer and longer steps at the same tolerance. Method kAuto chooses between BDF and Adams
  // from this Jacobian (ChooseMethod; BDF without one). Takes effect at the next Initialize(),
  // which throws std::invalid_argument if the size is not NY x NY.
  void set_jacobian(Eigen::MatrixXd jacobian);

  // Starts (or restarts) the integration from a copy of `initial` at initial.getTime(); the
  // copy is realized to Stage::Velocity (the input hook is not called yet: AdvanceTo(time())
  // realizes it to Acceleration with the inputs). Throws std::invalid_argument if the state
  // belongs to a system with constraints or quaternions, and NumericalError if CVODES cannot
  // be set up.
  void Initialize(const SimTK::State& initial);
  // The same, taking over `initial` instead of copying it.
  void Initialize(SimTK::State&& initial);

  // How far AdvanceTo() realizes the state it returns. A Simbody realization costs as much as a
  // right-hand side: callers that only read q, u or outputs skip forces and accelerations.
  enum class Realization {
    kNone,           // t and Y set, inputs applied, nothing realized (MechanicalModel outputs)
    kPositions,      // Stage::Position (kinematics); realize further as needed
    kAccelerations,  // Stage::Acceleration
  };

  // Integrates to exactly time `t` (s), t >= time(), and returns the working state at t
  // realized to `realization` (valid until the next call), with the inputs applied. Unless
  // options().interpolate_outputs, CVODES stops at t (a stop time, no interpolation), so
  // inputs changed between calls never act before their time.
  //
  // An exception thrown by Simbody or the input hook is a recoverable failure for CVODES
  // (it retries with a smaller step); after 100 failures within one call it is final. Throws
  // NumericalError (stage "CVODES") naming the SUNDIALS flag (CV_TOO_MUCH_WORK, ...), its
  // message, the time reached and the last exception; Initialize() must then be called again
  // and state() holds the last point CVODES reached. Throws std::logic_error before
  // Initialize() and std::invalid_argument for t < time().
  const SimTK::State& AdvanceTo(double t, Realization realization = Realization::kAccelerations);

  // The derivative dF/dp_k of the applied generalized forces (NU entries, mobility forces per
  // unit of p_k) by sensitivity parameter k at `state` (t, Y set, nominal parameters applied,
  // realized to Position): true if known in closed form, false to let the integrator difference
  // f in p_k. Sensitivity right-hand side kStateJacobian turns it into df/dp_k = [0 | M^-1 dF]
  // (forward-dynamics operator systems only).
  using ParameterForceDerivative =
      std::function<bool(const SimTK::State& state, int k, Eigen::VectorXd& dforce)>;
  void set_parameter_force_derivative(ParameterForceDerivative derivative);

  // Forward sensitivities s_i = dY/dp_i of parameters p (CVodeSensInit1; the right-hand side as
  // options.right_hand_side says). Difference quotients in p perturb the values read through
  // sensitivity_parameters(), so the right-hand side must take its parameters from there: the
  // input hook applies them to the working state. `scale` (p_scale_i > 0) sets the size of the
  // perturbations and the sensitivities' absolute tolerance; `initial` (NY x Np) is s_i at
  // time(). Call after every Initialize(), which turns sensitivities off. Throws
  // std::invalid_argument for inconsistent sizes or invalid options and NumericalError if
  // CVODES cannot set them up.
  void InitializeSensitivities(const std::vector<double>& p, const std::vector<double>& scale,
                               const Eigen::MatrixXd& initial, const SensitivityOptions& options);
  // The parameter values as CVODES currently perturbs them (p while no quotient is formed).
  const std::vector<double>& sensitivity_parameters() const;
  // s_i at time(), NY x Np (columns per parameter); empty without sensitivities.
  const Eigen::MatrixXd& sensitivities() const;

  // The working state at time(): realized to Velocity after Initialize(), as asked after
  // AdvanceTo(). Throws std::logic_error before the first Initialize().
  const SimTK::State& state() const;
  double time() const;
  IntegratorStatistics statistics() const;
  const IntegratorOptions& options() const;

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mbid::simulation
