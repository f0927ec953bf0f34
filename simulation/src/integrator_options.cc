#include "mbid/simulation/integrator_options.h"

#include <cmath>
#include <sstream>
#include <utility>

#include "mbid/common/eigen_decompositions.h"

namespace mbid::simulation {
namespace {

std::string Describe(const char* field, double value, const char* expected) {
  std::ostringstream out;
  out << field << ": " << value << "; expected " << expected;
  return out.str();
}

}  // namespace

bool IntegratorOptions::IsValid(std::string* why) const {
  auto fail = [why](std::string reason) {
    if (why != nullptr) *why = std::move(reason);
    return false;
  };
  if (method != Method::kBdf && method != Method::kAdams && method != Method::kAuto) {
    return fail("method: unknown value; expected kBdf, kAdams or kAuto");
  }
  // Below about 100 unit roundoffs CVODES cannot meet the tolerance (CV_TOO_MUCH_ACC); at 1
  // and above there is no accuracy left to control.
  if (!(relative_tolerance >= 1e-14 && relative_tolerance < 1.0)) {
    return fail(Describe("relative_tolerance", relative_tolerance, "a value in [1e-14, 1)"));
  }
  if (!(absolute_tolerance >= 0.0 && std::isfinite(absolute_tolerance))) {
    return fail(Describe("absolute_tolerance", absolute_tolerance, "a finite value >= 0"));
  }
  if (max_steps <= 0) {
    return fail(Describe("max_steps", max_steps, "a value > 0"));
  }
  if (!(max_step_s >= 0.0 && std::isfinite(max_step_s))) {
    return fail(Describe("max_step_s", max_step_s, "a finite value >= 0 (0 = unlimited)"));
  }
  return true;
}

bool SensitivityOptions::IsValid(std::string* why) const {
  auto fail = [why](std::string reason) {
    if (why != nullptr) *why = std::move(reason);
    return false;
  };
  if (right_hand_side != RightHandSide::kStateJacobian &&
      right_hand_side != RightHandSide::kCvodesQuotients &&
      right_hand_side != RightHandSide::kAuto) {
    return fail(
        "right_hand_side: unknown value; expected kStateJacobian, kCvodesQuotients or kAuto");
  }
  if (corrector != Corrector::kSimultaneous && corrector != Corrector::kStaggered) {
    return fail("corrector: unknown value; expected kSimultaneous or kStaggered");
  }
  if (difference_quotient != DifferenceQuotient::kCentered &&
      difference_quotient != DifferenceQuotient::kForward) {
    return fail("difference_quotient: unknown value; expected kCentered or kForward");
  }
  if (!(relative_tolerance >= 1e-14 && relative_tolerance < 1.0)) {
    return fail(
        Describe("sensitivity relative_tolerance", relative_tolerance, "a value in [1e-14, 1)"));
  }
  if (!(absolute_tolerance > 0.0 && std::isfinite(absolute_tolerance))) {
    return fail(
        Describe("sensitivity absolute_tolerance", absolute_tolerance, "a finite value > 0"));
  }
  return true;
}

IntegratorStatistics& IntegratorStatistics::operator+=(const IntegratorStatistics& later) {
  steps += later.steps;
  rhs_evaluations += later.rhs_evaluations;
  linear_solver_setups += later.linear_solver_setups;
  error_test_failures += later.error_test_failures;
  nonlinear_iterations += later.nonlinear_iterations;
  nonlinear_convergence_failures += later.nonlinear_convergence_failures;
  jacobian_evaluations += later.jacobian_evaluations;
  rhs_evaluations_for_jacobian += later.rhs_evaluations_for_jacobian;
  rhs_evaluations_for_sensitivities += later.rhs_evaluations_for_sensitivities;
  sensitivity_jacobians += later.sensitivity_jacobians;
  sensitivity_jacobian_reuses += later.sensitivity_jacobian_reuses;
  last_step_s = later.last_step_s;
  last_order = later.last_order;
  method = later.method;
  return *this;
}

IntegratorOptions::Method ChooseMethod(const Eigen::MatrixXd& jacobian) {
  if (jacobian.size() == 0 || !jacobian.allFinite()) return IntegratorOptions::Method::kBdf;
  const Eigen::VectorXcd eigenvalues =
      Eigen::EigenSolver<Eigen::MatrixXd>(jacobian, false).eigenvalues();
  double fastest_oscillation = 0.0, fastest = 0.0;
  for (const std::complex<double>& lambda : eigenvalues) {
    fastest_oscillation = std::max(fastest_oscillation, std::abs(lambda.imag()));
    fastest = std::max(fastest, std::abs(lambda));
  }
  return fastest_oscillation > 0 && fastest <= kStiffnessRatio * fastest_oscillation
             ? IntegratorOptions::Method::kAdams
             : IntegratorOptions::Method::kBdf;
}

const char* MethodName(IntegratorOptions::Method method) {
  switch (method) {
    case IntegratorOptions::Method::kBdf:
      return "bdf";
    case IntegratorOptions::Method::kAdams:
      return "adams";
    case IntegratorOptions::Method::kAuto:
      return "auto";
  }
  return "unknown";
}

}  // namespace mbid::simulation
