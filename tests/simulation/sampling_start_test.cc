// The sampling start (SensorOptions::start_time_s): records whose first sample lies after the
// excitation's t = 0, on the whole-sample grid (bit for bit the rows of a record from t = 0) or
// between two samples (a record cut at a detected release).
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

#include "mbid/common/yaml_reader.h"
#include "mbid/model/model_factory.h"
#include "mbid/simulation/scenario_sections.h"
#include "mbid/simulation/sensitivity.h"
#include "mbid/simulation/simulate.h"

namespace mbid::simulation {
namespace {

const std::string kSamplingCraneYaml =
    std::string(MBID_SOURCE_DIR) + "/scenarios/reference-crane.yaml";

struct SampledCrane {
  std::unique_ptr<model::MechanicalModel> model;
  Excitation excitation;
  SimulationOptions simulation;
};

SampledCrane LoadSampledCrane() {
  const YamlReader root = YamlReader::FromFile(kSamplingCraneYaml);
  SampledCrane crane;
  crane.model = model::MakeModel(root.Child("model"));
  crane.excitation = ReadExcitation(root.Child("excitation"), *crane.model);
  crane.simulation = ReadSimulationOptions(root.Child("simulation"));
  return crane;
}

std::string Sci(double value) {
  std::ostringstream out;
  out.precision(2);
  out << std::scientific << value;
  return out.str();
}

SensorOptions Sensors(double rate_hz, double start_s = 0.0) {
  SensorOptions sensors;
  sensors.sample_rate_hz = rate_hz;
  sensors.start_time_s = start_s;
  sensors.channels = {"psi", "phi"};
  return sensors;
}

// A lateral burst at the boom tip for 2 s (3 cycles at 1.5 Hz): the forced stretch stops at
// every sample, so a whole-sample start must still visit the skipped ones.
Excitation BoomTipBurst() {
  Burst burst;
  burst.target.point = "boom_tip";
  burst.target.force_N = Eigen::Vector3d(0, 2000, 0);
  burst.frequency_hz = 1.5;
  burst.cycles = 3;
  return burst;
}

TEST(SamplingStartTest, WholeSampleStartKeepsTheBitsOfTheRecordFromThatSample) {
  // 3 s at 50 Hz (151 samples). The free decay of the reference crane (dense output) from
  // sample 7, and the burst from sample 60 (1.2 s, inside the forcing, which ends at 2 s) and
  // from sample 120 (after it): each the rows of today's record from t = 0, bit for bit.
  // A start 1e-9 tau off the grid (a printed time column) counts as the grid point.
  SampledCrane crane = LoadSampledCrane();
  crane.simulation.duration_s = 3.0;
  const double tau = 1.0 / 50;
  for (const auto& [excitation, k] : {std::pair<Excitation, int>{crane.excitation, 7},
                                      {BoomTipBurst(), 60},
                                      {BoomTipBurst(), 120}}) {
    const SimulationResult from_zero =
        Simulate(*crane.model, excitation, crane.simulation, Sensors(50.0));
    for (const double start : {k * tau, k * tau * (1 + 1e-9)}) {
      const SimulationResult late =
          Simulate(*crane.model, excitation, crane.simulation, Sensors(50.0, start));
      ASSERT_EQ(late.exact.samples(), from_zero.exact.samples() - k) << excitation.type_name();
      EXPECT_EQ(late.exact.start_time_s, k * tau);
      EXPECT_TRUE(late.exact.values == from_zero.exact.values.bottomRows(late.exact.samples()))
          << excitation.type_name() << " from sample " << k;
    }
  }
}

TEST(SamplingStartTest, SensitivitiesFollowTheSameSamples) {
  // The sensitivities' run with a whole start: its rows are those from t = 0 bit for bit (the
  // same steps); with a start of 0.37 tau its values agree with Simulate's at the same times to
  // the integration error (another integrator: 1e-7 of the 1e-2 rad amplitude is far above the
  // 1e-8 tolerances' error and far below any sampling mistake, 0.37 tau of a 1.5 Hz swing ~ 4e-4).
  SampledCrane crane = LoadSampledCrane();
  crane.simulation.duration_s = 2.0;
  const double tau = 1.0 / 50;
  const SensitivityOptions sensitivity;
  const std::vector<std::string> parameters{"c_theta", "d_theta"};
  const SensitivityResult from_zero = SimulateWithSensitivities(
      *crane.model, crane.excitation, crane.simulation, Sensors(50.0), parameters, {}, sensitivity);
  const SensitivityResult whole =
      SimulateWithSensitivities(*crane.model, crane.excitation, crane.simulation,
                                Sensors(50.0, 9 * tau), parameters, {}, sensitivity);
  ASSERT_EQ(whole.exact.samples(), from_zero.exact.samples() - 9);
  EXPECT_TRUE(whole.exact.values == from_zero.exact.values.bottomRows(whole.exact.samples()));
  for (size_t k = 0; k < parameters.size(); ++k) {
    EXPECT_TRUE(whole.output_sensitivities[k] ==
                from_zero.output_sensitivities[k].bottomRows(whole.exact.samples()));
  }
  const SensitivityResult fractional =
      SimulateWithSensitivities(*crane.model, crane.excitation, crane.simulation,
                                Sensors(50.0, 0.37 * tau), parameters, {}, sensitivity);
  const SimulationResult plain =
      Simulate(*crane.model, crane.excitation, crane.simulation, Sensors(50.0, 0.37 * tau));
  ASSERT_EQ(fractional.exact.samples(), plain.exact.samples());
  EXPECT_EQ(fractional.exact.start_time_s, 0.37 * tau);
  const double difference = (fractional.exact.values - plain.exact.values).cwiseAbs().maxCoeff();
  RecordProperty("max_difference_rad", Sci(difference));
  EXPECT_LT(difference, 1e-7);
}

TEST(SamplingStartTest, FractionalStartSamplesBetweenTheGridPoints) {
  // First sample 0.37 tau after the excitation at 50 Hz, against a 5000 Hz record from t = 0
  // whose sample 100 j + 37 lies at the same time (j + 0.37) tau. Both are dense outputs of
  // CVODES, whose first step depends on the first output time: they agree to the integration
  // error (1e-7 rad of the 1e-2 rad swing, as above), not bit for bit.
  SampledCrane crane = LoadSampledCrane();
  crane.simulation.duration_s = 2.0;
  const double tau = 1.0 / 50;
  const SimulationResult late =
      Simulate(*crane.model, crane.excitation, crane.simulation, Sensors(50.0, 0.37 * tau));
  const SimulationResult fine =
      Simulate(*crane.model, crane.excitation, crane.simulation, Sensors(5000.0));
  // The last sample at or before 2 s: 0.37 tau + 99 tau.
  ASSERT_EQ(late.exact.samples(), 100);
  EXPECT_NEAR(late.exact.start_time_s, 0.37 * tau, 1e-15);
  double difference = 0;
  for (int j = 0; j < late.exact.samples(); ++j) {
    difference = std::max(
        difference,
        (late.exact.values.row(j) - fine.exact.values.row(100 * j + 37)).cwiseAbs().maxCoeff());
  }
  RecordProperty("max_difference_rad", Sci(difference));
  EXPECT_LT(difference, 1e-7);
  // The samples really moved: against the grid points themselves the difference is the swing's
  // change over 0.37 tau.
  const SimulationResult grid =
      Simulate(*crane.model, crane.excitation, crane.simulation, Sensors(50.0));
  EXPECT_GT((late.exact.values.topRows(99) - grid.exact.values.topRows(99)).cwiseAbs().maxCoeff(),
            1e-5);
}

// A mode above the Nyquist frequency shows in the record as its alias, a mode of its own the
// data cannot tell from a real one: the crane's modes sampled at 100 Hz (all below 5 Hz) have
// none; at 5 Hz every mode of 2.5 Hz or more is named with its alias |f - 5 round(f / 5)|.
TEST(SamplingStartTest, ModesAboveTheNyquistFrequencyAreNamedWithTheirAlias) {
  const SampledCrane crane = LoadSampledCrane();
  const std::vector<model::Mode> modes = model::CalcModes(crane.model->Linearize());
  EXPECT_TRUE(FindAliasedModes(modes, 0.01).empty());
  const std::vector<std::string> lines = FindAliasedModes(modes, 0.2);
  size_t above = 0;
  for (size_t k = 0; k < modes.size(); ++k) {
    const double f = modes[k].frequency_hz();
    if (f < 2.5) continue;
    ASSERT_LT(above, lines.size());
    std::ostringstream alias;
    alias.precision(4);
    alias << std::abs(f - 5 * std::round(f / 5));
    EXPECT_NE(lines[above].find("aliases it to " + alias.str() + " Hz"), std::string::npos)
        << lines[above];
    ++above;
  }
  EXPECT_GT(above, 0u) << "the crane has a mode above 2.5 Hz";
  EXPECT_EQ(lines.size(), above);
}

TEST(SamplingStartTest, RejectsAStartOutsideTheRecord) {
  SampledCrane crane = LoadSampledCrane();
  crane.simulation.duration_s = 1.0;
  for (const double start : {-0.001, 1.5, std::nan("")}) {
    EXPECT_THROW(Simulate(*crane.model, crane.excitation, crane.simulation, Sensors(50.0, start)),
                 std::invalid_argument)
        << start;
  }
}

}  // namespace
}  // namespace mbid::simulation
