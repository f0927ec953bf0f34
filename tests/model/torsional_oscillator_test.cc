// The one-joint model (its machine description, as `type: torsional_oscillator` expands)
// against its closed form.
#include "mbid/model/torsional_oscillator.h"

#include <gtest/gtest.h>

#include <cmath>

#include "mbid/common/error.h"
#include "mbid/common/yaml_reader.h"
#include "mbid/model/model_factory.h"

namespace mbid::model {
namespace {

TEST(TorsionalOscillatorTest, ModesAreTheClosedForm) {
  // J = 2, c = 800, d = 8: lambda = -2 +- i sqrt(400 - 4) (1/s).
  const MultibodyModel oscillator = MakeTorsionalOscillator({2.0, 800.0, 8.0});
  const std::vector<Mode> modes = CalcModes(oscillator.Linearize());
  ASSERT_EQ(modes.size(), 1u);
  EXPECT_NEAR(modes[0].lambda.real(), -2.0, 1e-12);
  EXPECT_NEAR(modes[0].lambda.imag(), std::sqrt(396.0), 1e-12);
  EXPECT_NEAR(modes[0].damping_ratio(), 8.0 / (2 * std::sqrt(800.0 * 2.0)), 1e-14);
  EXPECT_NEAR(oscillator.Linearize().M(0, 0), 2.0, 1e-14);  // Simbody's M is J
}

TEST(TorsionalOscillatorTest, OverdampedPolesAreReal) {
  // d^2 > 4 J c: two real poles -d/2J +- sqrt((d/2J)^2 - c/J) = -5 +- 3.
  const MultibodyModel oscillator = MakeTorsionalOscillator({1.0, 16.0, 10.0});
  const std::vector<Mode> modes = CalcModes(oscillator.Linearize());
  ASSERT_EQ(modes.size(), 2u);
  EXPECT_NEAR(modes[0].lambda.real(), -2.0, 1e-12);
  EXPECT_NEAR(modes[1].lambda.real(), -8.0, 1e-12);
}

TEST(TorsionalOscillatorTest, RimLoadEquilibriumSolvesTheNonlinearBalance) {
  // c theta = F cos(theta) at the rim (1 m): the residual vanishes to roundoff of c theta.
  const MultibodyModel oscillator = MakeTorsionalOscillator({1.0, 100.0, 1.0});
  const double F = 50.0;
  const double theta = oscillator.SolveStaticEquilibrium({{"rim", {0, F, 0}}})[0];
  EXPECT_NEAR(100.0 * theta, F * std::cos(theta), 1e-13);
  EXPECT_GT(theta, 0.4);  // a large deflection, far from the linear guess 0.5 only by cos
}

TEST(TorsionalOscillatorTest, ReadsFromScenario) {
  const YamlReader model = YamlReader::FromString(
      "type: torsional_oscillator\ninertia_kgm2: 3.0\n"
      "joints: {angle: {stiffness_Nm_per_rad: 30.0, damping_Nms_per_rad: 0.6}}\n",
      "inline.yaml");
  const auto oscillator = MakeModel(model);
  EXPECT_EQ(oscillator->type(), "torsional_oscillator");
  EXPECT_EQ(oscillator->GetParameter("c_angle"), 30.0);
  EXPECT_EQ(oscillator->GetParameter("d_angle"), 0.6);
  EXPECT_THROW(MakeModel(YamlReader::FromString("type: torsional_oscillator\ninertia_kgm2: -1\n"
                                                "joints: {angle: {stiffness_Nm_per_rad: 1}}\n",
                                                "inline.yaml")),
               InputError);
}

}  // namespace
}  // namespace mbid::model
