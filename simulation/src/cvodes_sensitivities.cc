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
  const bool own_rhs = options.right_hand_side == SensitivityOptions::RightHandSide::kStateJacobian;
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
int CvodesIntegrator::Impl::SensitivityRhs(int count, realtype t, N_Vector y, N_Vector /*y_dot*/,
                                           N_Vector* s, N_Vector* s_dot, void* user_data, N_Vector,
                                           N_Vector) {
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
void CvodesIntegrator::Impl::UpdateSensitivityJacobian(double t, const realtype* y) {
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

}  // namespace mbid::simulation
