// Next-test planning (updating/plan.h): the D-optimal score's exact properties on the torsional
// oscillator, and the reference crane's worked example of docs/planning.md: after the paper's
// 650 kg load drop, which next test determines d_eta, checked by fitting that test's record.
#include "mbid/identification/updating/plan.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "crane_fixture.h"
#include "mbid/common/error.h"
#include "mbid/common/yaml_reader.h"
#include "mbid/model/model_factory.h"

namespace mbid::updating {
namespace {

// The oscillator of fisher_test.cc: omega_0 = 20 rad/s, damping ratio 0.1, 2 s at 100 Hz.
std::unique_ptr<model::MechanicalModel> MakeOscillator(double stiffness = 800.0) {
  return model::MakeModel(
      YamlReader::FromString("type: torsional_oscillator\ninertia_kgm2: 2.0\n"
                             "joints: {angle: {stiffness_Nm_per_rad: " +
                                 std::to_string(stiffness) + ", damping_Nms_per_rad: 8.0}}\n",
                             "oscillator"));
}

TestDesign Release(const std::string& name, double deflection_rad, double noise_rad) {
  TestDesign design;
  design.name = name;
  design.excitation.type = simulation::Excitation::Type::kInitialDeflection;
  design.excitation.deflection_rad["angle"] = deflection_rad;
  design.simulation.duration_s = 2.0;
  design.simulation.integrator.method = simulation::IntegratorOptions::Method::kBdf;
  design.sensors.sample_rate_hz = 100.0;
  design.sensors.channels = {"angle"};
  design.sensors.noise_std["angle"] = noise_rad;
  return design;
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

TEST(PlanTest, RejectsNoCandidates) {
  const auto oscillator = MakeOscillator();
  EXPECT_THROW(PlanNextTest(*oscillator, {}, {}, PlanOptions()), InputError);
}

}  // namespace
}  // namespace mbid::updating
