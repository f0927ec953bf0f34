// The shipped excavator arm's pull-release record: three modes, as its linearization has, and no
// fourth one of the structure. Its bucket accelerometer sees the products of the modes (2 f3,
// 3 f2, 2 f1 + f3 and more, 12.7-15.3 Hz) at a few times the noise; in 14 of 40 noise seeds one
// pole fitted to them landed between them (12.9-14.3 Hz, +- 0.1 Hz), matched no single sum and
// was reported as a reliable fourth mode. The seeds are four of those.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "mbid/identification/identify.h"
#include "scenario_record.h"

namespace mbid {
namespace {

// The identified modes that are no combination tone: three, each within 5 standard deviations
// plus 0.5 % of the linearization's (2 and 10 mrad deflections move the modes by under 0.1 %:
// the noiseless records' modes against it).
void ExpectTheThreeExactModes(const testing::ScenarioRecord& simulated,
                              const identification::ModalResult& identified) {
  const std::vector<model::Mode> exact = model::CalcModes(simulated.model->Linearize());
  ASSERT_EQ(exact.size(), 3u);
  std::vector<identification::IdentifiedMode> modes;
  for (const identification::IdentifiedMode& mode : identified.modes) {
    if (mode.combination.empty()) modes.push_back(mode);
  }
  ASSERT_EQ(modes.size(), 3u) << ::testing::PrintToString(identified.warnings);
  for (size_t k = 0; k < 3; ++k) {
    EXPECT_NEAR(modes[k].frequency_hz, exact[k].frequency_hz(),
                5 * modes[k].std_frequency_hz + 0.005 * exact[k].frequency_hz())
        << k;
  }
}

class ExcavatorProductsTest : public ::testing::TestWithParam<std::uint64_t> {};

TEST_P(ExcavatorProductsTest, ProductsOfTheModesAreNoFourthMode) {
  const testing::ScenarioRecord simulated = testing::SimulateScenario(
      YamlReader::FromString(testing::ShippedScenarioText("excavator-arm.yaml"),
                             "excavator-arm.yaml"),
      GetParam());
  const identification::ModalResult identified =
      identification::Identify(simulated.record.measured, identification::IdentificationOptions{});
  ExpectTheThreeExactModes(simulated, identified);
  // The component between the products is still reported, marked, and the warning says why.
  EXPECT_TRUE(testing::Mentions(identified.warnings, "beside the products of the modes' poles"))
      << ::testing::PrintToString(identified.warnings);
  // A tone, even an undetermined one, is no reason to distrust the three modes.
  EXPECT_TRUE(identified.reliable) << ::testing::PrintToString(identified.reasons);
}

// Seeds of the 40-case campaign of scenarios/excavator-arm.yaml whose fourth "mode" was at
// 14.05 Hz (1705094727), 13.27 Hz (2085212535), 13.09 Hz (936228567) and 12.93 Hz (852914484);
// 93948706 had it at 14.02 Hz and an undetermined one at 8.07 Hz (f2 + f3 - f1) that made the
// result unreliable.
INSTANTIATE_TEST_SUITE_P(CampaignSeeds, ExcavatorProductsTest,
                         ::testing::Values(1705094727u, 2085212535u, 936228567u, 852914484u,
                                           93948706u));

// The same arm released from 5 times the deflection (10 mrad, a harder pull): its tones f1 + f3
// and 2 f3 have 3-4 % of their stronger parent's amplitude, above a tone of small vibrations
// (2 %); in 28 of 40 seeds one was reported as a reliable fourth mode. Three of those seeds.
class ExcavatorLargeVibrationTest : public ::testing::TestWithParam<std::uint64_t> {};

TEST_P(ExcavatorLargeVibrationTest, TonesOfALargeReleaseAreNoFourthMode) {
  const std::string scenario = testing::ShippedScenarioText(
      "excavator-arm.yaml", "deflection_rad: {swing: 0.002, boom: -0.0015, stick: 0.002}",
      "deflection_rad: {swing: 0.01, boom: -0.0075, stick: 0.01}");
  const testing::ScenarioRecord simulated =
      testing::SimulateScenario(YamlReader::FromString(scenario, "excavator-arm.yaml"), GetParam());
  const identification::ModalResult identified =
      identification::Identify(simulated.record.measured, identification::IdentificationOptions{});
  ExpectTheThreeExactModes(simulated, identified);
  EXPECT_TRUE(testing::Mentions(identified.warnings, "the test's vibrations were large"))
      << ::testing::PrintToString(identified.warnings);
}

INSTANTIATE_TEST_SUITE_P(CampaignSeeds, ExcavatorLargeVibrationTest,
                         ::testing::Values(1216681718u, 867888699u, 1463950283u));

}  // namespace
}  // namespace mbid
