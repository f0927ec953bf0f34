#pragma once

#include <string>

namespace mbid::simulation {

// How CvodesIntegrator integrates: the linear multistep family, the local error tolerances
// and the step limits. Checked by IsValid() when the integrator is built.
struct IntegratorOptions {
  enum class Method {
    kBdf,    // Backward differentiation formulas, Newton iteration with a dense Jacobian.
    kAdams,  // Adams-Moulton, fixed-point (functional) iteration; for non-stiff models.
  };

  Method method = Method::kBdf;
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
  double last_step_s = 0.0;
  int last_order = 0;
};

}  // namespace mbid::simulation
