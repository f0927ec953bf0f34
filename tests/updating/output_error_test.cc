// Route 2 (time-domain output error with Ceres) on records simulated from the reference crane:
// known truth, so recovery, the reported uncertainty and the identifiability report can all be
// checked against it.
#include "mbid/updating/output_error.h"

#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

#include "crane_fixture.h"
#include "mbid/simulation/sensor.h"

namespace mbid::updating {
namespace {

using testing::Sci;

using testing::Crane;
using testing::LoadCrane;

using testing::kAllParameters;

// Starts every stiffness at `c_factor` and every damping at `d_factor` times the truth.
UpdateOptions StartOff(const model::MechanicalModel& model, double c_factor, double d_factor,
                       const std::vector<std::string>& names = kAllParameters) {
  UpdateOptions options;
  for (const std::string& name : names) {
    ParameterSetting setting;
    setting.name = name;
    setting.initial = model.GetParameter(name) * (name[0] == 'c' ? c_factor : d_factor);
    options.parameters.push_back(setting);
  }
  options.quiet = true;
  options.threads = 2;  // sensitivity groups in parallel on the test machine's two cores
  return options;
}

// Noise of `snr_db` per channel relative to the channel's RMS, seeded.
std::map<std::string, double> NoiseForSnr(const Measurement& exact, double snr_db) {
  std::map<std::string, double> noise;
  for (int c = 0; c < exact.channel_count(); ++c) {
    const double rms = std::sqrt(exact.values.col(c).squaredNorm() / exact.samples());
    noise[exact.channels[static_cast<size_t>(c)]] = rms / std::pow(10.0, snr_db / 20);
  }
  return noise;
}

Measurement AddNoise(const Measurement& exact, const std::map<std::string, double>& noise,
                     std::uint64_t seed) {
  simulation::SensorOptions sensors;
  sensors.sample_rate_hz = 1.0 / exact.sample_interval_s;
  sensors.channels = exact.channels;
  sensors.noise_std = noise;
  sensors.seed = seed;
  return simulation::ApplySensor(exact, sensors);
}

double RelativeError(const UpdateResult& result, const model::MechanicalModel& truth,
                     const std::string& name) {
  return result.Find(name).value / truth.GetParameter(name) - 1;
}

// The measured numbers, in the test's XML output (--gtest_output=xml).
void Record(const UpdateResult& result, const model::MechanicalModel& truth) {
  for (const ParameterEstimate& estimate : result.parameters) {
    if (!estimate.test.empty()) continue;
    ::testing::Test::RecordProperty(estimate.name,
                                    "error " + Sci(RelativeError(result, truth, estimate.name)) +
                                        " relative_std " + Sci(estimate.relative_std));
  }
  ::testing::Test::RecordProperty("iterations", result.iterations);
  ::testing::Test::RecordProperty("sensitivity_runs",
                                  static_cast<int>(result.sensitivity_simulations));
}

TEST(OutputErrorTest, NoiselessLoadDropFromFiftyPercentOffRecoversAllEight) {
  // The test on reference-crane-load-drop.yaml. Noiseless, every parameter is
  // determined, even those of the barely excited 2.26 and 3.09 Hz modes (amplitudes < 2e-5 rad
  // are exact here): the fit must reach 1e-5 in all eight. What limits it is the integration
  // error (tolerance 1e-8), which the fit's own simulations do not share step for step.
  // 5 s at 50 Hz instead of the scenario's 8 s at 100 Hz keeps the test short: the slowest
  // mode has 2.8 of its 1/e decay times in it.
  const Crane crane = LoadCrane(testing::kLoadDropScenario);
  const Measurement record = testing::SimulateExact(crane, 5.0, 50.0);
  UpdateOptions options = StartOff(*crane.model, 1.5, 1.5);
  options.integrator = crane.simulation.integrator;
  options.integrator.interpolate_outputs = true;
  const UpdateResult result =
      UpdateModel(*crane.model, {{"load drop", record, crane.excitation, {}}}, options);
  ASSERT_EQ(result.termination, UpdateResult::Termination::kConverged) << result.message;
  Record(result, *crane.model);
  for (const std::string& name : kAllParameters) {
    EXPECT_LT(std::abs(RelativeError(result, *crane.model, name)), 1e-5) << name;
  }
  // Noise was not given: estimated from the residual, which is integration error only.
  ASSERT_EQ(result.tests.size(), 1u);
  EXPECT_TRUE(result.tests[0].noise_estimated[0]);
  EXPECT_LT(result.tests[0].noise_std.maxCoeff(), 1e-7);
  EXPECT_GT(result.tests[0].correlation.minCoeff(), 0.999999);
  // The cost history is recorded per iteration and falls.
  ASSERT_GE(result.history.size(), 2u);
  EXPECT_LT(result.final_cost, result.initial_cost);
  EXPECT_GT(result.sensitivity_simulations, 0);
}

TEST(OutputErrorTest, ThirtyDecibelsOnTheReferenceCraneWithinOneAndFivePercent) {
  // reference-crane.yaml (initial deflection: every mode visible) at 30 dB SNR per channel,
  // the noise level given to the fit as it would come from the identification. Start 20% off
  // (stiffnesses up, dampings down). The bounds: stiffnesses within 1%, dampings within
  // 5%, and the truth within 3 reported standard deviations (the stds are 0.02-2%, so the
  // bounds are loose; 3 std is the statistical check).
  const Crane crane = LoadCrane(testing::kReferenceScenario);
  const Measurement exact =
      testing::SimulateExact(crane, crane.simulation.duration_s, crane.sensors.sample_rate_hz);
  const std::map<std::string, double> noise = NoiseForSnr(exact, 30.0);
  const Measurement record = AddNoise(exact, noise, 7);
  UpdateOptions options = StartOff(*crane.model, 1.2, 0.8);
  options.integrator = crane.simulation.integrator;
  options.integrator.interpolate_outputs = true;
  const UpdateResult result =
      UpdateModel(*crane.model, {{"deflection", record, crane.excitation, noise}}, options);
  ASSERT_EQ(result.termination, UpdateResult::Termination::kConverged) << result.message;
  Record(result, *crane.model);
  for (const std::string& name : kAllParameters) {
    const ParameterEstimate& estimate = result.Find(name);
    const double error = RelativeError(result, *crane.model, name);
    EXPECT_LT(std::abs(error), name[0] == 'c' ? 0.01 : 0.05) << name;
    ASSERT_TRUE(std::isfinite(estimate.std)) << name;
    EXPECT_LT(std::abs(estimate.value - crane.model->GetParameter(name)), 3 * estimate.std) << name;
    EXPECT_TRUE(estimate.determined) << name;
  }
  EXPECT_TRUE(result.undetermined.empty());
  EXPECT_EQ(result.rank, 8);
  // The correlation matrix: unit diagonal, symmetric, entries in [-1, 1].
  for (int i = 0; i < 8; ++i) {
    EXPECT_NEAR(result.correlation(i, i), 1.0, 1e-12);
    for (int j = 0; j < 8; ++j) {
      EXPECT_NEAR(result.correlation(i, j), result.correlation(j, i), 1e-12);
      EXPECT_LE(std::abs(result.correlation(i, j)), 1.0 + 1e-12);
    }
  }
  // The re-simulated tuned model against the record: K limited by the 30 dB noise alone
  // (1 / sqrt(1 + 10^-3) = 0.9995).
  EXPECT_GT(result.tests[0].correlation.minCoeff(), 0.999);
}

TEST(OutputErrorTest, LoadDropReportsWhatItCannotDetermine) {
  // reference-crane-load-drop.yaml with its sensor noise (1e-5 rad): the 2.26 and 3.09 Hz
  // modes stay below 2e-5 rad, so the damping that acts mainly in them (d_eta, relative std
  // about 90%) is not determined by this record. The fit must say so instead of returning a
  // number that looks determined; the well-excited parameters stay determined.
  // Start 2% off, as Route 1 on identified poles would give: this single noisy record has other
  // local minima (Route 1's rival set that swaps what gamma and eta carry, and worse ones) that
  // starts 5-20% off reach in about half the cases; the point here is the report at the
  // record's own minimum.
  const Crane crane = LoadCrane(testing::kLoadDropScenario);
  const Measurement exact =
      testing::SimulateExact(crane, crane.simulation.duration_s, crane.sensors.sample_rate_hz);
  const Measurement record = AddNoise(exact, crane.sensors.noise_std, 7);
  UpdateOptions options = StartOff(*crane.model, 1.02, 0.98);
  options.integrator = crane.simulation.integrator;
  options.integrator.interpolate_outputs = true;
  const UpdateResult result = UpdateModel(
      *crane.model, {{"load drop", record, crane.excitation, crane.sensors.noise_std}}, options);
  ASSERT_NE(result.termination, UpdateResult::Termination::kFailure) << result.message;
  Record(result, *crane.model);
  std::string undetermined;
  for (const std::string& name : result.undetermined) undetermined += name + " ";
  RecordProperty("undetermined", undetermined);
  ASSERT_FALSE(result.undetermined.empty());
  EXPECT_NE(std::find(result.undetermined.begin(), result.undetermined.end(), "d_eta"),
            result.undetermined.end());
  EXPECT_FALSE(result.Find("d_eta").determined);
  EXPECT_GT(result.Find("d_eta").relative_std, options.undetermined_relative_std);
  // The phi-plane parameters of the dominant 1.51 Hz mode are determined to better than 1%.
  for (const char* name : {"c_theta", "d_theta"}) {
    EXPECT_TRUE(result.Find(name).determined) << name;
    EXPECT_LT(result.Find(name).relative_std, 0.01) << name;
  }
  bool warned = false;
  for (const std::string& warning : result.warnings) {
    warned = warned || warning.find("undetermined") != std::string::npos;
  }
  EXPECT_TRUE(warned);
}

TEST(OutputErrorTest, TwoTestsJointlyGiveSmallerStandardDeviations) {
  // The initial deflection and the load drop share the joint parameters: fitted together,
  // their information adds, so every standard deviation must shrink against each test alone.
  // Both start at the truth (the point here is the covariance, not the path); 4 s at 50 Hz.
  const Crane deflection = LoadCrane(testing::kReferenceScenario);
  const Crane drop = LoadCrane(testing::kLoadDropScenario);
  const std::map<std::string, double> noise = deflection.sensors.noise_std;  // 1e-5 rad
  const TestRecord a{"deflection",
                     AddNoise(testing::SimulateExact(deflection, 4.0, 50.0), noise, 11),
                     deflection.excitation, noise};
  const TestRecord b{"load drop", AddNoise(testing::SimulateExact(drop, 4.0, 50.0), noise, 12),
                     drop.excitation, noise};
  UpdateOptions options = StartOff(*deflection.model, 1.0, 1.0);
  options.integrator = deflection.simulation.integrator;
  options.integrator.interpolate_outputs = true;
  const UpdateResult alone_a = UpdateModel(*deflection.model, {a}, options);
  const UpdateResult alone_b = UpdateModel(*deflection.model, {b}, options);
  const UpdateResult joint = UpdateModel(*deflection.model, {a, b}, options);
  ASSERT_EQ(joint.termination, UpdateResult::Termination::kConverged) << joint.message;
  ASSERT_EQ(joint.tests.size(), 2u);
  for (const std::string& name : kAllParameters) {
    RecordProperty(name,
                   "std joint/deflection " + Sci(joint.Find(name).std / alone_a.Find(name).std) +
                       " joint/load drop " + Sci(joint.Find(name).std / alone_b.Find(name).std));
  }
  for (const std::string& name : kAllParameters) {
    const double std_joint = joint.Find(name).std;
    ASSERT_TRUE(std::isfinite(std_joint)) << name;
    EXPECT_LT(std_joint, alone_a.Find(name).std) << name;
    // A std the load drop leaves undefined (NaN) counts as infinite.
    const double std_b = alone_b.Find(name).std;
    EXPECT_TRUE(!std::isfinite(std_b) || std_joint < std_b) << name;
  }
  EXPECT_TRUE(joint.undetermined.empty());
}

TEST(OutputErrorTest, PayloadMassAsANuisanceParameter) {
  // The load drop's payload mass fitted along with theta's spring and damper: the initial
  // amplitude of the 1.51 Hz mode is the payload's static deflection (m / c_theta roughly), its
  // frequency sets c_theta alone, so all three are determined. Noiseless, 3 s at 50 Hz, start
  // 20% off: recovery to 1e-5 (integration error, as above).
  const Crane crane = LoadCrane(testing::kLoadDropScenario);
  const Measurement record = testing::SimulateExact(crane, 3.0, 50.0);
  TestRecord test{"drop", record, crane.excitation, {}};
  test.excitation.get<simulation::LoadDrop>().payload_mass_kg *=
      1.2;  // the start; the truth is the scenario's 650 kg
  test.fit_payload_mass = true;
  UpdateOptions options = StartOff(*crane.model, 1.2, 0.8, {"c_theta", "d_theta"});
  options.integrator = crane.simulation.integrator;
  options.integrator.interpolate_outputs = true;
  const UpdateResult result = UpdateModel(*crane.model, {test}, options);
  ASSERT_EQ(result.termination, UpdateResult::Termination::kConverged) << result.message;
  const ParameterEstimate& mass = result.Find("drop:payload_mass_kg");
  EXPECT_EQ(mass.test, "drop");
  EXPECT_EQ(mass.units, "kg");
  const double truth = crane.excitation.get<simulation::LoadDrop>().payload_mass_kg;
  EXPECT_NEAR(mass.value, truth, 1e-5 * truth);
  EXPECT_LT(std::abs(RelativeError(result, *crane.model, "c_theta")), 1e-5);
  EXPECT_LT(std::abs(RelativeError(result, *crane.model, "d_theta")), 1e-5);
}

TEST(OutputErrorTest, NumericJacobianReachesTheSameEstimate) {
  // The option: central differences of whole simulations instead of sensitivities. Two
  // parameters, noiseless 3 s at 50 Hz, 20% off: both Jacobians lead to the truth (1e-6: the
  // step 1e-4 in log p gives a Jacobian good to ~1e-4, enough for Gauss-Newton to converge to
  // the same minimum).
  const Crane crane = LoadCrane(testing::kReferenceScenario);
  const Measurement record = testing::SimulateExact(crane, 3.0, 50.0);
  UpdateOptions options = StartOff(*crane.model, 1.2, 0.8, {"c_theta", "d_theta"});
  options.integrator = crane.simulation.integrator;
  options.integrator.interpolate_outputs = true;
  const TestRecord test{"deflection", record, crane.excitation, {}};
  const UpdateResult by_sensitivities = UpdateModel(*crane.model, {test}, options);
  options.jacobian = UpdateOptions::Jacobian::kNumeric;
  const UpdateResult numeric = UpdateModel(*crane.model, {test}, options);
  ASSERT_EQ(numeric.termination, UpdateResult::Termination::kConverged) << numeric.message;
  EXPECT_EQ(numeric.jacobian, "numeric");
  EXPECT_EQ(numeric.sensitivity_simulations, 0);
  for (const char* name : {"c_theta", "d_theta"}) {
    EXPECT_LT(std::abs(RelativeError(numeric, *crane.model, name)), 1e-6) << name;
    EXPECT_LT(std::abs(RelativeError(by_sensitivities, *crane.model, name)), 1e-6) << name;
  }
}

TEST(OutputErrorTest, IterationLimitIsNoConvergenceNotSuccess) {
  // Two iterations from 50% off cannot converge: the result says no_convergence (exit code 3),
  // with the values reached and the message, and never "converged".
  const Crane crane = LoadCrane(testing::kReferenceScenario);
  const Measurement record = testing::SimulateExact(crane, 2.0, 50.0);
  UpdateOptions options = StartOff(*crane.model, 1.5, 1.5, {"c_theta", "d_theta"});
  options.integrator.interpolate_outputs = true;
  options.max_iterations = 2;
  const UpdateResult result =
      UpdateModel(*crane.model, {{"deflection", record, crane.excitation, {}}}, options);
  EXPECT_EQ(result.termination, UpdateResult::Termination::kNoConvergence) << result.message;
  EXPECT_EQ(result.termination_name(), "no_convergence");
  EXPECT_FALSE(result.message.empty());
  // Not at a minimum: no standard deviation holds, and none is reported as if it did.
  for (const ParameterEstimate& p : result.parameters) {
    EXPECT_FALSE(p.determined) << p.name;
    EXPECT_NE(p.why_undetermined.find("no convergence"), std::string::npos) << p.why_undetermined;
  }
}

TEST(OutputErrorTest, FailingSimulationIsAFailureResult) {
  // The integrator gives up at once (10 steps allowed): the fit cannot even start. That is a
  // result with termination "failure" and CVODES' reason, not an exception.
  const Crane crane = LoadCrane(testing::kReferenceScenario);
  const Measurement record = testing::SimulateExact(crane, 2.0, 50.0);
  UpdateOptions options = StartOff(*crane.model, 1.0, 1.0, {"c_theta"});
  options.integrator.max_steps = 10;
  options.integrator.interpolate_outputs = true;
  const UpdateResult result =
      UpdateModel(*crane.model, {{"deflection", record, crane.excitation, {}}}, options);
  EXPECT_EQ(result.termination, UpdateResult::Termination::kFailure);
  EXPECT_NE(result.message.find("CV_TOO_MUCH_WORK"), std::string::npos) << result.message;
}

TEST(OutputErrorTest, RejectsBadInput) {
  const Crane crane = LoadCrane(testing::kReferenceScenario);
  const Measurement record = testing::SimulateExact(crane, 0.5, 50.0);
  const TestRecord test{"deflection", record, crane.excitation, {}};
  UpdateOptions options;
  options.quiet = true;
  options.parameters = {{"c_beta"}};
  EXPECT_THROW(UpdateModel(*crane.model, {test}, options), InputError);
  options.parameters = {{"c_theta", 1e7, 2e7, 3e7}};  // start below the lower bound
  EXPECT_THROW(UpdateModel(*crane.model, {test}, options), InputError);
  options.parameters = {{"c_theta"}};
  EXPECT_THROW(UpdateModel(*crane.model, {}, options), InputError);
  TestRecord shifted = test;
  shifted.record.start_time_s = -0.005;  // half a sample before the excitation
  EXPECT_THROW(UpdateModel(*crane.model, {shifted}, options), InputError);
  TestRecord drift_alone = test;
  drift_alone.fit_drift = true;  // a drift needs its offset
  EXPECT_THROW(UpdateModel(*crane.model, {drift_alone}, options), InputError);
  TestRecord unknown_noise = test;
  unknown_noise.noise_std["gamma_dot"] = 1e-5;
  EXPECT_THROW(UpdateModel(*crane.model, {unknown_noise}, options), InputError);
  TestRecord not_a_drop = test;
  not_a_drop.fit_payload_mass = true;
  EXPECT_THROW(UpdateModel(*crane.model, {not_a_drop}, options), InputError);
}

}  // namespace
}  // namespace mbid::updating
