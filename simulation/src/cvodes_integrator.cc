#include "mbid/simulation/cvodes_integrator.h"

#include <Simbody.h>
#include <cvodes/cvodes.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>
#include <sunnonlinsol/sunnonlinsol_fixedpoint.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "cvodes_integrator_impl.h"
#include "dense_solve.h"
#include "mbid/common/error.h"
#include "mbid/common/stop.h"
#include "serial_vector_ops.h"

namespace mbid::simulation {
namespace {
// CVodeGet*ReturnFlagName returns a malloc'ed string that the caller frees.
std::string TakeName(char* name) {
  if (name == nullptr) return "unknown flag";
  std::string result(name);
  std::free(name);
  return result;
}

std::string FlagName(int flag) { return TakeName(CVodeGetReturnFlagName(flag)); }
std::string LinearSolverFlagName(int flag) { return TakeName(CVodeGetLinReturnFlagName(flag)); }

}  // namespace

CvodesIntegrator::Impl::Impl(const SimTK::System& system, const IntegratorOptions& options)
    : system_(&system), options_(options) {
  std::string why;
  if (!options.IsValid(&why)) {
    throw std::invalid_argument("CvodesIntegrator: invalid IntegratorOptions: " + why);
  }
  if (!system.systemTopologyHasBeenRealized()) {
    throw std::invalid_argument(
        "CvodesIntegrator: the system is not realized to Topology; expected "
        "realizeTopology() before building the integrator");
  }
  SUNContext context = nullptr;
  if (SUNContext_Create(nullptr, &context) != 0 || context == nullptr) {
    throw NumericalError("CVODES", "SUNContext_Create failed");
  }
  context_.reset(context);
}

// Takes the state by value: a caller's copy (`initial` may be our own working state) or a
// moved-in one, which saves a State copy (about four right-hand sides).
void CvodesIntegrator::Impl::Initialize(SimTK::State state) {
  try {
    system_->realize(state, SimTK::Stage::Instance);
  } catch (const std::exception& e) {
    throw std::invalid_argument(
        std::string("CvodesIntegrator::Initialize: the state does not fit the system: ") +
        e.what());
  }
  if (state.getNQ() != state.getNU()) {
    std::ostringstream why;
    why << "CvodesIntegrator::Initialize: the system has quaternions (nq = " << state.getNQ()
        << ", nu = " << state.getNU()
        << "), which would need normalization; expected nq == nu (Pin, Universal, "
           "Slider ... mobilizers)";
    throw std::invalid_argument(why.str());
  }
  if (state.getNYErr() != 0 || state.getNMultipliers() != 0) {
    std::ostringstream why;
    why << "CvodesIntegrator::Initialize: the system has constraints (" << state.getNYErr()
        << " position/velocity errors, " << state.getNMultipliers()
        << " multipliers), which would need projection; expected none";
    throw std::invalid_argument(why.str());
  }
  const int n = state.getNY();
  if (n == 0) {
    throw std::invalid_argument(
        "CvodesIntegrator::Initialize: the state has no continuous variables; expected "
        "q, u or z");
  }
  if (jacobian_.size() > 0 && (jacobian_.rows() != n || jacobian_.cols() != n)) {
    std::ostringstream why;
    why << "CvodesIntegrator::Initialize: the Jacobian is " << jacobian_.rows() << " x "
        << jacobian_.cols() << "; expected " << n << " x " << n << " (NY) or none";
    throw std::invalid_argument(why.str());
  }
  // Positions and velocities do not depend on the inputs: realizing them needs no hook.
  system_->realize(state, SimTK::Stage::Velocity);
  // Auxiliary states get their derivatives only from the Acceleration stage.
  forward_dynamics_operator_ = multibody_ != nullptr && state.getNZ() == 0;
  initialized_ = false;
  state_ = std::move(state);
  has_state_ = true;
  rhs_error_.clear();
  cvodes_message_.clear();
  CreateSolver(n);
  initialized_ = true;
}

const SimTK::State& CvodesIntegrator::Impl::AdvanceTo(double t, Realization realization) {
  if (!initialized_) {
    throw std::logic_error(
        "CvodesIntegrator::AdvanceTo: not initialized; call Initialize() first (and again "
        "after a failure)");
  }
  const double t_now = state_.getTime();
  if (!(t >= t_now) || !std::isfinite(t)) {
    std::ostringstream why;
    why.precision(17);
    why << "CvodesIntegrator::AdvanceTo: t = " << t << " s; expected a finite time >= " << t_now
        << " s";
    throw std::invalid_argument(why.str());
  }
  ThrowIfStopRequested();  // a Python user's Ctrl-C (stop.h)
  if (t > t_now) {
    // By default CVODES stops exactly at t rather than stepping past it and interpolating:
    // inputs that change between calls then never act before their time, and the returned
    // state is a step end point whose error the tolerances control.
    if (!options_.interpolate_outputs) {
      Check(CVodeSetStopTime(cvode_.get(), t), "CVodeSetStopTime");
    }
    rhs_failures_ = 0;
    realtype t_reached = t_now;
    const int flag = CVode(cvode_.get(), t, y_.get(), &t_reached, CV_NORMAL);
    if (flag < 0) {
      initialized_ = false;
      // Leave the last point CVODES reached in the state, for diagnosis.
      state_.setTime(t_reached);
      CopyToState(N_VGetArrayPointer(y_.get()));
      throw NumericalError("CVODES", DescribeFailure(flag, t_reached, t));
    }
    // At t itself (a stop time, or interpolated); before the first step they are the initial
    // ones, which InitializeSensitivities stored.
    if (sensitivity_count_ > 0) {
      realtype t_sensitivities = t;
      Check(CVodeGetSens(cvode_.get(), &t_sensitivities, sensitivity_vectors_.get()),
            "CVodeGetSens");
      for (int i = 0; i < sensitivity_count_; ++i) {
        const realtype* s = N_VGetArrayPointer(sensitivity_vectors_.get()[i]);
        for (Eigen::Index r = 0; r < sensitivities_.rows(); ++r) sensitivities_(r, i) = s[r];
      }
    }
  }
  SetTimeAndY(t, N_VGetArrayPointer(y_.get()));
  if (realization != Realization::kNone) {
    system_->realize(state_, realization == Realization::kPositions ? SimTK::Stage::Position
                                                                    : SimTK::Stage::Acceleration);
  }
  return state_;
}

IntegratorStatistics CvodesIntegrator::Impl::statistics() const {
  IntegratorStatistics s;
  if (!cvode_) return s;
  void* cv = cvode_.get();
  int current_order = 0;
  realtype first_step = 0, last_step = 0, current_step = 0, current_time = 0;
  CVodeGetIntegratorStats(cv, &s.steps, &s.rhs_evaluations, &s.linear_solver_setups,
                          &s.error_test_failures, &s.last_order, &current_order, &first_step,
                          &last_step, &current_step, &current_time);
  s.last_step_s = last_step;
  s.method = method_;
  CVodeGetNonlinSolvStats(cv, &s.nonlinear_iterations, &s.nonlinear_convergence_failures);
  if (linear_solver_) {
    CVodeGetNumJacEvals(cv, &s.jacobian_evaluations);
    CVodeGetNumLinRhsEvals(cv, &s.rhs_evaluations_for_jacobian);
  }
  if (sensitivity_count_ > 0) CVodeGetNumRhsEvalsSens(cv, &s.rhs_evaluations_for_sensitivities);
  s.rhs_evaluations_for_sensitivities += own_sensitivity_rhs_;
  s.sensitivity_jacobians = sensitivity_jacobians_;
  s.sensitivity_jacobian_reuses = sensitivity_jacobian_reuses_;
  return s;
}

void CvodesIntegrator::Impl::CreateSolver(int n) {
  // Members referring to others go first.
  cvode_.reset();
  sensitivity_count_ = 0;
  sensitivity_nonlinear_solver_.reset();
  sensitivity_vectors_.Reset();
  sensitivities_.resize(0, 0);
  jacobian_cached_ = false;
  own_sensitivity_rhs_ = 0;
  sensitivity_jacobians_ = 0;
  sensitivity_jacobian_reuses_ = 0;
  nonlinear_solver_.reset();
  linear_solver_.reset();
  matrix_.reset();
  y_.reset();
  SUNContext context = context_.get();

  y_.reset(N_VNew_Serial(n, context));
  if (!y_) throw NumericalError("CVODES", "N_VNew_Serial returned NULL");
  // Before CVodeInit: CVODES' own vectors (and the sensitivities) are clones and share the ops.
  internal::UseOptimizedSerialOps(y_.get());
  const SimTK::Vector& y0 = state_.getY();
  realtype* y = N_VGetArrayPointer(y_.get());
  for (int i = 0; i < n; ++i) y[i] = y0[i];

  method_ = options_.method == IntegratorOptions::Method::kAuto ? ChooseMethod(jacobian_)
                                                                : options_.method;
  const bool bdf = method_ == IntegratorOptions::Method::kBdf;
  cvode_.reset(CVodeCreate(bdf ? CV_BDF : CV_ADAMS, context));
  if (!cvode_) throw NumericalError("CVODES", "CVodeCreate returned NULL");
  void* cv = cvode_.get();
  Check(CVodeSetErrHandlerFn(cv, &Impl::ErrorHandler, this), "CVodeSetErrHandlerFn");
  Check(CVodeInit(cv, &Impl::Rhs, state_.getTime(), y_.get()), "CVodeInit");
  Check(CVodeSetUserData(cv, this), "CVodeSetUserData");
  Check(CVodeSStolerances(cv, options_.relative_tolerance, options_.absolute_tolerance),
        "CVodeSStolerances");
  Check(CVodeSetMaxNumSteps(cv, options_.max_steps), "CVodeSetMaxNumSteps");
  if (options_.max_step_s > 0) Check(CVodeSetMaxStep(cv, options_.max_step_s), "CVodeSetMaxStep");

  const bool given_jacobian = jacobian_.size() > 0;
  if (bdf || given_jacobian) {
    matrix_.reset(SUNDenseMatrix(n, n, context));
    if (!matrix_) throw NumericalError("CVODES", "SUNDenseMatrix returned NULL");
    linear_solver_.reset(SUNLinSol_Dense(y_.get(), matrix_.get(), context));
    if (!linear_solver_) throw NumericalError("CVODES", "SUNLinSol_Dense returned NULL");
    internal::UseOptimizedDenseSolve(linear_solver_.get());
    const int flag = CVodeSetLinearSolver(cv, linear_solver_.get(), matrix_.get());
    if (flag != CVLS_SUCCESS) {
      throw NumericalError("CVODES", "CVodeSetLinearSolver failed: " + LinearSolverFlagName(flag));
    }
    if (given_jacobian) Check(CVodeSetJacFn(cv, &Impl::Jacobian), "CVodeSetJacFn");
  } else {
    // Without a given Jacobian, Adams (for non-stiff models) iterates to a fixed point instead
    // of spending n extra RHS calls per difference-quotient Jacobian on Newton.
    nonlinear_solver_.reset(SUNNonlinSol_FixedPoint(y_.get(), 0, context));
    if (!nonlinear_solver_) {
      throw NumericalError("CVODES", "SUNNonlinSol_FixedPoint returned NULL");
    }
    Check(CVodeSetNonlinearSolver(cv, nonlinear_solver_.get()), "CVodeSetNonlinearSolver");
  }
}

void CvodesIntegrator::Impl::Check(int flag, const char* call) const {
  if (flag < 0) {
    std::string reason = std::string(call) + " failed: " + FlagName(flag);
    if (!cvodes_message_.empty()) reason += " (" + cvodes_message_ + ")";
    throw NumericalError("CVODES", reason);
  }
}

std::string CvodesIntegrator::Impl::DescribeFailure(int flag, double t_reached,
                                                    double t_target) const {
  std::ostringstream reason;
  reason.precision(10);
  reason << FlagName(flag) << " at t = " << t_reached << " s while advancing to " << t_target
         << " s";
  if (!cvodes_message_.empty()) reason << ": " << cvodes_message_;
  if (!rhs_error_.empty()) {
    reason << "; the right-hand side failed " << rhs_failures_
           << " time(s) in this call, last at t = " << rhs_error_time_ << " s: " << rhs_error_;
  }
  return reason.str();
}

// The given constant Jacobian (dense, column-major).
int CvodesIntegrator::Impl::Jacobian(realtype /*t*/, N_Vector /*y*/, N_Vector /*f*/,
                                     SUNMatrix jacobian, void* user_data, N_Vector, N_Vector,
                                     N_Vector) {
  const Eigen::MatrixXd& given = static_cast<Impl*>(user_data)->jacobian_;
  for (Eigen::Index j = 0; j < given.cols(); ++j) {
    realtype* column = SM_COLUMN_D(jacobian, j);
    for (Eigen::Index i = 0; i < given.rows(); ++i) column[i] = given(i, j);
  }
  return 0;
}

// Keeps CVODES' message for the exception instead of printing it to stderr. Warnings
// (e.g. t + h == t) are dropped: if they matter, an error flag follows.
void CvodesIntegrator::Impl::ErrorHandler(int error_code, const char* /*module*/,
                                          const char* function, char* message, void* user_data) {
  if (error_code == CV_WARNING) return;
  auto* self = static_cast<Impl*>(user_data);
  self->cvodes_message_ =
      std::string(function ? function : "CVODES") + ": " + (message ? message : "");
}

CvodesIntegrator::CvodesIntegrator(const SimTK::System& system, const IntegratorOptions& options)
    : impl_(std::make_unique<Impl>(system, options)) {}
CvodesIntegrator::CvodesIntegrator(const SimTK::MultibodySystem& system,
                                   const IntegratorOptions& options)
    : impl_(std::make_unique<Impl>(system, options)) {
  impl_->set_multibody_system(&system);
}
CvodesIntegrator::~CvodesIntegrator() = default;
CvodesIntegrator::CvodesIntegrator(CvodesIntegrator&&) noexcept = default;
CvodesIntegrator& CvodesIntegrator::operator=(CvodesIntegrator&&) noexcept = default;

void CvodesIntegrator::set_time_dependent_inputs(TimeDependentInputs hook) {
  impl_->set_time_dependent_inputs(std::move(hook));
}
void CvodesIntegrator::set_parameter_force_derivative(ParameterForceDerivative derivative) {
  impl_->set_parameter_force_derivative(std::move(derivative));
}
void CvodesIntegrator::set_state_derivative(StateDerivative derivative) {
  impl_->set_state_derivative(std::move(derivative));
}
void CvodesIntegrator::set_residual(Residual residual) { impl_->set_residual(std::move(residual)); }
void CvodesIntegrator::set_jacobian(Eigen::MatrixXd jacobian) {
  impl_->set_jacobian(std::move(jacobian));
}
void CvodesIntegrator::Initialize(const SimTK::State& initial) {
  impl_->Initialize(SimTK::State(initial));
}
void CvodesIntegrator::Initialize(SimTK::State&& initial) { impl_->Initialize(std::move(initial)); }
const SimTK::State& CvodesIntegrator::AdvanceTo(double t, Realization realization) {
  return impl_->AdvanceTo(t, realization);
}
void CvodesIntegrator::InitializeSensitivities(const std::vector<double>& p,
                                               const std::vector<double>& scale,
                                               const Eigen::MatrixXd& initial,
                                               const SensitivityOptions& options) {
  impl_->InitializeSensitivities(p, scale, initial, options);
}
const std::vector<double>& CvodesIntegrator::sensitivity_parameters() const {
  return impl_->sensitivity_parameters();
}
const Eigen::MatrixXd& CvodesIntegrator::sensitivities() const { return impl_->sensitivities(); }
const SimTK::State& CvodesIntegrator::state() const { return impl_->state(); }
double CvodesIntegrator::time() const { return impl_->state().getTime(); }
IntegratorStatistics CvodesIntegrator::statistics() const { return impl_->statistics(); }
const IntegratorOptions& CvodesIntegrator::options() const { return impl_->options(); }

}  // namespace mbid::simulation
