#pragma once

#include <Eigen/Core>
#include <string>

namespace mbid::simulation {

// How CvodesIntegrator integrates: the linear multistep family, the local error tolerances
// and the step limits. Checked by IsValid() when the integrator is built.
struct IntegratorOptions {
  enum class Method {
    kBdf,    // Backward differentiation formulas, Newton iteration with a dense Jacobian.
    kAdams,  // Adams-Moulton, for non-stiff models: Newton with a given Jacobian
             // (CvodesIntegrator::set_jacobian; Simulate gives one), else fixed-point iteration.
    kAuto,   // Adams if the given Jacobian is not stiff (ChooseMethod), else BDF.
  };

  Method method = Method::kAuto;
  // CVODES weights each component's local error by rtol * |y_i| + atol (y in SI units).
  double relative_tolerance = 1e-8;
  double absolute_tolerance = 1e-10;
  // Internal steps allowed within one AdvanceTo() call.
  int max_steps = 100000;
  // Largest internal step (s); 0 leaves it unlimited.
  double max_step_s = 0.0;
  // false: every AdvanceTo(t) ends a step exactly at t. true: CVODES steps past t and
  // interpolates its Nordsieck history (error of the order of the tolerance), which is cheaper
  // with dense outputs, but the input hook is then evaluated up to one step beyond t before
  // AdvanceTo(t) returns: use it only for inputs that depend on time alone.
  bool interpolate_outputs = false;

  // True if the options can be used; otherwise false with the reason in `why` (if not null).
  bool IsValid(std::string* why) const;
};

// The method `auto` runs for a model whose Jacobian df/dY (e.g. the linearization) is
// `jacobian`: Adams unless an eigenvalue is more than kStiffnessRatio times faster (in modulus)
// than the fastest oscillation, BDF then, and for a Jacobian without oscillation or none at all.
// Adams takes about half BDF's steps on lightly damped structures at a smaller error, but an
// eigenvalue far outside its stability region (a heavily damped joint) holds its step down.
// Measured on the reference crane with one joint's damping raised 2-500x (docs/performance.md):
// Adams' steps / BDF's grow from 0.5 at ratio 1 to 0.7-0.85 at 5-7, 1.1 at 13, 2-3.5 at 40-135.
inline constexpr double kStiffnessRatio = 8.0;
IntegratorOptions::Method ChooseMethod(const Eigen::MatrixXd& jacobian);
// "bdf", "adams" or "auto".
const char* MethodName(IntegratorOptions::Method method);

// How CvodesIntegrator integrates forward sensitivities s_i = dY/dp_i (CVODES; docs/toolchain.md).
// Checked by IsValid() when the sensitivities are initialized.
struct SensitivityOptions {
  // Where the sensitivity right-hand side s_i' = J s_i + df/dp_i comes from.
  enum class RightHandSide {
    // CVODES' own difference quotients of f along (s_i, p_i): one (forward) or two (centered)
    // right-hand sides per sensitivity and corrector iteration.
    kCvodesQuotients,
    // J = df/dY formed once per distinct (t, Y) and reused for every sensitivity and corrector
    // iteration; df/dp_i in closed form where CvodesIntegrator::set_parameter_force_derivative
    // knows it, else central differences of f in p_i alone. `difference_quotient` says how J's
    // columns are differenced: centered, 2 NY right-hand sides, as close to
    // Richardson-extrapolated differences as centered quotients; forward, where
    // CvodesIntegrator::set_residual gives the inverse-dynamics residual (centered otherwise),
    // from the f(t, Y) CVODES hands over and the residual at fixed u' (M^-1 once per mobility):
    // about 6 right-hand sides' work on the crane (NY = 8), more accurate than forward
    // quotients (docs/performance.md, session 17).
    kStateJacobian,
    // kStateJacobian where there are at least as many sensitivities as states (each forward
    // quotient costs a right-hand side, J about 0.7 of one per state: 0.80 of the quotients'
    // instructions for the crane's 8 joint parameters, 0.61 with 4 initial deflections beside
    // them), kCvodesQuotients otherwise.
    kAuto,
  };
  enum class Corrector {
    kSimultaneous,  // state and sensitivities in one nonlinear system (CV_SIMULTANEOUS)
    kStaggered,     // sensitivities corrected after the state has converged (CV_STAGGERED)
  };
  enum class DifferenceQuotient {
    kCentered,  // two right-hand sides per sensitivity, error O(delta^2)
    kForward,   // one right-hand side per sensitivity, error O(delta)
  };

  RightHandSide right_hand_side = RightHandSide::kCvodesQuotients;
  Corrector corrector = Corrector::kSimultaneous;
  // kCvodesQuotients only.
  DifferenceQuotient difference_quotient = DifferenceQuotient::kCentered;
  // Local error test of the sensitivities: rtol_s * |s_i| + atol_s / p_scale_i. Looser than the
  // state's on purpose: at the state's tolerance (<= 1e-9) the internal difference quotients are
  // noisier than the test and CVODES stalls (docs/toolchain.md).
  double relative_tolerance = 1e-6;
  double absolute_tolerance = 1e-8;
  // false leaves the sensitivities out of the error test (steps chosen for the state alone).
  bool error_control = true;

  bool IsValid(std::string* why) const;
};

// Counters of CVODES since the last CvodesIntegrator::Initialize().
struct IntegratorStatistics {
  long steps = 0;
  // Calls of the right-hand side by the integrator itself (not for the Jacobian).
  long rhs_evaluations = 0;
  long linear_solver_setups = 0;
  long error_test_failures = 0;
  long nonlinear_iterations = 0;
  long nonlinear_convergence_failures = 0;
  long jacobian_evaluations = 0;
  // Calls of the right-hand side for difference-quotient Jacobians (BDF only).
  long rhs_evaluations_for_jacobian = 0;
  // Calls of the right-hand side for the sensitivities: CVODES' difference quotients, or the
  // columns of J and the parameter differences of kStateJacobian.
  long rhs_evaluations_for_sensitivities = 0;
  // State Jacobians J formed for the sensitivities (kStateJacobian).
  long sensitivity_jacobians = 0;
  // Later corrector iterates of a step that kept its J (only df/dp recomputed).
  long sensitivity_jacobian_reuses = 0;
  double last_step_s = 0.0;
  int last_order = 0;
  // The method CVODES ran (`auto` resolved).
  IntegratorOptions::Method method = IntegratorOptions::Method::kBdf;

  // Adds the counters of a later stretch of integration (after a restart); the last step and
  // order become the later stretch's.
  IntegratorStatistics& operator+=(const IntegratorStatistics& later);
};

}  // namespace mbid::simulation
