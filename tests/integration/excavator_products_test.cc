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

class ExcavatorProductsTest : public ::testing::TestWithParam<std::uint64_t> {};

TEST_P(ExcavatorProductsTest, ProductsOfTheModesAreNoFourthMode) {
  const testing::ScenarioRecord simulated = testing::SimulateScenario(
      YamlReader::FromFile(std::string(MBID_SOURCE_DIR) + "/scenarios/excavator-arm.yaml"),
      GetParam());
  const model::MechanicalModel* model = simulated.model.get();
  const simulation::SimulationResult& record = simulated.record;
  const identification::ModalResult identified =
      identification::Identify(record.measured, identification::IdentificationOptions{});

  const std::vector<model::Mode> exact = model::CalcModes(model->Linearize());
  ASSERT_EQ(exact.size(), 3u);
  std::vector<identification::IdentifiedMode> modes;
  for (const identification::IdentifiedMode& mode : identified.modes) {
    if (mode.combination.empty()) modes.push_back(mode);
  }
  ASSERT_EQ(modes.size(), 3u) << ::testing::PrintToString(identified.warnings);
  for (size_t k = 0; k < 3; ++k) {
    // Within 5 standard deviations plus 0.5 %: the 2 mrad deflection's second-order terms move
    // the modes by under 0.1 % (the noiseless record's modes against the linearization).
    EXPECT_NEAR(modes[k].frequency_hz, exact[k].frequency_hz(),
                5 * modes[k].std_frequency_hz + 0.005 * exact[k].frequency_hz())
        << k;
  }
  // The component between the products is still reported, marked, and the warning says why.
  const bool explained = std::any_of(
      identified.warnings.begin(), identified.warnings.end(), [](const std::string& warning) {
        return warning.find("beside the products of the modes' poles") != std::string::npos;
      });
  EXPECT_TRUE(explained) << ::testing::PrintToString(identified.warnings);
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

}  // namespace
}  // namespace mbid
