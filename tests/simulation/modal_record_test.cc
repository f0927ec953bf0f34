#include "mbid/simulation/modal_record.h"

#include <gtest/gtest.h>

#include <cmath>

#include "mbid/common/error.h"

namespace mbid::simulation {
namespace {

TEST(ModalRecordTest, SynthesizesTheModesItIsGiven) {
  ModalRecordSpec spec;
  spec.channels = {"psi"};
  spec.sample_rate_hz = 100;
  spec.duration_s = 1;
  spec.modes = {{2.0, 1.5, {{"psi", 0.01}}, {{"psi", 0.3}}}};
  Measurement exact;
  const Measurement noisy = SynthesizeModalRecord(spec, &exact);
  ASSERT_EQ(exact.samples(), 101);  // 0..1 s at 100 Hz inclusive
  for (int j = 0; j < exact.samples(); j += 10) {
    const double t = j / 100.0;
    EXPECT_NEAR(exact.values(j, 0), 0.01 * std::exp(-1.5 * t) * std::cos(4 * M_PI * t + 0.3),
                1e-17);  // one rounding of the same expression
  }
  EXPECT_EQ(noisy.values, exact.values);  // no noise asked
}

TEST(ModalRecordTest, NoiseIsSeeded) {
  ModalRecordSpec spec;
  spec.channels = {"psi", "phi"};
  spec.modes = {{1.0, 1.0, {{"psi", 1e-3}, {"phi", 2e-3}}, {}}};
  spec.noise_std = {{"psi", 1e-4}, {"phi", 1e-4}};
  spec.seed = 3;
  EXPECT_EQ(SynthesizeModalRecord(spec).values, SynthesizeModalRecord(spec).values);
  Measurement exact;
  const Measurement noisy = SynthesizeModalRecord(spec, &exact);
  // 1001 samples: the sample std of N(0, 1e-4) is within 10% of 1e-4 (4.5 sigma of its 2.2%).
  const Eigen::VectorXd noise = noisy.values.col(1) - exact.values.col(1);
  EXPECT_NEAR(std::sqrt(noise.squaredNorm() / noise.size()), 1e-4, 1e-5);
}

double Correlation(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  const Eigen::ArrayXd x = a.array() - a.mean();
  const Eigen::ArrayXd y = b.array() - b.mean();
  return (x * y).sum() / std::sqrt(x.square().sum() * y.square().sum());
}

TEST(ModalRecordTest, TargetCorrelationSetsTheNoiseLevel) {
  ModalRecordSpec spec;
  spec.channels = {"psi", "phi"};
  spec.sample_rate_hz = 100;
  spec.duration_s = 100;  // 10001 samples: the sample correlation scatters by ~0.002
  spec.modes = {{1.155, 0.2, {{"psi", 0.0112}, {"phi", 0.0055}}, {}},
                {3.179, 0.1, {{"psi", 0.0010}, {"phi", 0.0062}}, {}}};
  spec.target_correlation = {{"psi", 0.883}, {"phi", 0.5}};
  Measurement exact;
  std::map<std::string, double> noise_std;
  const Measurement noisy = SynthesizeModalRecord(spec, &exact, &noise_std);
  // std = std(exact) sqrt(1/K^2 - 1): the formula, checked on the record it was applied to.
  const Eigen::VectorXd psi = exact.values.col(0);
  const double psi_std = std::sqrt((psi.array() - psi.mean()).square().mean());
  EXPECT_NEAR(noise_std.at("psi"), psi_std * std::sqrt(1 / (0.883 * 0.883) - 1), 1e-15);
  // The realized correlation is the target within 5 times its sampling scatter.
  EXPECT_NEAR(Correlation(noisy.values.col(0), exact.values.col(0)), 0.883, 0.01);
  EXPECT_NEAR(Correlation(noisy.values.col(1), exact.values.col(1)), 0.5, 0.02);
}

TEST(ModalRecordTest, ReadsTheScenarioSectionStrictly) {
  const YamlReader good = YamlReader::FromString(
      "channels: [psi, phi]\nsample_rate_hz: 100\nduration_s: 10\nnoise_std_rad: 1.0e-4\n"
      "modes:\n  - {frequency_hz: 1.155, decay_rate_per_s: 6.77, "
      "amplitude_rad: {psi: 0.0112, phi: 0.0055}}\n",
      "paper.yaml");
  const ModalRecordSpec spec = ReadModalRecordSpec(good);
  ASSERT_EQ(spec.modes.size(), 1u);
  EXPECT_EQ(spec.modes[0].amplitude.at("phi"), 0.0055);
  EXPECT_EQ(spec.noise_std.at("psi"), 1e-4);  // one number for every channel
  const YamlReader above_nyquist = YamlReader::FromString(
      "channels: [psi]\nsample_rate_hz: 10\nmodes:\n  - {frequency_hz: 6, decay_rate_per_s: 1, "
      "amplitude_rad: 0.01}\n",
      "bad.yaml");
  try {
    ReadModalRecordSpec(above_nyquist);
    FAIL() << "a mode above Nyquist was accepted";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("modes[0].frequency_hz"), std::string::npos)
        << error.what();
  }
  const YamlReader both_noise_forms = YamlReader::FromString(
      "channels: [psi]\nnoise_std_rad: 1.0e-4\ntarget_correlation: 0.9\nmodes:\n"
      "  - {frequency_hz: 1, decay_rate_per_s: 1, amplitude_rad: 0.01}\n",
      "bad.yaml");
  EXPECT_THROW(ReadModalRecordSpec(both_noise_forms), InputError);
  const YamlReader correlation_above_one = YamlReader::FromString(
      "channels: [psi]\ntarget_correlation: 1.2\nmodes:\n"
      "  - {frequency_hz: 1, decay_rate_per_s: 1, amplitude_rad: 0.01}\n",
      "bad.yaml");
  EXPECT_THROW(ReadModalRecordSpec(correlation_above_one), InputError);
}

}  // namespace
}  // namespace mbid::simulation
