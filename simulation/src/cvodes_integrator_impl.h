#pragma once

// CvodesIntegrator::Impl: the integrator's state and its inline right-hand-side helpers.
// Private to simulation/. Its members are defined in cvodes_integrator.cc (set-up, integration,
// statistics, CVODES' callbacks) and cvodes_sensitivities.cc (forward sensitivities); the
// right-hand side's small hot helpers stay inline here, so that both callbacks inline them as
// before.

#include <Simbody.h>
#include <cvodes/cvodes.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>
#include <sunnonlinsol/sunnonlinsol_fixedpoint.h>

#include <algorithm>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "mbid/simulation/cvodes_integrator.h"

namespace mbid::simulation {
namespace internal {

// Failed right-hand-side evaluations tolerated within one AdvanceTo() call. CVODES answers a
// recoverable failure with a smaller step; a failure that persists past some time (e.g. inputs
// that end there) would otherwise make it crawl towards that time until max_steps. Beyond the
// limit every evaluation fails: SUNDIALS 6.4.1's fixed-point solver (Adams) turns an
// unrecoverable RHS failure into a convergence failure, so only a sticky failure ends it.
constexpr int kMaxRhsFailuresPerCall = 100;

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

}  // namespace internal

class CvodesIntegrator::Impl {
 public:
  Impl(const SimTK::System& system, const IntegratorOptions& options);

  void set_time_dependent_inputs(TimeDependentInputs hook) { hook_ = std::move(hook); }
  void set_parameter_force_derivative(ParameterForceDerivative derivative) {
    parameter_force_derivative_ = std::move(derivative);
  }

  void set_multibody_system(const SimTK::MultibodySystem* system) { multibody_ = system; }
  void set_state_derivative(StateDerivative derivative) {
    state_derivative_ = std::move(derivative);
  }

  void set_residual(CvodesIntegrator::Residual residual) { residual_ = std::move(residual); }

  void set_jacobian(Eigen::MatrixXd jacobian) { jacobian_ = std::move(jacobian); }

  void Initialize(SimTK::State state);

  const SimTK::State& AdvanceTo(double t, Realization realization);

  void InitializeSensitivities(const std::vector<double>& p, const std::vector<double>& scale,
                               const Eigen::MatrixXd& initial, const SensitivityOptions& options);

  const std::vector<double>& sensitivity_parameters() const { return sensitivity_p_; }
  const Eigen::MatrixXd& sensitivities() const { return sensitivities_; }

  const SimTK::State& state() const {
    if (!has_state_) {
      throw std::logic_error("CvodesIntegrator::state: call Initialize() first");
    }
    return state_;
  }

  IntegratorStatistics statistics() const;

  const IntegratorOptions& options() const { return options_; }

 private:
  void CreateSolver(int n);

  void Check(int flag, const char* call) const;

  std::string DescribeFailure(int flag, double t_reached, double t_target) const;

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

  // The working state holds exactly this Y (its realized stages then still hold).
  bool SameY(const realtype* y) const {
    const SimTK::Vector& current = state_.getY();
    const int n = current.size();
    if (n == 0 || !current.hasContiguousData()) return false;
    return std::equal(y, y + n, &current[0]);
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
    if (rhs_failures_ > internal::kMaxRhsFailuresPerCall) return -1;
    try {
      body();
      return 0;
    } catch (const std::exception& e) {
      RecordRhsError(t, e.what());
    } catch (...) {
      RecordRhsError(t, "unknown exception");
    }
    return rhs_failures_ > internal::kMaxRhsFailuresPerCall ? -1 : 1;
  }

  // s_i' = J s_i + df/dp_i for CVODES (kStateJacobian), see cvodes_sensitivities.cc.
  static int SensitivityRhs(int count, realtype t, N_Vector y, N_Vector y_dot, N_Vector* s,
                            N_Vector* s_dot, void* user_data, N_Vector, N_Vector);

  // J = df/dY and df/dp at (t, Y) unless they are cached for these very bits.
  // `y_dot` is f(t, Y) (the forward columns' base).
  void UpdateSensitivityJacobian(double t, const realtype* y, const realtype* y_dot);
  // df/dp at a later corrector iterate near J's point, J kept.
  void RefreshParameterDerivative(double t, const realtype* y);
  // J's columns by forward differences of the residual at fixed u' (residual_ set, no z).
  void FormJacobianFromResidual(const realtype* y, const realtype* y_dot);

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
                      void* user_data, N_Vector, N_Vector, N_Vector);

  void RecordRhsError(double t, const char* what) {
    ++rhs_failures_;
    rhs_error_time_ = t;
    rhs_error_ = what;
  }

  // Keeps CVODES' message for the exception instead of printing it to stderr.
  static void ErrorHandler(int error_code, const char* /*module*/, const char* function,
                           char* message, void* user_data);

  const SimTK::System* system_;
  // The same system when it is a MultibodySystem (the forward-dynamics operator's right-hand
  // side, used when the state has no z), else null.
  const SimTK::MultibodySystem* multibody_ = nullptr;
  bool forward_dynamics_operator_ = false;
  StateDerivative state_derivative_;
  CvodesIntegrator::Residual residual_;
  SimTK::Vector u_dot_;                                   // scratch of CalcDerivative
  SimTK::Vector_<SimTK::SpatialVec> body_accelerations_;  // scratch of CalcDerivative
  IntegratorOptions options_;
  IntegratorOptions::Method method_ = IntegratorOptions::Method::kBdf;  // the one running
  TimeDependentInputs hook_;
  ParameterForceDerivative parameter_force_derivative_;
  Eigen::MatrixXd jacobian_;  // empty: difference quotients
  // kStateJacobian's cache: J and df/dp at (jacobian_time_, jacobian_y_), and scratch.
  bool jacobian_cached_ = false;
  // Forward columns through residual_ where it is set (else central).
  bool forward_jacobian_ = false;
  // J came from the residual with every df/dp in closed form: a later corrector iterate of the
  // same step may keep it (RefreshParameterDerivative).
  bool jacobian_reusable_ = false;
  // df/dp is the one at jacobian_y_ (not refreshed at a later iterate since).
  bool parameter_derivative_at_jacobian_y_ = false;
  double jacobian_time_ = 0.0;
  std::vector<double> jacobian_y_;
  Eigen::MatrixXd state_jacobian_;
  Eigen::MatrixXd parameter_derivative_;
  Eigen::VectorXd f_forward_, column_, dforce_;
  SimTK::Vector mobility_force_, m_inv_force_;
  // FormJacobianFromResidual's scratch: M^-1 by columns, dresidual/dY, u' at (t, Y).
  Eigen::MatrixXd m_inverse_, residual_jacobian_;
  Eigen::VectorXd base_residual_, residual_column_;
  long own_sensitivity_rhs_ = 0;
  long sensitivity_jacobians_ = 0;
  long sensitivity_jacobian_reuses_ = 0;
  SimTK::State state_;
  bool has_state_ = false;
  bool initialized_ = false;  // CVODES is ready to advance state_.
  std::string cvodes_message_;
  std::string rhs_error_;
  double rhs_error_time_ = std::numeric_limits<double>::quiet_NaN();
  int rhs_failures_ = 0;

  // Declared in creation order so that they are destroyed in reverse: CVODES memory first,
  // the context last.
  internal::Owned<SUNContext, internal::ContextDeleter> context_;
  internal::Owned<N_Vector, internal::VectorDeleter> y_;
  internal::Owned<SUNMatrix, internal::MatrixDeleter> matrix_;
  internal::Owned<SUNLinearSolver, internal::LinearSolverDeleter> linear_solver_;
  internal::Owned<SUNNonlinearSolver, internal::NonlinearSolverDeleter> nonlinear_solver_;
  // Forward sensitivities (InitializeSensitivities); CVODES points into sensitivity_p_.
  std::vector<double> sensitivity_p_;
  std::vector<double> sensitivity_scale_;
  internal::VectorArray sensitivity_vectors_;
  internal::Owned<SUNNonlinearSolver, internal::NonlinearSolverDeleter>
      sensitivity_nonlinear_solver_;
  Eigen::MatrixXd sensitivities_;
  int sensitivity_count_ = 0;
  internal::Owned<void*, internal::CvodeDeleter> cvode_;
};

}  // namespace mbid::simulation
