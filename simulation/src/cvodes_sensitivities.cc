// CvodesIntegrator's forward sensitivities: their set-up and kStateJacobian's right-hand side.
#include <Simbody.h>
#include <cvodes/cvodes.h>
#include <nvector/nvector_serial.h>
#include <sunnonlinsol/sunnonlinsol_fixedpoint.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "cvodes_integrator_impl.h"
#include "mbid/common/error.h"

namespace mbid::simulation {
namespace {

// Central-difference step of the state Jacobian's columns, relative to max(|Y_j|, 1): roundoff
// (eps |f| / h, |f| holding the dead weight's cancelling terms) and truncation (h^2 times f's
// third derivative, f smooth on the scale of 1 rad, m or rad/s) both near 1e-10 of J. Forward
// steps of 1e-8 left 2e-4 errors in the excavator's weak swing-boom coupling (measured against
// Richardson-extrapolated differences).
constexpr double kJacobianStep = 1e-5;
// Forward-difference step of J's columns (from the f(t, Y) CVODES hands over, through the
// model's residual; central columns without one), relative to max(|Y_j|, 1), chosen against
// Richardson-extrapolated differences (sensitivity_test.cc): at 1e-8 roundoff left 1.2e-4 in the
// excavator's weak swing-boom coupling, at 1e-6 truncation 4.8e-7 on the crane; 1e-7 keeps both
// below the forward quotients' errors.
constexpr double kForwardJacobianStep = 1e-7;
// A later corrector iterate of the same step within this distance of J's point (relative to
// max(|Y_j|, 1)) keeps J: it moves J by a tenth of the forward step's own truncation error at
// most. Newton's corrections within a step are ~rtol |Y|, far below it.
constexpr double kJacobianReuseDistance = 1e-8;
// Central-difference step of df/dp where no closed form is known, relative to the parameter's
// scale: exact to roundoff (~1e-12) for forces affine in p, O(h^2) ~ 1e-8 otherwise.
constexpr double kParameterStep = 1e-4;
}  // namespace

void CvodesIntegrator::Impl::InitializeSensitivities(const std::vector<double>& p,
                                                     const std::vector<double>& scale,
                                                     const Eigen::MatrixXd& initial,
                                                     const SensitivityOptions& options) {
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
      options.right_hand_side == SensitivityOptions::RightHandSide::kStateJacobian ||
      (options.right_hand_side == SensitivityOptions::RightHandSide::kAuto && count >= n);
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
  forward_jacobian_ =
      options.difference_quotient == SensitivityOptions::DifferenceQuotient::kForward;
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
    sensitivity_nonlinear_solver_.reset(
        SUNNonlinSol_FixedPointSens(simultaneous ? count + 1 : count, y_.get(), 0, context_.get()));
    if (!sensitivity_nonlinear_solver_) {
      throw NumericalError("CVODES", "SUNNonlinSol_FixedPointSens returned NULL");
    }
    Check(simultaneous ? CVodeSetNonlinearSolverSensSim(cv, sensitivity_nonlinear_solver_.get())
                       : CVodeSetNonlinearSolverSensStg(cv, sensitivity_nonlinear_solver_.get()),
          "CVodeSetNonlinearSolverSens");
  }
  sensitivities_ = initial;
}

// s_i' = J s_i + df/dp_i for CVODES (kStateJacobian); J and df/dp come from the cache of
// (t, Y), so every sensitivity and corrector iteration at one point shares one J.
int CvodesIntegrator::Impl::SensitivityRhs(int count, realtype t, N_Vector y, N_Vector y_dot,
                                           N_Vector* s, N_Vector* s_dot, void* user_data, N_Vector,
                                           N_Vector) {
  auto* self = static_cast<Impl*>(user_data);
  return self->Guarded(t, [&] {
    self->UpdateSensitivityJacobian(t, N_VGetArrayPointer(y), N_VGetArrayPointer(y_dot));
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
void CvodesIntegrator::Impl::UpdateSensitivityJacobian(double t, const realtype* y,
                                                       const realtype* y_dot) {
  const int ny = state_.getNY();
  if (jacobian_cached_ && t == jacobian_time_) {
    if (parameter_derivative_at_jacobian_y_ && std::equal(y, y + ny, jacobian_y_.data())) return;
    if (jacobian_reusable_) {
      bool near = true;
      for (int j = 0; j < ny && near; ++j) {
        near = std::abs(y[j] - jacobian_y_[j]) <=
               kJacobianReuseDistance * std::max(std::abs(jacobian_y_[j]), 1.0);
      }
      if (near) {
        RefreshParameterDerivative(t, y);
        return;
      }
    }
  }
  jacobian_cached_ = false;
  jacobian_reusable_ = false;
  const int nq = state_.getNQ();
  const int nu = state_.getNU();
  const int count = sensitivity_count_;
  state_jacobian_.resize(ny, ny);
  parameter_derivative_.resize(ny, count);
  f_forward_.resize(ny);
  column_.resize(ny);
  // Nominal parameters: the input hook applies sensitivity_p_ as it is. CVODES evaluates f at
  // this very (t, Y) just before: its realized stages (and M^-1's articulated-body inertias)
  // serve J when the state still holds it.
  if (state_.getTime() == t && SameY(y)) {
    if (hook_) hook_(state_);
  } else {
    SetTimeAndY(t, y);
  }
  const bool from_residual =
      forward_jacobian_ && residual_ && forward_dynamics_operator_ && state_.getNZ() == 0;
  system_->realize(state_, from_residual ? SimTK::Stage::Velocity : SimTK::Stage::Position);
  if (from_residual) {
    const SimTK::SimbodyMatterSubsystem& matter = multibody_->getMatterSubsystem();
    // M^-1 by columns, one operator call per mobility: it serves df/dp and the acceleration
    // rows of J.
    m_inverse_.resize(nu, nu);
    mobility_force_.resize(nu);
    for (int i = 0; i < nu; ++i) {
      mobility_force_ = 0;
      mobility_force_[i] = 1;
      matter.multiplyByMInv(state_, mobility_force_, m_inv_force_);
      for (int r = 0; r < nu; ++r) m_inverse_(r, i) = m_inv_force_[r];
    }
  }
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
    if (from_residual) {
      parameter_derivative_.col(k).segment(nq, nu).noalias() = m_inverse_ * dforce_;
      continue;
    }
    for (int i = 0; i < nu; ++i) mobility_force_[i] = dforce_[i];
    multibody_->getMatterSubsystem().multiplyByMInv(state_, mobility_force_, m_inv_force_);
    for (int i = 0; i < nu; ++i) parameter_derivative_(nq + i, k) = m_inv_force_[i];
  }
  if (from_residual) {
    FormJacobianFromResidual(y, y_dot);
  } else {
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
  }
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
  jacobian_reusable_ = from_residual && differenced.empty();
  parameter_derivative_at_jacobian_y_ = true;
  jacobian_time_ = t;
  jacobian_y_.assign(y, y + ny);
  jacobian_cached_ = true;
}

// df/dp at a later corrector iterate (t, Y) of J's step, J kept: the closed-form dF/dp at the new
// q and u times the M^-1 of J's point (the iterates differ by ~rtol |Y|).
void CvodesIntegrator::Impl::RefreshParameterDerivative(double t, const realtype* y) {
  const int nq = state_.getNQ();
  const int nu = state_.getNU();
  SetTimeAndY(t, y);
  system_->realize(state_, SimTK::Stage::Position);
  for (int k = 0; k < sensitivity_count_; ++k) {
    parameter_derivative_.col(k).setZero();
    if (!parameter_force_derivative_(state_, k, dforce_) || dforce_.size() != nu) {
      throw std::logic_error("CvodesIntegrator: a parameter force derivative went missing");
    }
    parameter_derivative_.col(k).segment(nq, nu).noalias() = m_inverse_ * dforce_;
  }
  parameter_derivative_at_jacobian_y_ = std::equal(y, y + nq + nu, jacobian_y_.data());
  ++sensitivity_jacobian_reuses_;
}

// J by forward differences from (t, Y), realized to Velocity: q' = N(q) u read from the state,
// u' through the residual r(Y, u') = M u' + f_inertial - f_applied, which vanishes at the
// u' of f(t, Y): du'/dY = -M^-1 dr/dY at fixed u' (the implicit function theorem), so each
// column costs a realization and an inverse dynamics, and M^-1 is applied once to all of them.
// Speeds first: they keep the Position stage.
void CvodesIntegrator::Impl::FormJacobianFromResidual(const realtype* y, const realtype* y_dot) {
  const int nq = state_.getNQ();
  const int nu = state_.getNU();
  const int ny = nq + nu;
  const double* base_u_dot = y_dot + nq;
  base_residual_.resize(nu);
  residual_column_.resize(nu);
  residual_(state_, base_u_dot, base_residual_.data());
  residual_jacobian_.resize(nu, ny);
  for (int jj = 0; jj < ny; ++jj) {
    const int j = (jj + nq) % ny;  // u, then q
    const double h = kForwardJacobianStep * std::max(std::abs(y[j]), 1.0);
    const double forward = y[j] + h;
    const double step = forward - y[j];
    SetEntry(j, nq, nu, forward);
    system_->realize(state_, SimTK::Stage::Velocity);
    residual_(state_, base_u_dot, residual_column_.data());
    const SimTK::Vector& q_dot = state_.getQDot();
    for (int i = 0; i < nq; ++i) state_jacobian_(i, j) = (q_dot[i] - y_dot[i]) / step;
    residual_jacobian_.col(j) = (residual_column_ - base_residual_) / step;
    SetEntry(j, nq, nu, y[j]);
  }
  state_jacobian_.bottomRows(nu).noalias() = -m_inverse_ * residual_jacobian_;
  own_sensitivity_rhs_ += ny;
}

}  // namespace mbid::simulation
