// The reference crane's 8 s decay at boom elevations of a campaign sweep: four modes, as its
// linearization has, with no false pair and no mode taken for a combination tone. The cases are
// those of a campaign (elevation, noise seed) where both once happened: the record's slight
// amplitude dependence made the close-mode score significant and its split kept an undetermined
// pole (5 modes, unreliable; 3 cases in 20), and the weak, heavily damped third mode, near
// f1 + f2 or f4 - f1, was marked a tone (5 cases in 20).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "mbid/identification/identify.h"
#include "scenario_record.h"

namespace mbid {
namespace {

struct SweepCase {
  double elevation_deg;
  std::uint64_t seed;
};

// scenarios/reference-crane.yaml at another elevation and noise seed; returns its warnings.
// Unless `reasons` is given, the result must be reliable; else it gets the reasons.
std::vector<std::string> ExpectTheFourExactModes(const SweepCase& sweep_case,
                                                 std::vector<std::string>* reasons = nullptr) {
  const std::string scenario = testing::ShippedScenarioText(
      "reference-crane.yaml", "boom_elevation_deg: 16.0",
      "boom_elevation_deg: " + std::to_string(sweep_case.elevation_deg));
  const testing::ScenarioRecord simulated = testing::SimulateScenario(
      YamlReader::FromString(scenario, "reference-crane.yaml"), sweep_case.seed);
  const model::MechanicalModel* model = simulated.model.get();
  const simulation::SimulationResult& record = simulated.record;

  const identification::ModalResult identified =
      identification::Identify(record.measured, identification::IdentificationOptions{});
  const std::vector<model::Mode> exact = model::CalcModes(model->Linearize());
  EXPECT_EQ(exact.size(), 4u);
  EXPECT_EQ(identified.modes.size(), 4u);
  if (exact.size() != 4 || identified.modes.size() != 4) return identified.warnings;
  if (reasons == nullptr) {
    EXPECT_TRUE(identified.reliable) << ::testing::PrintToString(identified.reasons);
  } else {
    *reasons = identified.reasons;
  }
  for (size_t k = 0; k < 4; ++k) {
    const identification::IdentifiedMode& mode = identified.modes[k];
    EXPECT_TRUE(mode.combination.empty()) << mode.frequency_hz << " Hz: " << mode.combination;
    // Within 5 standard deviations plus 2 % of the exact mode: the 4-7 mrad deflection's
    // second-order terms move the heavily damped third mode by 1.4 % (modes_vs_decay_test.cc).
    EXPECT_NEAR(mode.frequency_hz, exact[k].frequency_hz(),
                5 * mode.std_frequency_hz + 0.02 * exact[k].frequency_hz())
        << k;
  }
  return identified.warnings;
}

TEST(CraneElevationTest, AModeThatDriftsWithAmplitudeIsNoHiddenPair) {
  // 40 deg, seed 936228567: the 0.71 Hz mode leaves the Taylor terms of a drift in its own shape
  // (close-mode score 39.9 against 26.1 when the shape is not taken out; 6.9 against 18.5 when
  // it is). Split, it gave 0.7072 +- 0.0025 Hz and 0.4175 +- 0.075 Hz, decay 1.52 +- 0.58 1/s.
  const std::vector<std::string> warnings = ExpectTheFourExactModes({40, 936228567});
  EXPECT_FALSE(testing::Mentions(warnings, "found by splitting"))
      << ::testing::PrintToString(warnings);
}

TEST(CraneElevationTest, ASplitWhosePoleTheRecordCannotPlaceIsRefused) {
  // 25 deg, seed 1471176023: the 2.27 Hz mode's residual has a shape of its own (score 19.5,
  // threshold 18.5); split, its second pole went to 1.33 +- 0.20 Hz, 3.4 +- 1.1 1/s, and was
  // kept as a fifth mode. Refused, the four modes stand and the result says why it is doubtful.
  std::vector<std::string> reasons;
  ExpectTheFourExactModes({25, 1471176023}, &reasons);
  EXPECT_TRUE(
      testing::Mentions(reasons, "the record does not determine the two modes it splits into"))
      << ::testing::PrintToString(reasons);
}

TEST(CraneElevationTest, AWeakModeNearASumIsNoCombinationTone) {
  // 45 deg, seed 1750952045: the third mode (2.21 Hz, 3.0 1/s exact) was identified at
  // 2.27 +- 0.03 Hz, matching f1 + f2 = 2.23 Hz, with 5.5 % of f2's amplitude; this record's
  // 0.77 Hz mode also has a significant close-mode score.
  EXPECT_TRUE(testing::Mentions(ExpectTheFourExactModes({45, 1750952045}),
                                "lies where a combination tone would (f1 + f2"));
  // 35 deg, seed 1138335979: the third mode near f4 - f1, with 18 % of f1's amplitude.
  EXPECT_TRUE(testing::Mentions(ExpectTheFourExactModes({35, 1138335979}),
                                "lies where a combination tone would (f4 - f1"));
}

}  // namespace
}  // namespace mbid
