// Next-test planning (updating/plan.h): the D-optimal score's exact properties on the torsional
// oscillator, and the reference crane's worked example of docs/planning.md: after the paper's
// 650 kg load drop, which next test determines d_eta, checked by fitting that test's record.
#include "mbid/updating/plan.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "crane_fixture.h"
#include "mbid/common/error.h"
#include "mbid/common/yaml_reader.h"
#include "mbid/model/model_factory.h"
#include "oscillator_fixture.h"

namespace mbid::updating {
namespace {

using testing::MakeOscillator;

TestDesign Release(const std::string& name, double deflection_rad, double noise_rad) {
  return testing::OscillatorRelease(name, deflection_rad, noise_rad);
}

TEST(PlanTest, RanksByLogDetWithoutRecordedTests) {
  const auto oscillator = MakeOscillator();
  const std::vector<PlanCandidate> candidates{
      {"loud", nullptr, Release("loud", 0.01, 1e-3)},
      {"still", nullptr, Release("still", 0.0, 1e-4)},  // nothing moves: no information
      {"quiet", nullptr, Release("quiet", 0.01, 1e-4)}};
  const TestPlan plan = PlanNextTest(*oscillator, {}, candidates, PlanOptions());
  ASSERT_EQ(plan.candidates.size(), 3u);
  EXPECT_EQ(plan.parameters, (std::vector<std::string>{"c_angle", "d_angle"}));
  EXPECT_EQ(plan.recorded_tests, 0);
  EXPECT_TRUE(std::isnan(plan.recorded_score));
  EXPECT_EQ(plan.candidates[0].name, "quiet");
  EXPECT_EQ(plan.candidates[1].name, "loud");
  EXPECT_EQ(plan.candidates[2].name, "still");
  // F ~ 1 / sigma^2: ten times less noise is 100 times F in each of the 2 dimensions, so the
  // log det differs by 2 ln 100 (the ridge, 1e-12 of the diagonal, changes it by ~1e-12), and
  // every standard deviation by 10.
  EXPECT_NEAR(plan.candidates[0].score - plan.candidates[1].score, 2 * std::log(100.0), 1e-8);
  for (int k = 0; k < 2; ++k) {
    EXPECT_NEAR(plan.candidates[1].relative_std[k] / plan.candidates[0].relative_std[k], 10.0,
                1e-8);
    EXPECT_TRUE(plan.candidates[0].determined[static_cast<size_t>(k)]);
  }
  // No information at all: -inf, both parameters undetermined, no gain without records.
  EXPECT_TRUE(std::isinf(plan.candidates[2].score) && plan.candidates[2].score < 0);
  EXPECT_TRUE(std::isinf(plan.candidates[2].relative_std[0]));
  EXPECT_FALSE(plan.candidates[2].determined[0]);
  EXPECT_TRUE(std::isnan(plan.candidates[0].gain));
}

TEST(PlanTest, RepeatingTheRecordedTestHalvesTheVariance) {
  // The recorded test made again: F doubles, so the gain is 2 ln 2 (two parameters) and each
  // standard deviation shrinks by sqrt(2) from the recorded one.
  const auto oscillator = MakeOscillator();
  const TestPlan plan =
      PlanNextTest(*oscillator, {Release("recorded", 0.01, 1e-4)},
                   {{"again", nullptr, Release("again", 0.01, 1e-4)}}, PlanOptions());
  ASSERT_EQ(plan.candidates.size(), 1u);
  EXPECT_EQ(plan.recorded_tests, 1);
  EXPECT_NEAR(plan.candidates[0].gain, 2 * std::log(2.0), 1e-8);
  EXPECT_NEAR(plan.candidates[0].score - plan.recorded_score, 2 * std::log(2.0), 1e-8);
  for (int k = 0; k < 2; ++k) {
    EXPECT_NEAR(plan.candidates[0].relative_std[k] * std::sqrt(2.0), plan.current_relative_std[k],
                1e-8 * plan.current_relative_std[k]);
  }
}

TEST(PlanTest, CandidateModelsTakeThePlansParameterValues) {
  // A candidate on its own model (here the same oscillator with another stiffness, as a
  // configuration override would give) is evaluated at the plan's values of the tuned
  // parameters: its information equals that of the plan's model, to the integration's
  // reproducibility (bit-identical inputs: exactly).
  const auto oscillator = MakeOscillator();
  std::shared_ptr<const model::MechanicalModel> other = MakeOscillator(1234.0);
  const TestPlan plan = PlanNextTest(*oscillator, {},
                                     {{"own model", other, Release("own", 0.01, 1e-4)},
                                      {"plan model", nullptr, Release("plan", 0.01, 1e-4)}},
                                     PlanOptions());
  EXPECT_EQ(plan.candidates[0].fisher, plan.candidates[1].fisher);
  EXPECT_EQ(plan.values[0], 800.0);
}

// The worked example of docs/planning.md. The paper's 650 kg load drop
// (reference-crane-load-drop.yaml, 8 s at 100 Hz, 1e-5 rad noise) hardly excites the 2.26 and
// 3.09 Hz modes, so its fit leaves d_eta undetermined (docs/validation.md). Three next tests
// are candidates: a second drop at twice the mass, a release from a deflection of the boom's
// yaw joint eta alone, and a short torque pulse on the slewing joint gamma. The plan must rank
// first one that determines d_eta, and fitting that test's record beside the drop must report
// the standard deviation the plan expected.
TEST(PlanCraneTest, AfterThePapersLoadDropAnEtaDeflectionDeterminesDEta) {
  const testing::Crane drop = testing::LoadCrane(testing::kLoadDropScenario);
  UpdateOptions options;
  options.quiet = true;
  options.threads = 2;  // the test machine's two cores
  options.integrator = drop.simulation.integrator;
  options.integrator.interpolate_outputs = true;
  // The recorded drop with the scenario's sensor noise (seed 1), fitted from the truth: the
  // point is the information at the record's own minimum, not the path to it.
  const Measurement drop_record =
      simulation::Simulate(*drop.model, drop.excitation, drop.simulation, drop.sensors).measured;
  const TestRecord recorded{"drop-650kg", drop_record, drop.excitation, drop.sensors.noise_std};
  const UpdateResult first = UpdateModel(*drop.model, {recorded}, options);
  ASSERT_EQ(first.termination, UpdateResult::Termination::kConverged) << first.message;
  // The drop alone: d_eta undetermined (relative std above UpdateModel's 0.3).
  EXPECT_FALSE(first.Find("d_eta").determined);
  auto estimate = drop.model->Clone();
  ApplyEstimates(first, *estimate);

  // The candidates: the drop's length, rate, channels and noise.
  auto candidate = [&](const std::string& name, const simulation::Excitation& excitation) {
    TestDesign design;
    design.name = name;
    design.excitation = excitation;
    design.simulation = drop.simulation;
    design.sensors = drop.sensors;
    return PlanCandidate{name, nullptr, design};
  };
  simulation::Excitation heavier = drop.excitation;
  heavier.get<simulation::LoadDrop>().payload_mass_kg = 1300.0;
  simulation::InitialDeflection eta;
  eta.deflection_rad["eta"] = 0.004;  // the reference scenario's eta deflection, eta alone
  simulation::Impulse pulse;
  pulse.target.coordinate = "gamma";
  pulse.target.torque_Nm = 2e4;  // 50 ms half sine: gamma's response ~1e-3 rad, the drop's order
  pulse.duration_s = 0.05;
  PlanOptions plan_options;
  plan_options.threads = 2;
  const TestPlan plan = PlanNextTest(
      *estimate, {MakeRecordedDesign(recorded, first.tests[0].noise_std, options.integrator)},
      {candidate("drop-1300kg", heavier), candidate("deflect-eta", eta),
       candidate("impulse-slewing", pulse)},
      plan_options);
  ASSERT_EQ(plan.candidates.size(), 3u);
  const auto d_eta = static_cast<Eigen::Index>(
      std::find(plan.parameters.begin(), plan.parameters.end(), "d_eta") - plan.parameters.begin());
  // The recorded drop alone: the plan's current std is UpdateModel's (same J^T J from its own
  // integration, equal to roundoff; d_eta is the least determined direction, 32%, where
  // (J^T J)^-1 magnifies roundoff of 1e-9 in J to about 2e-6): 1e-5.
  EXPECT_NEAR(plan.current_relative_std[d_eta], first.Find("d_eta").relative_std,
              1e-5 * first.Find("d_eta").relative_std);
  std::string ranking;
  for (const CandidateScore& score : plan.candidates) {
    ranking += score.name + " " + std::to_string(score.score) + " d_eta " +
               std::to_string(score.relative_std[d_eta]) + "; ";
  }
  RecordProperty("ranking", ranking);
  const CandidateScore& best = plan.candidates[0];
  EXPECT_EQ(best.name, "deflect-eta") << ranking;
  // Measured 0.0115 (the pulse 0.044, the heavier drop 0.14): eta's own release puts the 2.26
  // and 3.09 Hz modes far above the noise. 0.05 is well below the 0.3 of "determined" and four
  // times the measured value.
  EXPECT_LT(best.relative_std[d_eta], 0.05) << ranking;
  for (bool determined : best.determined) EXPECT_TRUE(determined) << ranking;
  EXPECT_GT(best.gain, 0);

  // The claim checked: the candidate's record (simulated at the truth, its own noise seed)
  // fitted with the drop from the first estimate; UpdateModel's reported std of d_eta must be
  // what the plan expected within a factor 2 (the plan's F is at the drop's estimate, d_eta
  // there ~2x the truth; the new fit's at its own estimate).
  simulation::SensorOptions sensors = drop.sensors;
  sensors.seed = 2;
  const Measurement eta_record =
      simulation::Simulate(*drop.model, eta, drop.simulation, sensors).measured;
  UpdateOptions joint = options;
  for (const ParameterEstimate& p : first.parameters) {
    ParameterSetting setting;
    setting.name = p.name;
    setting.initial = p.value;
    joint.parameters.push_back(setting);
  }
  const UpdateResult both = UpdateModel(
      *drop.model, {recorded, {"deflect-eta", eta_record, eta, drop.sensors.noise_std}}, joint);
  ASSERT_EQ(both.termination, UpdateResult::Termination::kConverged) << both.message;
  const ParameterEstimate& fitted = both.Find("d_eta");
  RecordProperty("fitted_d_eta_relative_std", std::to_string(fitted.relative_std));
  EXPECT_TRUE(fitted.determined);
  EXPECT_LT(fitted.relative_std, 2 * best.relative_std[d_eta]);
  EXPECT_GT(fitted.relative_std, 0.5 * best.relative_std[d_eta]);
  // The factor 2 is the linearization point: the same plan at the truth (where the joint fit
  // ends, d_eta 44000 instead of the drop alone's ~2x) expects what the fit reports (measured:
  // 0.0191 at the truth, 0.0115 at the drop's estimate, the fit 0.0192). 10% allowed: the fit's
  // estimate lies off the truth by its own errors (d_eta's std ~2%, the others' below), which
  // move the information by about as much.
  const TestPlan at_truth = PlanNextTest(
      *drop.model, {MakeRecordedDesign(recorded, first.tests[0].noise_std, options.integrator)},
      {candidate("deflect-eta", eta)}, plan_options);
  const double expected_at_truth = at_truth.candidates[0].relative_std[d_eta];
  RecordProperty("expected_d_eta_relative_std_at_truth", std::to_string(expected_at_truth));
  EXPECT_NEAR(fitted.relative_std, expected_at_truth, 0.1 * expected_at_truth);
  // And the value: within 4 of its standard deviations of the truth (44000 N m s/rad).
  EXPECT_LT(std::abs(fitted.value - drop.model->GetParameter("d_eta")), 4 * fitted.std);
}

// A trial's plan ranked a test that deflects a gantry's roll but records no sensor that sees
// it, and promised c_roll to 2 %: the model's nonlinear coupling gives the Fisher matrix some
// information, which no fit can use (the test, run, found no mode at all). The excavator arm's
// swing is such a mode for its two inclinometers (UnseenModesTest): a release of all three
// joints recorded by them alone leaves c_swing and d_swing undetermined; with the lateral
// accelerometer, determined.
TEST(PlanTest, ACandidateThatDoesNotSeeAModeDeterminesNoneOfItsParameters) {
  const auto arm = model::MakeModel(
      YamlReader::FromFile(std::string(MBID_SOURCE_DIR) + "/scenarios/excavator-arm.yaml")
          .Child("model"));
  const auto release = [](const std::string& name, const std::vector<std::string>& channels) {
    TestDesign design;
    design.name = name;
    simulation::InitialDeflection deflection;
    deflection.deflection_rad = {{"swing", 0.002}, {"boom", -0.0015}, {"stick", 0.002}};
    design.excitation = deflection;
    design.simulation.duration_s = 2.0;
    design.sensors.sample_rate_hz = 100.0;
    design.sensors.channels = channels;
    for (const std::string& channel : channels) {
      design.sensors.noise_std[channel] = channel == "a_bucket_y" ? 2e-3 : 1e-5;
    }
    return design;
  };
  const std::vector<PlanCandidate> candidates{
      {"inclinometers", nullptr, release("inclinometers", {"boom_incl", "stick_incl"})},
      {"lateral", nullptr, release("lateral", {"boom_incl", "stick_incl", "a_bucket_y"})}};
  const TestPlan plan = PlanNextTest(*arm, {}, candidates, PlanOptions());
  for (const CandidateScore& candidate : plan.candidates) {
    SCOPED_TRACE(candidate.name);
    const bool blind = candidate.name == "inclinometers";
    const std::vector<std::string> expected_unseen =
        blind ? std::vector<std::string>{"c_swing", "d_swing"} : std::vector<std::string>{};
    EXPECT_EQ(candidate.unseen, expected_unseen);
    for (size_t k = 0; k < plan.parameters.size(); ++k) {
      const bool swing = plan.parameters[k] == "c_swing" || plan.parameters[k] == "d_swing";
      EXPECT_EQ(candidate.determined[k], !(blind && swing)) << plan.parameters[k];
      // Left out of what the candidate adds, so of its score too.
      if (blind && swing) {
        EXPECT_TRUE(candidate.fisher.row(static_cast<Eigen::Index>(k)).isZero())
            << plan.parameters[k];
      }
    }
  }
}

TEST(PlanTest, RejectsNoCandidates) {
  const auto oscillator = MakeOscillator();
  EXPECT_THROW(PlanNextTest(*oscillator, {}, {}, PlanOptions()), InputError);
}

}  // namespace
}  // namespace mbid::updating
