// CVODES forward sensitivities of the crane's outputs (simulation/sensitivity.h) against central
// differences of whole simulations.
#include "mbid/simulation/sensitivity.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <sstream>

#include "crane_fixture.h"
#include "mbid/common/error.h"

namespace mbid::simulation {
namespace {

using updating::testing::Sci;

using updating::testing::Crane;
using updating::testing::LoadCrane;

using updating::testing::kAllParameters;

// The reference: Richardson-extrapolated central differences (4 D(h/2) - D(h)) / 3 with
// h = 1e-3 of the value, simulated with Adams at 1e-12: truncation O(h^4) ~ 1e-12 and
// integration noise ~1e-12 / 1e-3, both far below the 1e-4 under test.
Eigen::MatrixXd ReferenceSensitivity(const std::function<Measurement(double)>& simulate_at,
                                     double value) {
  auto central = [&](double h) {
    return Eigen::MatrixXd((simulate_at(value + h).values - simulate_at(value - h).values) /
                           (2 * h));
  };
  const double h = 1e-3 * value;
  return (4 * central(h / 2) - central(h)) / 3;
}

SimulationOptions Tight(SimulationOptions options) {
  options.integrator.method = IntegratorOptions::Method::kAdams;
  options.integrator.relative_tolerance = 1e-12;
  options.integrator.absolute_tolerance = 1e-14;
  return options;
}

// Largest deviation relative to the largest sensitivity: the 1e-4.
double RelativeError(const Eigen::MatrixXd& actual, const Eigen::MatrixXd& expected) {
  return (actual - expected).cwiseAbs().maxCoeff() / expected.cwiseAbs().maxCoeff();
}

void CheckAgainstDifferences(const Crane& crane, double duration_s,
                             const std::vector<std::string>& names) {
  SimulationOptions options = crane.simulation;
  options.duration_s = duration_s;
  SensorOptions sensors;
  sensors.sample_rate_hz = 50.0;               // the sensitivities do not depend on the sampling
  sensors.channels = {"psi", "phi", "theta"};  // outputs and a coordinate channel
  // The settings of the fit: the scenario's method (auto: Adams here) at 1e-8, interpolated
  // outputs; CVODES' quotients centered (the simulation layer's default) and forward (the fit's
  // default).
  options.integrator.interpolate_outputs = true;
  SensitivityOptions forward;
  forward.difference_quotient = SensitivityOptions::DifferenceQuotient::kForward;
  const SensitivityResult result =
      SimulateWithSensitivities(*crane.model, crane.excitation, options, sensors, names, {}, {});
  const SensitivityResult result_forward = SimulateWithSensitivities(
      *crane.model, crane.excitation, options, sensors, names, {}, forward);
  // Adams iterates with Newton on the linearization's Jacobian here too, so the simultaneous
  // corrector with forward quotients (fixed-point iteration's failure in SUNDIALS 6.4) runs.
  SimulationOptions adams = options;
  adams.integrator.method = IntegratorOptions::Method::kAdams;
  const SensitivityResult result_adams =
      SimulateWithSensitivities(*crane.model, crane.excitation, adams, sensors, names, {}, forward);
  // The sensitivity right-hand side from the state Jacobian (an option; docs/performance.md).
  SensitivityOptions jacobian;
  jacobian.right_hand_side = SensitivityOptions::RightHandSide::kStateJacobian;
  const SensitivityResult result_jacobian = SimulateWithSensitivities(
      *crane.model, crane.excitation, options, sensors, names, {}, jacobian);
  EXPECT_GT(result_jacobian.statistics.sensitivity_jacobians, 0);
  // The fit's right-hand side where it has as many sensitivities as states: J by forward
  // differences of the inverse-dynamics residual.
  SensitivityOptions forward_jacobian = jacobian;
  forward_jacobian.difference_quotient = SensitivityOptions::DifferenceQuotient::kForward;
  const SensitivityResult result_forward_jacobian = SimulateWithSensitivities(
      *crane.model, crane.excitation, options, sensors, names, {}, forward_jacobian);
  EXPECT_GT(result_forward_jacobian.statistics.sensitivity_jacobians, 0);
  // Later corrector iterates of a step keep its J (their Y moved by ~rtol): the accuracy below
  // covers them.
  EXPECT_GT(result_forward_jacobian.statistics.sensitivity_jacobian_reuses, 0);
  ASSERT_EQ(result.output_sensitivities.size(), names.size());
  EXPECT_GT(result.statistics.rhs_evaluations_for_sensitivities, 0);
  // One right-hand side per sensitivity instead of two.
  EXPECT_LT(result_forward.statistics.rhs_evaluations_for_sensitivities,
            0.6 * result.statistics.rhs_evaluations_for_sensitivities);
  const SimulationOptions tight = Tight(options);
  for (size_t k = 0; k < names.size(); ++k) {
    auto simulate_at = [&](double value) {
      std::unique_ptr<model::MechanicalModel> copy = crane.model->Clone();
      copy->SetParameter(names[k], value);
      return Simulate(*copy, crane.excitation, tight, sensors).exact;
    };
    const Eigen::MatrixXd expected =
        ReferenceSensitivity(simulate_at, crane.model->GetParameter(names[k]));
    const double error = RelativeError(result.output_sensitivities[k], expected);
    const double error_forward = RelativeError(result_forward.output_sensitivities[k], expected);
    const double error_adams = RelativeError(result_adams.output_sensitivities[k], expected);
    const double error_jacobian = RelativeError(result_jacobian.output_sensitivities[k], expected);
    const double error_forward_jacobian =
        RelativeError(result_forward_jacobian.output_sensitivities[k], expected);
    ::testing::Test::RecordProperty("relative_error_" + names[k],
                                    Sci(error) + " forward " + Sci(error_forward) + " adams " +
                                        Sci(error_adams) + " jacobian " + Sci(error_jacobian) +
                                        " forward jacobian " + Sci(error_forward_jacobian));
    // As accurate as the forward quotients it stands in for: measured 0.1-1.2x their error
    // (1.9e-8..1.0e-6 here), so 1.5x plus 1e-7 of integration scatter.
    EXPECT_LT(error_forward_jacobian, 1.5 * error_forward + 1e-7)
        << names[k] << " (forward state Jacobian)";
    EXPECT_LT(error_jacobian, 1e-4) << names[k] << " (state-Jacobian right-hand side)";
    EXPECT_LT(error_forward_jacobian, 1e-4) << names[k] << " (forward state Jacobian)";
    EXPECT_LT(error, 1e-4) << names[k];
    EXPECT_LT(error_forward, 1e-4) << names[k] << " (forward quotients)";
    EXPECT_LT(error_adams, 1e-4) << names[k] << " (Adams, forward quotients)";
  }
}

TEST(SensitivityTest, RateOutputsOfADescribedMachineMatchCentralDifferences) {
  // scenarios/excavator-arm.yaml: accelerations depend on u and, through the forces, on the
  // stiffness and damping directly; an inclinometer and a coordinate channel beside them. The
  // scenario's pull release moves all three joints (a load drop in the arm's plane would leave
  // the swing at rest).
  const Crane machine = LoadCrane(std::string(MBID_SOURCE_DIR) + "/scenarios/excavator-arm.yaml");
  SimulationOptions options = machine.simulation;
  options.duration_s = 2.0;  // six periods of the slowest mode
  options.integrator.interpolate_outputs = true;
  SensorOptions sensors;
  sensors.sample_rate_hz = 50.0;
  sensors.channels = {"boom_incl", "a_bucket_z", "a_bucket_y", "stick"};
  const std::vector<std::string> names{"c_boom", "c_swing", "d_stick", "d_boom"};
  const SensitivityResult result = SimulateWithSensitivities(*machine.model, machine.excitation,
                                                             options, sensors, names, {}, {});
  SensitivityOptions jacobian;
  jacobian.right_hand_side = SensitivityOptions::RightHandSide::kStateJacobian;
  const SensitivityResult result_jacobian = SimulateWithSensitivities(
      *machine.model, machine.excitation, options, sensors, names, {}, jacobian);
  SensitivityOptions forward_jacobian = jacobian;
  forward_jacobian.difference_quotient = SensitivityOptions::DifferenceQuotient::kForward;
  const SensitivityResult result_forward_jacobian = SimulateWithSensitivities(
      *machine.model, machine.excitation, options, sensors, names, {}, forward_jacobian);
  const SimulationOptions tight = Tight(options);
  for (size_t k = 0; k < names.size(); ++k) {
    auto simulate_at = [&](double value) {
      std::unique_ptr<model::MechanicalModel> copy = machine.model->Clone();
      copy->SetParameter(names[k], value);
      return Simulate(*copy, machine.excitation, tight, sensors).exact;
    };
    const Eigen::MatrixXd expected =
        ReferenceSensitivity(simulate_at, machine.model->GetParameter(names[k]));
    // Channel by channel: accelerations are ~1e3 times the angles, so one shared scale would
    // hide an error in the inclinometer; the state-Jacobian right-hand side meets 1e-4 on every
    // channel. CVODES' forward quotients (step sqrt(rtol) = 1e-4 in p and along s) carry the
    // right-hand side's roundoff into the weak couplings: c_swing reaches a_bucket_z 1e-3 and
    // boom_incl, stick 1e-7 as much as a_bucket_y, c_boom reaches a_bucket_y 1e-3 as much as
    // a_bucket_z; there the quotients' errors are 1e-4..1e-3 of the coupling, 1e-7 of the
    // parameter's main effect (since session 9's right-hand side, which sums the forces in
    // another order). They are compared at a floor of 1e-2 of the parameter's largest channel:
    // a wrong derivative of the main effect still fails, and the inclinometer keeps the
    // Jacobian path's check.
    double largest = 0;
    for (int c = 0; c < expected.cols(); ++c)
      largest = std::max(largest, expected.col(c).cwiseAbs().maxCoeff());
    for (int c = 0; c < expected.cols(); ++c) {
      const double floor = 1e-2 * largest;
      const double error =
          (result.output_sensitivities[k].col(c) - expected.col(c)).cwiseAbs().maxCoeff() /
          std::max(expected.col(c).cwiseAbs().maxCoeff(), floor);
      ::testing::Test::RecordProperty("relative_error_" + names[k] + "_" + sensors.channels[c],
                                      Sci(error));
      EXPECT_LT(error, 1e-4) << names[k] << " " << sensors.channels[c];
      const double error_jacobian =
          RelativeError(result_jacobian.output_sensitivities[k].col(c), expected.col(c));
      EXPECT_LT(error_jacobian, 1e-4) << names[k] << " " << sensors.channels[c] << " (Jacobian)";
      // Forward columns at step 1e-7: at most 4e-5 on the weak swing-boom coupling (CVODES'
      // forward quotients 1.1e-4 there), 6e-6 elsewhere; the channel's own scale, as above.
      const double error_forward_jacobian =
          RelativeError(result_forward_jacobian.output_sensitivities[k].col(c), expected.col(c));
      EXPECT_LT(error_forward_jacobian, 1e-4)
          << names[k] << " " << sensors.channels[c] << " (forward Jacobian)";
    }
  }
}

TEST(SensitivityTest, InitialDeflectionMatchesCentralDifferences) {
  // 3 s covers about two periods of the slowest mode and ten of the fastest.
  CheckAgainstDifferences(LoadCrane(updating::testing::kReferenceScenario), 3.0, kAllParameters);
}

TEST(SensitivityTest, LoadDropMatchesCentralDifferencesIncludingTheInitialState) {
  // The loaded equilibrium moves with the stiffnesses: s(0) = dq(0)/dc is not zero here.
  const Crane crane = LoadCrane(updating::testing::kLoadDropScenario);
  CheckAgainstDifferences(crane, 3.0, kAllParameters);
  SimulationOptions options = crane.simulation;
  options.duration_s = 1.0;
  const SensitivityResult result = SimulateWithSensitivities(
      *crane.model, crane.excitation, options, crane.sensors, {"c_theta"}, {}, {});
  EXPECT_GT(result.initial_q_sensitivity.cwiseAbs().maxCoeff(), 0.0);
}

TEST(SensitivityTest, ForcedTestCarriesSensitivitiesAcrossTheRestart) {
  // An impulse: Simulate restarts CVODES where the pulse ends; the sensitivities must carry
  // over. A torque pulse on theta, 0.2 s, then 1.8 s of free decay.
  Crane crane = LoadCrane(updating::testing::kReferenceScenario);
  simulation::Impulse impulse;
  impulse.target.coordinate = "theta";
  impulse.target.torque_Nm = 5e4;
  impulse.duration_s = 0.2;
  crane.excitation = impulse;
  CheckAgainstDifferences(crane, 2.0, {"c_theta", "d_theta", "c_alpha"});
}

// The load drop's payload mass as a nuisance parameter acting only through the initial state:
// dq(0)/dm by central differences of the loaded equilibrium.
InitialStateDirection PayloadMassDirection(const Crane& crane) {
  const double mass = crane.excitation.get<simulation::LoadDrop>().payload_mass_kg;
  auto initial_q = [&](double m) {
    Excitation changed = crane.excitation;
    changed.get<simulation::LoadDrop>().payload_mass_kg = m;
    return CalcInitialCoordinates(*crane.model, changed);
  };
  InitialStateDirection direction;
  direction.name = "payload_mass_kg";
  direction.dq0_dp = (initial_q(mass * 1.0001) - initial_q(mass * 0.9999)) / (2e-4 * mass);
  direction.scale = mass;
  return direction;
}

TEST(SensitivityTest, AutoFormsTheStateJacobianForAsManySensitivitiesAsStates) {
  // The fit's default (kAuto): the crane has NY = 8 states. Seven joint parameters stay with
  // CVODES' quotients (the same bits); all eight, and eight with the payload mass (nine), form
  // the state Jacobian, which gives the same sensitivities for less work.
  const Crane crane = LoadCrane(updating::testing::kLoadDropScenario);
  SimulationOptions options = crane.simulation;
  options.duration_s = 1.0;
  options.integrator.interpolate_outputs = true;
  const InitialStateDirection direction = PayloadMassDirection(crane);
  SensitivityOptions automatic = updating::UpdateOptions().sensitivity;
  ASSERT_EQ(automatic.right_hand_side, SensitivityOptions::RightHandSide::kAuto);
  SensitivityOptions quotients = automatic;
  quotients.right_hand_side = SensitivityOptions::RightHandSide::kCvodesQuotients;
  const std::vector<std::string> seven(kAllParameters.begin(), kAllParameters.begin() + 7);
  auto run = [&](const std::vector<std::string>& names,
                 const std::vector<InitialStateDirection>& directions,
                 const SensitivityOptions& sensitivity) {
    return SimulateWithSensitivities(*crane.model, crane.excitation, options, crane.sensors, names,
                                     directions, sensitivity);
  };
  const SensitivityResult few = run(seven, {}, automatic);
  const SensitivityResult few_quotients = run(seven, {}, quotients);
  EXPECT_EQ(few.statistics.sensitivity_jacobians, 0);
  for (size_t k = 0; k < seven.size(); ++k) {
    EXPECT_EQ(few.output_sensitivities[k], few_quotients.output_sensitivities[k]);
  }
  for (const bool with_payload : {false, true}) {
    std::vector<InitialStateDirection> directions;
    if (with_payload) directions.push_back(direction);
    const SensitivityResult many = run(kAllParameters, directions, automatic);
    const SensitivityResult many_quotients = run(kAllParameters, directions, quotients);
    EXPECT_GT(many.statistics.sensitivity_jacobians, 0);
    ASSERT_EQ(many.output_sensitivities.size(), kAllParameters.size() + directions.size());
    for (size_t k = 0; k < many.output_sensitivities.size(); ++k) {
      // Both within 1e-6 of Richardson-extrapolated differences (the tests above), so within
      // 1e-5 of each other at the sensitivity tolerance's step sequence.
      EXPECT_LT(RelativeError(many.output_sensitivities[k], many_quotients.output_sensitivities[k]),
                1e-5)
          << k << (with_payload ? " with the payload mass" : "");
    }
    if (with_payload) {
      // Nine quotients per corrector iteration against one J of NY = 8 columns (half of them
      // redo only the Velocity stage, none an M^-1).
      EXPECT_LT(many.statistics.rhs_evaluations_for_sensitivities,
                many_quotients.statistics.rhs_evaluations_for_sensitivities);
    }
  }
}

TEST(SensitivityTest, PayloadMassDirectionMatchesCentralDifferences) {
  // A nuisance parameter that acts only through the initial state: the outputs' derivative by
  // the payload mass of a load drop, along dq(0)/dm.
  const Crane crane = LoadCrane(updating::testing::kLoadDropScenario);
  SimulationOptions options = crane.simulation;
  options.duration_s = 2.0;
  options.integrator.interpolate_outputs = true;
  SensorOptions sensors;
  sensors.sample_rate_hz = 50.0;
  const double mass = crane.excitation.get<simulation::LoadDrop>().payload_mass_kg;
  const InitialStateDirection direction = PayloadMassDirection(crane);
  const SensitivityResult result = SimulateWithSensitivities(*crane.model, crane.excitation,
                                                             options, sensors, {}, {direction}, {});
  const SimulationOptions tight = Tight(options);
  auto simulate_at = [&](double m) {
    Excitation changed = crane.excitation;
    changed.get<simulation::LoadDrop>().payload_mass_kg = m;
    return Simulate(*crane.model, changed, tight, sensors).exact;
  };
  const Eigen::MatrixXd expected = ReferenceSensitivity(simulate_at, mass);
  const double error = RelativeError(result.output_sensitivities[0], expected);
  RecordProperty("relative_error_payload_mass", Sci(error));
  EXPECT_LT(error, 1e-4);
}

TEST(SensitivityTest, RejectsMisuse) {
  const Crane crane = LoadCrane(updating::testing::kReferenceScenario);
  SimulationOptions options = crane.simulation;
  options.duration_s = 0.1;
  EXPECT_THROW(
      SimulateWithSensitivities(*crane.model, crane.excitation, options, crane.sensors, {}, {}, {}),
      std::invalid_argument);
  EXPECT_THROW(SimulateWithSensitivities(*crane.model, crane.excitation, options, crane.sensors,
                                         {"c_beta"}, {}, {}),
               InputError);
  SensitivityOptions bad;
  bad.relative_tolerance = 0;
  EXPECT_THROW(SimulateWithSensitivities(*crane.model, crane.excitation, options, crane.sensors,
                                         {"c_alpha"}, {}, bad),
               std::invalid_argument);
}

}  // namespace
}  // namespace mbid::simulation
