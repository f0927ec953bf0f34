// The model's exact linear modes against the modes identified from its simulated free decay:
// two independent routes (eigenvalues of M, D, C vs CVODES + Simbody + the identifier).
#include <gtest/gtest.h>

#include <cmath>

#include "mbid/common/yaml_reader.h"
#include "mbid/identification/identify.h"
#include "mbid/model/model_factory.h"
#include "mbid/simulation/scenario_sections.h"
#include "mbid/simulation/simulate.h"

namespace mbid {
namespace {

struct Case {
  std::string scenario;
  std::vector<int> modes;   // which exact modes are checked
  bool every_mode_checked;  // the record shows exactly these modes
};

// The excitation is scaled down 100x from the scenario's: the linear modes describe small
// motions, and at the scenario's 4e-3..7e-3 rad the second-order terms of the outputs (products
// of joint angles, ~1.6e-5 rad at sum and difference frequencies) shift the heavily damped
// 2.26 Hz mode's estimate by 1.4% (measured: 2.2956 Hz from the noiseless record at full
// amplitude, 2.26333 at 1/100; docs/validation.md).
constexpr double kScale = 0.01;

void ExpectIdentifiedModesMatchExact(const Case& test_case, double noise_std_rad) {
  const YamlReader root =
      YamlReader::FromFile(std::string(MBID_SOURCE_DIR) + "/scenarios/" + test_case.scenario);
  const auto model = model::MakeModel(root.Child("model"));
  simulation::Excitation excitation = simulation::ReadExcitation(root.Child("excitation"), *model);
  if (auto* drop = excitation.get_if<simulation::LoadDrop>()) drop->payload_mass_kg *= kScale;
  if (auto* deflection = excitation.get_if<simulation::InitialDeflection>()) {
    for (auto& [coordinate, angle] : deflection->deflection_rad) angle *= kScale;
  }
  simulation::SimulationOptions options =
      simulation::ReadSimulationOptions(root.Child("simulation"));
  options.integrator.relative_tolerance = 1e-10;  // integration error far below the noise
  options.integrator.absolute_tolerance = 1e-16;  // amplitudes ~4e-5 rad
  simulation::SensorOptions sensors = simulation::ReadSensorOptions(root.Child("sensors"), *model);
  // The noise in each channel's unit: angles get `noise_std_rad`; accelerations (m/s^2, about
  // (2 pi f)^2 * 7 m ~ 1e3 times an angle's size on the excavator) 1e3 times as much.
  sensors.noise_std.clear();
  for (size_t i = 0; i < model->output_names().size(); ++i) {
    const std::string& unit = model->output_units()[i];
    sensors.noise_std[model->output_names()[i]] =
        unit == "rad" ? noise_std_rad : 1e3 * noise_std_rad;
  }
  const simulation::SimulationResult record = Simulate(*model, excitation, options, sensors);

  identification::IdentificationOptions identify;
  const identification::ModalResult identified =
      identification::Identify(record.measured, identify);
  const std::vector<model::Mode> exact = model::CalcModes(model->Linearize());
  ASSERT_GE(identified.modes.size(), test_case.modes.size());
  if (test_case.every_mode_checked) {
    ASSERT_EQ(identified.modes.size(), test_case.modes.size());
  }
  for (int index : test_case.modes) {
    const model::Mode& truth = exact[index];
    // The identified mode nearest in frequency.
    const identification::IdentifiedMode* nearest = &identified.modes[0];
    for (const auto& candidate : identified.modes) {
      if (std::abs(candidate.frequency_hz - truth.frequency_hz()) <
          std::abs(nearest->frequency_hz - truth.frequency_hz())) {
        nearest = &candidate;
      }
    }
    const identification::IdentifiedMode& mode = *nearest;
    const int k = index;
    // The bound: 0.5% in frequency and decay (the remaining nonlinearity at 4e-5 rad
    // shifts them by ~2e-5 relative).
    EXPECT_NEAR(mode.frequency_hz, truth.frequency_hz(), 0.005 * truth.frequency_hz()) << k;
    EXPECT_NEAR(mode.decay_rate_per_s, truth.decay_rate_per_s(), 0.005 * truth.decay_rate_per_s())
        << k;
  }
}

// A sensor noise of 1e-9 rad, 1/500 of the smallest modal amplitude (2.26 Hz in phi, 5.8e-7
// rad at this scale): what remains of the nonlinearity and of the integration error (~1e-10
// relative) sits below it instead of being fitted as extra modes.
constexpr double kNoiseStd = 1e-9;

TEST(ModesVsDecayTest, InitialDeflectionShowsAllFourExactModes) {
  ExpectIdentifiedModesMatchExact({"reference-crane.yaml", {0, 1, 2, 3}, true}, kNoiseStd);
}

TEST(ModesVsDecayTest, LoadDropShowsTheModesItExcites) {
  // reference-crane.md: the drop excites mainly the 0.58 and 1.51 Hz modes; the 2.26 and 3.09 Hz
  // ones stay 350 times smaller (SNR ~45 dB here), too weak for 0.5% in decay: check the two.
  ExpectIdentifiedModesMatchExact({"reference-crane-load-drop.yaml", {0, 1}, false}, kNoiseStd);
}

TEST(ModesVsDecayTest, ExcavatorDescriptionShowsItsThreeModes) {
  // A machine from a description (scenarios/excavator-arm.yaml: weld, two inclinometers, two
  // accelerometer axes). The accelerations carry the arm's centripetal terms, quadratic in the
  // rates: sum-frequency components (3.04 + 7.42 = 10.46 Hz) ~1e-4 of the modes at this scale,
  // above the noise, so extra poles are allowed; the three exact modes must be found.
  ExpectIdentifiedModesMatchExact({"excavator-arm.yaml", {0, 1, 2}, false}, kNoiseStd);
}

}  // namespace
}  // namespace mbid
