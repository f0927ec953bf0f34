// Simulations of the truck crane against independent truth: energy conservation, the linear
// model integrated in closed form, and Simbody's own integrator.
#include "mbid/simulation/simulate.h"

#include <gtest/gtest.h>

#include <cmath>
#include <tuple>

#include "mbid/common/eigen_decompositions.h"
#include "mbid/common/yaml_reader.h"
#include "mbid/model/model_factory.h"
#include "mbid/model/simbody.h"
#include "mbid/model/torsional_oscillator.h"
#include "mbid/model/truck_crane_description.h"
#include "mbid/simulation/cvodes_integrator.h"
#include "mbid/simulation/scenario_sections.h"
#include "mbid/simulation/sensitivity.h"

namespace mbid::simulation {
namespace {

const std::string kReferenceCraneYaml =
    std::string(MBID_SOURCE_DIR) + "/scenarios/reference-crane.yaml";

model::TruckCraneParameters ReferenceParameters() {
  return model::ReadTruckCraneParameters(YamlReader::FromFile(kReferenceCraneYaml).Child("model"));
}

SensorOptions NoiselessSensors(double rate_hz, std::vector<std::string> channels) {
  SensorOptions sensors;
  sensors.sample_rate_hz = rate_hz;
  sensors.channels = std::move(channels);
  return sensors;
}

Excitation Deflection(double alpha, double gamma, double eta, double theta) {
  InitialDeflection excitation;
  excitation.deflection_rad = {{"alpha", alpha}, {"gamma", gamma}, {"eta", eta}, {"theta", theta}};
  return excitation;
}

// y(t_j) of the linear model M q'' + D q' + C q = 0, y = H q from q(0) = q0, q'(0) = 0, through
// the eigendecomposition of the first-order matrix (exact up to roundoff).
Eigen::MatrixXd IntegrateLinear(const model::LinearModel& linear, const Eigen::VectorXd& q0,
                                double tau, int samples) {
  const int n = static_cast<int>(linear.M.rows());
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(2 * n, 2 * n);
  A.topRightCorner(n, n).setIdentity();
  A.bottomLeftCorner(n, n) = -linear.M.lu().solve(linear.C);
  A.bottomRightCorner(n, n) = -linear.M.lu().solve(linear.D);
  const Eigen::EigenSolver<Eigen::MatrixXd> eigen(A);
  const Eigen::MatrixXcd V = eigen.eigenvectors();
  Eigen::VectorXcd x0 = Eigen::VectorXcd::Zero(2 * n);
  x0.head(n) = q0.cast<std::complex<double>>();
  const Eigen::VectorXcd coefficients = V.lu().solve(x0);
  Eigen::MatrixXd y(samples, linear.H.rows());
  for (int j = 0; j < samples; ++j) {
    const Eigen::VectorXcd modal =
        coefficients.cwiseProduct((eigen.eigenvalues() * (j * tau)).array().exp().matrix());
    y.row(j) = (linear.H * (V * modal).head(n).real()).transpose();
  }
  return y;
}

TEST(SimulateTest, EnergyIsConservedWithoutDamping) {
  // Damping off, free motion from a deflection, 10 s at tight tolerance: the total energy
  // (kinetic + gravity + springs) drifts by less than 1e-8 of itself (the bound).
  model::TruckCraneParameters parameters = ReferenceParameters();
  for (auto& joint : parameters.joints) joint.damping_Nms_per_rad = 0.0;
  const model::MultibodyModel crane = model::MakeTruckCrane(parameters);
  SimulationOptions options;
  options.duration_s = 10.0;
  // Adams: the most accurate CVODES family on this smooth, non-stiff motion (docs/performance).
  options.integrator.method = IntegratorOptions::Method::kAdams;
  options.integrator.relative_tolerance = 1e-12;
  options.integrator.absolute_tolerance = 1e-15;
  const SimulationResult result =
      Simulate(crane, Deflection(0.004, 0.004, -0.004, -0.006), options,
               NoiselessSensors(10.0, {"alpha", "gamma", "eta", "theta"}));
  // Energy from the sampled coordinates needs speeds: re-simulate the end state instead by
  // comparing energy at t = 0 and at the last sample through a fresh integration.
  CvodesIntegrator integrator(crane.system(), options.integrator);
  integrator.Initialize(crane.MakeState(result.initial_q, Eigen::VectorXd::Zero(4)));
  const double e0 = crane.CalcEnergy(integrator.state());
  double max_drift = 0.0;
  for (int j = 1; j <= 100; ++j) {
    const double e = crane.CalcEnergy(integrator.AdvanceTo(0.1 * j));
    max_drift = std::max(max_drift, std::abs(e - e0));
  }
  // Energy is measured from the unloaded rest (potential zero there up to a constant): use the
  // deflection energy as the scale, which is what the integrator must conserve.
  const double deflection_energy = std::abs(
      e0 - crane.CalcEnergy(crane.MakeState(Eigen::VectorXd::Zero(4), Eigen::VectorXd::Zero(4))));
  EXPECT_GT(deflection_energy, 100.0);  // ~0.5 c_alpha 0.004^2 ~ 400 J: a real excitation
  EXPECT_LT(max_drift / deflection_energy, 1e-8);
}

TEST(SimulateTest, SmallLoadDropFollowsLinearModel) {
  // A 10 kg drop deflects ~1e-4 rad: the nonlinear terms are O(q) ~ 1e-4 of the response, so the
  // nonlinear and linear responses agree to 1e-3 of the amplitude (the bound).
  const model::MultibodyModel crane = model::MakeTruckCrane(ReferenceParameters());
  LoadDrop load_drop;
  load_drop.payload_mass_kg = 10.0;
  const Excitation drop = load_drop;
  SimulationOptions options;
  options.duration_s = 5.0;
  options.integrator.relative_tolerance = 1e-10;
  options.integrator.absolute_tolerance = 1e-14;
  const SimulationResult result =
      Simulate(crane, drop, options, NoiselessSensors(100.0, {"psi", "phi"}));
  const Eigen::MatrixXd linear =
      IntegrateLinear(crane.Linearize(), result.initial_q, 0.01, result.exact.samples());
  const double amplitude = result.exact.values.cwiseAbs().maxCoeff();
  EXPECT_GT(amplitude, 1e-5);  // the drop moves the boom
  EXPECT_LT((result.exact.values - linear).cwiseAbs().maxCoeff(), 1e-3 * amplitude);
}

TEST(SimulateTest, CvodesMatchesSimbodyRungeKuttaMerson) {
  // Both at rtol 1e-10 on the reference free decay: the trajectories agree to 1e-8 rad (global
  // errors of both are ~1e-10 of the 1e-2 rad amplitude).
  const model::MultibodyModel crane = model::MakeTruckCrane(ReferenceParameters());
  SimulationOptions options;
  options.duration_s = 4.0;
  options.integrator.relative_tolerance = 1e-10;
  options.integrator.absolute_tolerance = 1e-12;
  const Excitation excitation = Deflection(0.004, 0.004, -0.004, -0.006);
  const SimulationResult cvodes = Simulate(
      crane, excitation, options, NoiselessSensors(20.0, {"alpha", "gamma", "eta", "theta"}));

  SimTK::RungeKuttaMersonIntegrator rk(crane.system());
  rk.setAccuracy(1e-10);
  rk.initialize(crane.MakeState(cvodes.initial_q, Eigen::VectorXd::Zero(4)));
  double max_difference = 0.0;
  for (int j = 1; j < cvodes.exact.samples(); ++j) {
    while (rk.getTime() < j * 0.05) rk.stepTo(j * 0.05);  // stepTo may return at an event
    for (int i = 0; i < 4; ++i) {
      max_difference =
          std::max(max_difference, std::abs(rk.getState().getQ()[i] - cvodes.exact.values(j, i)));
    }
  }
  EXPECT_LT(max_difference, 1e-8);
}

TEST(SimulateTest, SensorModelIsSeededAndAddsWhatItSays) {
  const model::MultibodyModel crane = model::MakeTruckCrane(ReferenceParameters());
  SimulationOptions options;
  options.duration_s = 2.0;
  SensorOptions sensors = NoiselessSensors(100.0, {"psi", "phi"});
  sensors.noise_std = {{"psi", 1e-4}, {"phi", 1e-4}};
  sensors.bias = {{"phi", 1e-3}};
  sensors.seed = 7;
  const Excitation excitation = Deflection(0.004, 0, 0, 0);
  const SimulationResult a = Simulate(crane, excitation, options, sensors);
  const SimulationResult b = Simulate(crane, excitation, options, sensors);
  EXPECT_EQ(a.measured.values, b.measured.values);  // same seed, same bits
  sensors.seed = 8;
  const SimulationResult c = Simulate(crane, excitation, options, sensors);
  EXPECT_NE(a.measured.values, c.measured.values);
  const Eigen::MatrixXd error = a.measured.values - a.exact.values;
  // 201 samples: the sample std of N(0, 1e-4) is within 15% of 1e-4 (5 sigma of its 5% spread).
  const double mean_psi = error.col(0).mean();
  const double std_psi = std::sqrt((error.col(0).array() - mean_psi).square().mean());
  EXPECT_NEAR(std_psi, 1e-4, 0.15e-4);
  EXPECT_NEAR(error.col(1).mean(), 1e-3, 5 * 1e-4 / std::sqrt(201.0));  // the bias, 5 sigma
  EXPECT_EQ(a.measured.samples(), 201);  // 0..2 s at 100 Hz inclusive
}

TEST(SimulateTest, QuantizationRoundsToTheStep) {
  const model::MultibodyModel crane = model::MakeTruckCrane(ReferenceParameters());
  SimulationOptions options;
  options.duration_s = 1.0;
  SensorOptions sensors = NoiselessSensors(100.0, {"psi"});
  sensors.quantization_step = {{"psi", 1e-4}};
  const SimulationResult result = Simulate(crane, Deflection(0, 0.004, 0, 0), options, sensors);
  for (int j = 0; j < result.measured.samples(); ++j) {
    const double steps = result.measured.values(j, 0) / 1e-4;
    EXPECT_NEAR(steps, std::round(steps), 1e-9);  // a whole number of steps
    EXPECT_LE(std::abs(result.measured.values(j, 0) - result.exact.values(j, 0)), 0.5e-4 + 1e-15);
  }
}

TEST(SimulateTest, ImpulseDeliversItsMomentum) {
  // A 1 ms half-sine torque pulse on gamma, short against every period (>= 0.32 s), delivers the
  // impulse J = T * 2 duration / pi to the generalized momentum M q' of gamma. The springs pull
  // back during the pulse by a fraction ~(omega T)^2 ~ 4e-4 of it (omega = 2 pi 3.1 Hz): 0.2%.
  // Dampers off: they would take d M^-1 T / 4 ~ 0.4% (gamma is light once eta is coupled in).
  model::TruckCraneParameters parameters = ReferenceParameters();
  for (auto& joint : parameters.joints) joint.damping_Nms_per_rad = 0.0;
  model::MultibodyModel crane = model::MakeTruckCrane(parameters);
  Impulse impulse;
  impulse.target.coordinate = "gamma";
  impulse.target.torque_Nm = 1e5;
  impulse.duration_s = 0.001;
  const Excitation excitation = impulse;
  crane.SetExternalLoad([&](double t, std::vector<model::PointLoad>&, Eigen::VectorXd& tau) {
    tau = Eigen::VectorXd::Zero(4);
    tau[1] = impulse.target.torque_Nm * excitation.CalcForcingFactor(t);
  });
  IntegratorOptions options;
  options.relative_tolerance = 1e-10;
  options.absolute_tolerance = 1e-14;
  CvodesIntegrator integrator(crane.system(), options);
  integrator.Initialize(crane.MakeState(Eigen::VectorXd::Zero(4), Eigen::VectorXd::Zero(4)));
  const SimTK::State& end = integrator.AdvanceTo(impulse.duration_s);
  Eigen::VectorXd u(4);
  for (int i = 0; i < 4; ++i) u[i] = end.getU()[i];
  const Eigen::VectorXd momentum = crane.Linearize().M * u;
  const double J = impulse.target.torque_Nm * 2 * impulse.duration_s / M_PI;
  EXPECT_NEAR(momentum[1], J, 0.002 * J);
  EXPECT_LT(std::abs(momentum[3]), 0.002 * J);  // no direct push on theta
}

TEST(SimulateTest, BurstAndImpulseRunThroughSimulate) {
  const model::MultibodyModel crane = model::MakeTruckCrane(ReferenceParameters());
  SimulationOptions options;
  options.duration_s = 3.0;
  Burst burst;
  burst.target.point = "boom_tip";
  burst.target.force_N = Eigen::Vector3d(0, 2000, 0);
  burst.frequency_hz = 1.5;
  burst.cycles = 3;
  const SimulationResult result =
      Simulate(crane, burst, options, NoiselessSensors(100.0, {"psi", "phi"}));
  EXPECT_NEAR(result.forcing_end_s, 2.0, 1e-15);  // 3 cycles at 1.5 Hz
  EXPECT_EQ(result.initial_q.norm(), 0.0);        // starts from the unloaded rest
  EXPECT_GT(result.exact.values.col(0).cwiseAbs().maxCoeff(), 1e-5);  // a lateral push swings psi
  EXPECT_GT(result.statistics.rhs_evaluations, 0);
}

TEST(SimulateTest, TorsionalOscillatorFollowsItsClosedForm) {
  // J theta'' + d theta' + c theta = 0 from theta0 at rest:
  // theta = theta0 e^{-s t} (cos w t + s/w sin w t), s = d/2J, w = sqrt(c/J - s^2).
  const double J = 2.0, c = 800.0, d = 8.0, theta0 = 0.01;
  const model::MultibodyModel oscillator = model::MakeTorsionalOscillator({J, c, d});
  InitialDeflection deflection;
  deflection.deflection_rad = {{"angle", theta0}};
  const Excitation excitation = deflection;
  SimulationOptions options;
  options.duration_s = 3.0;
  options.integrator.relative_tolerance = 1e-11;
  options.integrator.absolute_tolerance = 1e-15;
  const SimulationResult result =
      Simulate(oscillator, excitation, options, NoiselessSensors(200.0, {"angle"}));
  const double sigma = d / (2 * J), omega = std::sqrt(c / J - sigma * sigma);
  double max_error = 0.0;
  for (int j = 0; j < result.exact.samples(); ++j) {
    const double t = j / 200.0;
    const double exact =
        theta0 * std::exp(-sigma * t) * (std::cos(omega * t) + sigma / omega * std::sin(omega * t));
    max_error = std::max(max_error, std::abs(result.exact.values(j, 0) - exact));
  }
  // rtol 1e-11 over ~10 periods: global error ~1e-10 of theta0 = 1e-12 rad; bound 1e-10 rad.
  EXPECT_LT(max_error, 1e-10);
}

// At 20 kHz the oscillator's 3.2 Hz decay is evaluated at every 52nd sample only and
// interpolated between (a logger's rate, far above what the swing needs): every sample still
// follows the closed form as the 200 Hz record does, and so do the sensitivities to c and d,
// against central differences of the closed form.
TEST(SimulateTest, AHighRateRecordFollowsTheClosedFormAtEverySample) {
  const double J = 2.0, c = 800.0, d = 8.0, theta0 = 0.01;
  auto closed_form = [&](double cc, double dd, double t) {
    const double sigma = dd / (2 * J), omega = std::sqrt(cc / J - sigma * sigma);
    return theta0 * std::exp(-sigma * t) *
           (std::cos(omega * t) + sigma / omega * std::sin(omega * t));
  };
  const model::MultibodyModel oscillator = model::MakeTorsionalOscillator({J, c, d});
  InitialDeflection deflection;
  deflection.deflection_rad = {{"angle", theta0}};
  SimulationOptions options;
  options.duration_s = 3.0;
  options.integrator.relative_tolerance = 1e-11;
  options.integrator.absolute_tolerance = 1e-15;
  const double rate_hz = 20000;
  const SimulationResult result =
      Simulate(oscillator, deflection, options, NoiselessSensors(rate_hz, {"angle"}));
  // ASSERT_EQ(result.exact.samples(), 60001);
  double max_error = 0.0;
  for (int j = 0; j < result.exact.samples(); ++j) {
    max_error =
        std::max(max_error, std::abs(result.exact.values(j, 0) - closed_form(c, d, j / rate_hz)));
  }
  // The bound of the 200 Hz test above; the interpolation adds 0.0049 (2 pi / 120)^6 theta0
  // = 1e-12 rad.
  EXPECT_LT(max_error, 1e-10);

  const SensitivityResult sensitivities = SimulateWithSensitivities(
      oscillator, deflection, options, NoiselessSensors(rate_hz, {"angle"}), {"c_angle", "d_angle"},
      {}, SensitivityOptions());
  for (const auto& [k, dc, dd] : {std::tuple{0, 1e-4 * c, 0.0}, std::tuple{1, 0.0, 1e-4 * d}}) {
    const Eigen::MatrixXd& s = sensitivities.output_sensitivities[static_cast<size_t>(k)];
    double error = 0, largest = 0;
    for (int j = 0; j < s.rows(); ++j) {
      const double t = j / rate_hz;
      const double expected =
          (closed_form(c + dc, d + dd, t) - closed_form(c - dc, d - dd, t)) / (2 * (dc + dd));
      error = std::max(error, std::abs(s(j, 0) - expected));
      largest = std::max(largest, std::abs(expected));
    }
    // The sensitivities' own tolerance (relative 1e-6) over 10 periods: 1.1e-5 of their largest
    // measured at 200 Hz (every sample evaluated), 2.5e-5 at 20 kHz (the largest of 100 times the
    // samples). A wrong node or weight would err by the swing itself.
    EXPECT_LT(error, 5e-5 * largest) << sensitivities.parameters[static_cast<size_t>(k)];
  }
}

// The first-order matrix [0 I; -C -D] of uncoupled unit-inertia joints with the given undamped
// angular frequencies (rad/s) and damping ratios: eigenvalues -zeta w +- i w sqrt(1 - zeta^2),
// or two real ones when overdamped.
Eigen::MatrixXd JointsJacobian(const std::vector<double>& w, const std::vector<double>& zeta) {
  const int n = static_cast<int>(w.size());
  Eigen::MatrixXd jacobian = Eigen::MatrixXd::Zero(2 * n, 2 * n);
  jacobian.topRightCorner(n, n).setIdentity();
  for (int i = 0; i < n; ++i) {
    jacobian(n + i, i) = -w[i] * w[i];
    jacobian(n + i, n + i) = -2 * zeta[i] * w[i];
  }
  return jacobian;
}

TEST(SimulateTest, AutoChoosesAdamsUnlessAnEigenvalueOutrunsTheOscillations) {
  using Method = IntegratorOptions::Method;
  // Lightly damped modes at 4 and 20 rad/s: the fastest |lambda| is the fastest oscillation.
  EXPECT_EQ(ChooseMethod(JointsJacobian({4, 20}, {0.02, 0.05})), Method::kAdams);
  // A third joint overdamped, zeta = 3 at 50 rad/s: a real eigenvalue of
  // -50 (3 + sqrt(8)) = -291, 14.6x the fastest oscillation (20 rad/s, above the ratio 8): BDF.
  EXPECT_EQ(ChooseMethod(JointsJacobian({4, 20, 50}, {0.02, 0.05, 3.0})), Method::kBdf);
  // zeta = 1.1 at 50 rad/s: -50 (1.1 + sqrt(0.21)) = -78, 3.9x: still Adams.
  EXPECT_EQ(ChooseMethod(JointsJacobian({4, 20, 50}, {0.02, 0.05, 1.1})), Method::kAdams);
  // No oscillation at all, no Jacobian, or a broken one: BDF, the safe method.
  EXPECT_EQ(ChooseMethod(JointsJacobian({4}, {2.0})), Method::kBdf);
  EXPECT_EQ(ChooseMethod(Eigen::MatrixXd()), Method::kBdf);
  Eigen::MatrixXd broken = JointsJacobian({4}, {0.1});
  broken(1, 0) = std::nan("");
  EXPECT_EQ(ChooseMethod(broken), Method::kBdf);
}

TEST(SimulateTest, AutoRunsAdamsOnTheCraneAndBdfWithAHeavilyDampedJoint) {
  // The reference crane (stiffness ratio 1.0, docs/performance.md) runs Adams by default; with
  // alpha's damping x500 (ratio 135) BDF, which Adams would need 3.5x the steps of. An explicit
  // method is kept, and every run agrees with BDF at the tolerance (rtol 1e-8 on ~1e-3 rad).
  const model::MultibodyModel crane = model::MakeTruckCrane(ReferenceParameters());
  SimulationOptions options;
  options.duration_s = 2.0;
  EXPECT_EQ(options.integrator.method, IntegratorOptions::Method::kAuto);  // the default
  const Excitation deflection = Deflection(0.004, 0.004, -0.004, -0.006);
  const SensorOptions sensors = NoiselessSensors(100.0, {"psi", "phi"});
  const SimulationResult automatic = Simulate(crane, deflection, options, sensors);
  EXPECT_EQ(automatic.statistics.method, IntegratorOptions::Method::kAdams);
  SimulationOptions bdf = options;
  bdf.integrator.method = IntegratorOptions::Method::kBdf;
  const SimulationResult explicit_bdf = Simulate(crane, deflection, bdf, sensors);
  EXPECT_EQ(explicit_bdf.statistics.method, IntegratorOptions::Method::kBdf);
  EXPECT_LT(automatic.statistics.steps, 0.7 * explicit_bdf.statistics.steps);
  EXPECT_LT((automatic.exact.values - explicit_bdf.exact.values).cwiseAbs().maxCoeff(), 1e-8);

  model::TruckCraneParameters damped = ReferenceParameters();
  damped.joints[0].damping_Nms_per_rad *= 500;
  const model::MultibodyModel damped_crane = model::MakeTruckCrane(damped);
  EXPECT_EQ(Simulate(damped_crane, deflection, options, sensors).statistics.method,
            IntegratorOptions::Method::kBdf);
}

TEST(SimulateTest, ReadsScenarioSections) {
  const YamlReader root = YamlReader::FromFile(kReferenceCraneYaml);
  const model::MultibodyModel crane = model::MakeTruckCrane(ReferenceParameters());
  const Excitation excitation = ReadExcitation(root.Child("excitation"), crane);
  ASSERT_NE(excitation.get_if<InitialDeflection>(), nullptr);
  EXPECT_EQ(excitation.get<InitialDeflection>().deflection_rad.at("theta"), -0.006);
  const SimulationOptions options = ReadSimulationOptions(root.Child("simulation"));
  EXPECT_EQ(options.duration_s, 8.0);
  EXPECT_EQ(options.integrator.relative_tolerance, 1e-8);
  EXPECT_EQ(options.integrator.method, IntegratorOptions::Method::kAuto);  // as the file says
  const YamlReader bdf =
      YamlReader::FromString("integrator: {method: bdf}\nduration_s: 1\n", "inline.yaml");
  EXPECT_EQ(ReadSimulationOptions(bdf).integrator.method, IntegratorOptions::Method::kBdf);
  const YamlReader automatic =
      YamlReader::FromString("integrator: {method: auto}\nduration_s: 1\n", "inline.yaml");
  EXPECT_EQ(ReadSimulationOptions(automatic).integrator.method, IntegratorOptions::Method::kAuto);
  const YamlReader omitted = YamlReader::FromString("duration_s: 1\n", "inline.yaml");
  EXPECT_EQ(ReadSimulationOptions(omitted).integrator.method, IntegratorOptions::Method::kAuto);
  const SensorOptions sensors = ReadSensorOptions(root.Child("sensors"), crane);
  EXPECT_EQ(sensors.channels, (std::vector<std::string>{"psi", "phi"}));
  EXPECT_EQ(sensors.noise_std.at("phi"), 1e-5);
}

}  // namespace
}  // namespace mbid::simulation
