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

#include "mbid/common/error.h"

namespace mbid::simulation {
namespace {

// Failed right-hand-side evaluations tolerated within one AdvanceTo() call. CVODES answers a
// recoverable failure with a smaller step; a failure that persists past some time (e.g. inputs
// that end there) would otherwise make it crawl towards that time until max_steps. Beyond the
// limit every evaluation fails: SUNDIALS 6.4.1's fixed-point solver (Adams) turns an
// unrecoverable RHS failure into a convergence failure, so only a sticky failure ends it.
constexpr int kMaxRhsFailuresPerCall = 100;

// Central-difference step of the state Jacobian's columns, relative to max(|Y_j|, 1): roundoff
// (eps |f| / h, |f| holding the dead weight's cancelling terms) and truncation (h^2 times f's
// third derivative, f smooth on the scale of 1 rad, m or rad/s) both near 1e-10 of J. Forward
// steps of 1e-8 left 2e-4 errors in the excavator's weak swing-boom coupling (measured against
// Richardson-extrapolated differences).
constexpr double kJacobianStep = 1e-5;
// Central-difference step of df/dp where no closed form is known, relative to the parameter's
// scale: exact to roundoff (~1e-12) for forces affine in p, O(h^2) ~ 1e-8 otherwise.
constexpr double kParameterStep = 1e-4;

// Owners of SUNDIALS objects; each deleter is the matching SUNDIALS destructor.
struct ContextDeleter {
  void operator()(SUNContext context) const { SUNContext_Free(&context); }
};
struct VectorDeleter {
  void operator()(N_Vector vector) const { N_VDestroy(vector); }
};
struct MatrixDeleter {
  void operator()(SUNMatrix matrix) const { SUNMatDestroy(matrix); }
};
struct LinearSolverDeleter {
  void operator()(SUNLinearSolver solver) const { SUNLinSolFree(solver); }
};
struct NonlinearSolverDeleter {
  void operator()(SUNNonlinearSolver solver) const { SUNNonlinSolFree(solver); }
};
struct CvodeDeleter {
  void operator()(void* memory) const { CVodeFree(&memory); }
};
// An array of `count` vectors (N_VCloneVectorArray), e.g. the sensitivities s_i.
struct VectorArray {
  VectorArray() = default;
  VectorArray(const VectorArray&) = delete;
  VectorArray& operator=(const VectorArray&) = delete;
  ~VectorArray() { Reset(); }
  void Reset(N_Vector* vectors = nullptr, int count = 0) {
    if (vectors_ != nullptr) N_VDestroyVectorArray(vectors_, count_);
    vectors_ = vectors;
    count_ = count;
  }
  N_Vector* get() const { return vectors_; }

 private:
  N_Vector* vectors_ = nullptr;
  int count_ = 0;
};

template <typename Handle, typename Deleter>
using Owned = std::unique_ptr<std::remove_pointer_t<Handle>, Deleter>;

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

class CvodesIntegrator::Impl {
 public:
  Impl(const SimTK::System& system, const IntegratorOptions& options)
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

  void set_time_dependent_inputs(TimeDependentInputs hook) { hook_ = std::move(hook); }
  void set_parameter_force_derivative(ParameterForceDerivative derivative) {
    parameter_force_derivative_ = std::move(derivative);
  }
  void set_multibody_system(const SimTK::MultibodySystem* system) { multibody_ = system; }
  void set_state_derivative(StateDerivative derivative) {
    state_derivative_ = std::move(derivative);
  }
  void set_jacobian(Eigen::MatrixXd jacobian) { jacobian_ = std::move(jacobian); }

  // Takes the state by value: a caller's copy (`initial` may be our own working state) or a
  // moved-in one, which saves a State copy (about four right-hand sides).
  void Initialize(SimTK::State state) {
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

  const SimTK::State& AdvanceTo(double t, Realization realization) {
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

  void InitializeSensitivities(const std::vector<double>& p, const std::vector<double>& scale,
                               const Eigen::MatrixXd& initial, const SensitivityOptions& options) {
    if (!initialized_) {
      throw std::logic_error(
          "CvodesIntegrator::InitializeSensitivities: call Initialize() first (and again after "
          "a failure)");
    }
    const int count = static_cast<int>(p.size());
    const int n = static_cast<int>(N_VGetLength(y_.get()));
    if (count == 0 || scale.size() != p.size() || initial.rows() != n || initial.cols() != count) {
      std::ostringstream why;
      why << "CvodesIntegrator::InitializeSensitivities: " << p.size() << " parameters, "
          << scale.size() << " scales, initial sensitivities " << initial.rows() << " x "
          << initial.cols() << "; expected at least one parameter, one scale each and a " << n
          << " x " << p.size() << " matrix";
      throw std::invalid_argument(why.str());
    }
    for (int i = 0; i < count; ++i) {
      if (!std::isfinite(p[i]) || !(scale[i] > 0 && std::isfinite(scale[i]))) {
        std::ostringstream why;
        why << "CvodesIntegrator::InitializeSensitivities: parameter " << i << " = " << p[i]
            << " with scale " << scale[i] << "; expected a finite value and a finite scale > 0";
        throw std::invalid_argument(why.str());
      }
    }
    std::string why;
    if (!options.IsValid(&why)) {
      throw std::invalid_argument("CvodesIntegrator: invalid SensitivityOptions: " + why);
    }
    const bool fixed_point = nonlinear_solver_ != nullptr;
    const bool own_rhs =
        options.right_hand_side == SensitivityOptions::RightHandSide::kStateJacobian;
    if (!own_rhs && fixed_point &&
        options.corrector == SensitivityOptions::Corrector::kSimultaneous &&
        options.difference_quotient == SensitivityOptions::DifferenceQuotient::kForward) {
      // Found on the crane: SUNDIALS 6.4.1's simultaneous fixed-point corrector with forward
      // quotients evaluates the right-hand side at NaN states at once.
      throw std::invalid_argument(
          "CvodesIntegrator::InitializeSensitivities: Adams with simultaneous corrector and "
          "forward difference quotients fails in SUNDIALS 6.4; expected BDF, the staggered "
          "corrector or centered quotients");
    }
    void* cv = cvode_.get();
    if (sensitivity_count_ > 0) CVodeSensFree(cv);
    sensitivity_count_ = 0;
    sensitivity_nonlinear_solver_.reset();
    sensitivity_vectors_.Reset(N_VCloneVectorArray(count, y_.get()), count);
    if (sensitivity_vectors_.get() == nullptr) {
      throw NumericalError("CVODES", "N_VCloneVectorArray returned NULL");
    }
    for (int i = 0; i < count; ++i) {
      realtype* s = N_VGetArrayPointer(sensitivity_vectors_.get()[i]);
      for (int r = 0; r < n; ++r) s[r] = initial(r, i);
    }
    // CVODES keeps the pointer to p and perturbs it in place for its difference quotients.
    sensitivity_p_ = p;
    sensitivity_scale_ = scale;
    const bool simultaneous = options.corrector == SensitivityOptions::Corrector::kSimultaneous;
    jacobian_cached_ = false;
    const int corrector = simultaneous ? CV_SIMULTANEOUS : CV_STAGGERED;
    if (own_rhs) {
      Check(CVodeSensInit(cv, count, corrector, &Impl::SensitivityRhs, sensitivity_vectors_.get()),
            "CVodeSensInit");
    } else {
      Check(CVodeSensInit1(cv, count, corrector, nullptr, sensitivity_vectors_.get()),
            "CVodeSensInit1");
    }
    sensitivity_count_ = count;
    Check(CVodeSetSensParams(cv, sensitivity_p_.data(), sensitivity_scale_.data(), nullptr),
          "CVodeSetSensParams");
    // s_i has the unit of Y / p_i: the absolute tolerance scales like the sensitivity.
    std::vector<realtype> absolute(count);
    for (int i = 0; i < count; ++i) absolute[i] = options.absolute_tolerance / scale[i];
    Check(CVodeSensSStolerances(cv, options.relative_tolerance, absolute.data()),
          "CVodeSensSStolerances");
    const bool centered =
        options.difference_quotient == SensitivityOptions::DifferenceQuotient::kCentered;
    if (!own_rhs) {
      // rhomax = 0: perturb Y and p together, one quotient per sensitivity.
      Check(CVodeSetSensDQMethod(cv, centered ? CV_CENTERED : CV_FORWARD, 0.0),
            "CVodeSetSensDQMethod");
    }
    Check(CVodeSetSensErrCon(cv, options.error_control ? SUNTRUE : SUNFALSE), "CVodeSetSensErrCon");
    if (fixed_point) {
      // Without a linear solver the sensitivities need fixed-point iteration too; CVODES'
      // default would be Newton.
      sensitivity_nonlinear_solver_.reset(SUNNonlinSol_FixedPointSens(
          simultaneous ? count + 1 : count, y_.get(), 0, context_.get()));
      if (!sensitivity_nonlinear_solver_) {
        throw NumericalError("CVODES", "SUNNonlinSol_FixedPointSens returned NULL");
      }
      Check(simultaneous ? CVodeSetNonlinearSolverSensSim(cv, sensitivity_nonlinear_solver_.get())
                         : CVodeSetNonlinearSolverSensStg(cv, sensitivity_nonlinear_solver_.get()),
            "CVodeSetNonlinearSolverSens");
    }
    sensitivities_ = initial;
  }

  const std::vector<double>& sensitivity_parameters() const { return sensitivity_p_; }
  const Eigen::MatrixXd& sensitivities() const { return sensitivities_; }

  const SimTK::State& state() const {
    if (!has_state_) {
      throw std::logic_error("CvodesIntegrator::state: call Initialize() first");
    }
    return state_;
  }

  IntegratorStatistics statistics() const {
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
    return s;
  }

  const IntegratorOptions& options() const { return options_; }

 private:
  void CreateSolver(int n) {
    // Members referring to others go first.
    cvode_.reset();
    sensitivity_count_ = 0;
    sensitivity_nonlinear_solver_.reset();
    sensitivity_vectors_.Reset();
    sensitivities_.resize(0, 0);
    jacobian_cached_ = false;
    own_sensitivity_rhs_ = 0;
    sensitivity_jacobians_ = 0;
    nonlinear_solver_.reset();
    linear_solver_.reset();
    matrix_.reset();
    y_.reset();
    SUNContext context = context_.get();

    y_.reset(N_VNew_Serial(n, context));
    if (!y_) throw NumericalError("CVODES", "N_VNew_Serial returned NULL");
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
      const int flag = CVodeSetLinearSolver(cv, linear_solver_.get(), matrix_.get());
      if (flag != CVLS_SUCCESS) {
        throw NumericalError("CVODES",
                             "CVodeSetLinearSolver failed: " + LinearSolverFlagName(flag));
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

  void Check(int flag, const char* call) const {
    if (flag < 0) {
      std::string reason = std::string(call) + " failed: " + FlagName(flag);
      if (!cvodes_message_.empty()) reason += " (" + cvodes_message_ + ")";
      throw NumericalError("CVODES", reason);
    }
  }

  std::string DescribeFailure(int flag, double t_reached, double t_target) const {
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

  void CopyToState(const realtype* y) {
    SimTK::Vector& y_state = state_.updY();
    const int n = y_state.size();
    for (int i = 0; i < n; ++i) y_state[i] = y[i];
  }

  void SetTimeAndY(double t, const realtype* y) {
    // setTime() invalidates the Time stage even for the same time; the corrector iterations
    // and difference quotients of one step all evaluate at one t.
    if (state_.getTime() != t) state_.setTime(t);
    CopyToState(y);
    if (hook_) hook_(state_);
  }

  // Y' = f(t, Y) for CVODES: Simbody's own derivative of [q | u | z].
  static int Rhs(realtype t, N_Vector y, N_Vector y_dot, void* user_data) {
    auto* self = static_cast<Impl*>(user_data);
    return self->Guarded(t, [&] {
      self->SetTimeAndY(t, N_VGetArrayPointer(y));
      self->CalcDerivative(N_VGetArrayPointer(y_dot));
    });
  }

  // Runs a callback's `body` for CVODES: an exception is recoverable (CVODES retries with a
  // smaller step) until the failure persists.
  template <typename Body>
  int Guarded(double t, Body&& body) {
    if (rhs_failures_ > kMaxRhsFailuresPerCall) return -1;
    try {
      body();
      return 0;
    } catch (const std::exception& e) {
      RecordRhsError(t, e.what());
    } catch (...) {
      RecordRhsError(t, "unknown exception");
    }
    return rhs_failures_ > kMaxRhsFailuresPerCall ? -1 : 1;
  }

  // s_i' = J s_i + df/dp_i for CVODES (kStateJacobian); J and df/dp come from the cache of
  // (t, Y), so every sensitivity and corrector iteration at one point shares one J.
  static int SensitivityRhs(int count, realtype t, N_Vector y, N_Vector /*y_dot*/, N_Vector* s,
                            N_Vector* s_dot, void* user_data, N_Vector, N_Vector) {
    auto* self = static_cast<Impl*>(user_data);
    return self->Guarded(t, [&] {
      self->UpdateSensitivityJacobian(t, N_VGetArrayPointer(y));
      const Eigen::Index ny = self->state_jacobian_.rows();
      for (int i = 0; i < count; ++i) {
        const Eigen::Map<const Eigen::VectorXd> s_i(N_VGetArrayPointer(s[i]), ny);
        Eigen::Map<Eigen::VectorXd> s_dot_i(N_VGetArrayPointer(s_dot[i]), ny);
        s_dot_i.noalias() = self->state_jacobian_ * s_i;
        s_dot_i += self->parameter_derivative_.col(i);
      }
    });
  }

  // J = df/dY and df/dp at (t, Y) unless they are cached for these very bits.
  void UpdateSensitivityJacobian(double t, const realtype* y) {
    const int ny = state_.getNY();
    if (jacobian_cached_ && t == jacobian_time_ && std::equal(y, y + ny, jacobian_y_.data())) {
      return;
    }
    jacobian_cached_ = false;
    const int nq = state_.getNQ();
    const int nu = state_.getNU();
    const int count = sensitivity_count_;
    state_jacobian_.resize(ny, ny);
    parameter_derivative_.resize(ny, count);
    f_forward_.resize(ny);
    column_.resize(ny);
    SetTimeAndY(t, y);  // nominal parameters: the input hook applies sensitivity_p_ as it is
    system_->realize(state_, SimTK::Stage::Position);  // for M^-1 below
    // df/dp_k = [0 | M^-1 dF/dp_k] where the forces' derivative is known, while the state is
    // realized at (t, Y) (M^-1 reuses its articulated-body inertias); the rest by differences.
    std::vector<int> differenced;
    mobility_force_.resize(nu);
    for (int k = 0; k < count; ++k) {
      bool known = forward_dynamics_operator_ && parameter_force_derivative_ &&
                   parameter_force_derivative_(state_, k, dforce_);
      if (known && dforce_.size() != nu) {
        throw std::logic_error(
            "CvodesIntegrator: the parameter force derivative has the wrong size; expected NU "
            "entries");
      }
      if (!known) {
        differenced.push_back(k);
        continue;
      }
      parameter_derivative_.col(k).setZero();
      for (int i = 0; i < nu; ++i) mobility_force_[i] = dforce_[i];
      multibody_->getMatterSubsystem().multiplyByMInv(state_, mobility_force_, m_inv_force_);
      for (int i = 0; i < nu; ++i) parameter_derivative_(nq + i, k) = m_inv_force_[i];
    }
    // Columns of J: only the perturbed entry changes, so a speed keeps the Position stage.
    for (int j = 0; j < ny; ++j) {
      const double h = kJacobianStep * std::max(std::abs(y[j]), 1.0);
      const double forward = y[j] + h;
      const double backward = y[j] - h;
      SetEntry(j, nq, nu, forward);
      CalcDerivative(column_.data());
      f_forward_ = column_;
      SetEntry(j, nq, nu, backward);
      CalcDerivative(column_.data());
      SetEntry(j, nq, nu, y[j]);
      state_jacobian_.col(j) = (f_forward_ - column_) / (forward - backward);
    }
    own_sensitivity_rhs_ += 2 * ny;
    for (int k : differenced) {
      // The input hook reads the parameters from sensitivity_p_ (as for CVODES' quotients).
      const double nominal = sensitivity_p_[k];
      const double h = kParameterStep * sensitivity_scale_[k];
      auto evaluate_at = [&](double value) {
        sensitivity_p_[k] = value;
        if (hook_) hook_(state_);
        CalcDerivative(column_.data());
        ++own_sensitivity_rhs_;
        return Eigen::VectorXd(column_);
      };
      try {
        const Eigen::VectorXd plus = evaluate_at(nominal + h);
        parameter_derivative_.col(k) = (plus - evaluate_at(nominal - h)) / (2 * h);
      } catch (...) {
        sensitivity_p_[k] = nominal;
        throw;
      }
      sensitivity_p_[k] = nominal;
      if (hook_) hook_(state_);
    }
    ++sensitivity_jacobians_;
    jacobian_time_ = t;
    jacobian_y_.assign(y, y + ny);
    jacobian_cached_ = true;
  }

  // Y_j of the working state, through q, u or z so that only the stages above it are redone.
  void SetEntry(int j, int nq, int nu, double value) {
    if (j < nq) {
      state_.updQ()[j] = value;
    } else if (j < nq + nu) {
      state_.updU()[j - nq] = value;
    } else {
      state_.updZ()[j - nq - nu] = value;
    }
  }

  // Y' of the working state (t and Y set, inputs applied) into `out` (NY values).
  void CalcDerivative(realtype* out) {
    if (!forward_dynamics_operator_) {
      system_->realize(state_, SimTK::Stage::Acceleration);
      const SimTK::Vector& y_dot = state_.getYDot();
      for (int i = 0; i < y_dot.size(); ++i) out[i] = y_dot[i];
      return;
    }
    if (state_derivative_) {
      system_->realize(state_, SimTK::Stage::Velocity);
      state_derivative_(state_, out);
      return;
    }
    system_->realize(state_, SimTK::Stage::Dynamics);
    multibody_->getMatterSubsystem().calcAccelerationIgnoringConstraints(
        state_, multibody_->getMobilityForces(state_, SimTK::Stage::Dynamics),
        multibody_->getRigidBodyForces(state_, SimTK::Stage::Dynamics), u_dot_,
        body_accelerations_);
    const SimTK::Vector& q_dot = state_.getQDot();
    const int nq = q_dot.size();
    for (int i = 0; i < nq; ++i) out[i] = q_dot[i];
    for (int i = 0; i < u_dot_.size(); ++i) out[nq + i] = u_dot_[i];
  }

  // The given constant Jacobian (dense, column-major).
  static int Jacobian(realtype /*t*/, N_Vector /*y*/, N_Vector /*f*/, SUNMatrix jacobian,
                      void* user_data, N_Vector, N_Vector, N_Vector) {
    const Eigen::MatrixXd& given = static_cast<Impl*>(user_data)->jacobian_;
    for (Eigen::Index j = 0; j < given.cols(); ++j) {
      realtype* column = SM_COLUMN_D(jacobian, j);
      for (Eigen::Index i = 0; i < given.rows(); ++i) column[i] = given(i, j);
    }
    return 0;
  }

  void RecordRhsError(double t, const char* what) {
    ++rhs_failures_;
    rhs_error_time_ = t;
    rhs_error_ = what;
  }

  // Keeps CVODES' message for the exception instead of printing it to stderr. Warnings
  // (e.g. t + h == t) are dropped: if they matter, an error flag follows.
  static void ErrorHandler(int error_code, const char* /*module*/, const char* function,
                           char* message, void* user_data) {
    if (error_code == CV_WARNING) return;
    auto* self = static_cast<Impl*>(user_data);
    self->cvodes_message_ =
        std::string(function ? function : "CVODES") + ": " + (message ? message : "");
  }

  const SimTK::System* system_;
  // The same system when it is a MultibodySystem (the forward-dynamics operator's right-hand
  // side, used when the state has no z), else null.
  const SimTK::MultibodySystem* multibody_ = nullptr;
  bool forward_dynamics_operator_ = false;
  StateDerivative state_derivative_;
  SimTK::Vector u_dot_;                                   // scratch of CalcDerivative
  SimTK::Vector_<SimTK::SpatialVec> body_accelerations_;  // scratch of CalcDerivative
  IntegratorOptions options_;
  IntegratorOptions::Method method_ = IntegratorOptions::Method::kBdf;  // the one running
  TimeDependentInputs hook_;
  ParameterForceDerivative parameter_force_derivative_;
  Eigen::MatrixXd jacobian_;  // empty: difference quotients
  // kStateJacobian's cache: J and df/dp at (jacobian_time_, jacobian_y_), and scratch.
  bool jacobian_cached_ = false;
  double jacobian_time_ = 0.0;
  std::vector<double> jacobian_y_;
  Eigen::MatrixXd state_jacobian_;
  Eigen::MatrixXd parameter_derivative_;
  Eigen::VectorXd f_forward_, column_, dforce_;
  SimTK::Vector mobility_force_, m_inv_force_;
  long own_sensitivity_rhs_ = 0;
  long sensitivity_jacobians_ = 0;
  SimTK::State state_;
  bool has_state_ = false;
  bool initialized_ = false;  // CVODES is ready to advance state_.
  std::string cvodes_message_;
  std::string rhs_error_;
  double rhs_error_time_ = std::numeric_limits<double>::quiet_NaN();
  int rhs_failures_ = 0;

  // Declared in creation order so that they are destroyed in reverse: CVODES memory first,
  // the context last.
  Owned<SUNContext, ContextDeleter> context_;
  Owned<N_Vector, VectorDeleter> y_;
  Owned<SUNMatrix, MatrixDeleter> matrix_;
  Owned<SUNLinearSolver, LinearSolverDeleter> linear_solver_;
  Owned<SUNNonlinearSolver, NonlinearSolverDeleter> nonlinear_solver_;
  // Forward sensitivities (InitializeSensitivities); CVODES points into sensitivity_p_.
  std::vector<double> sensitivity_p_;
  std::vector<double> sensitivity_scale_;
  VectorArray sensitivity_vectors_;
  Owned<SUNNonlinearSolver, NonlinearSolverDeleter> sensitivity_nonlinear_solver_;
  Eigen::MatrixXd sensitivities_;
  int sensitivity_count_ = 0;
  Owned<void*, CvodeDeleter> cvode_;
};

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
