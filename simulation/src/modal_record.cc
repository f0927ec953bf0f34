#include "mbid/simulation/modal_record.h"

#include <cmath>
#include <random>

#include "channel_value.h"
#include "mbid/common/error.h"
#include "mbid/simulation/scenario_sections.h"

namespace mbid::simulation {
using internal::ChannelValueOrZero;

Measurement SynthesizeModalRecord(const ModalRecordSpec& spec, Measurement* exact,
                                  std::map<std::string, double>* noise_std) {
  const double tau = 1.0 / spec.sample_rate_hz;
  const int samples = static_cast<int>(std::floor(spec.duration_s / tau + 1e-9)) + 1;
  Measurement clean;
  clean.channels = spec.channels;
  clean.units.assign(spec.channels.size(), "rad");
  clean.sample_interval_s = tau;
  clean.source = "synthetic";
  clean.values = Eigen::MatrixXd::Zero(samples, static_cast<Eigen::Index>(spec.channels.size()));
  for (size_t c = 0; c < spec.channels.size(); ++c) {
    for (const ModalComponent& mode : spec.modes) {
      const double amplitude = ChannelValueOrZero(mode.amplitude, spec.channels[c]);
      const double phase = ChannelValueOrZero(mode.phase_rad, spec.channels[c]);
      for (int j = 0; j < samples; ++j) {
        const double t = j * tau;
        clean.values(j, static_cast<Eigen::Index>(c)) +=
            amplitude * std::exp(-mode.decay_rate_per_s * t) *
            std::cos(2 * M_PI * mode.frequency_hz * t + phase);
      }
    }
  }
  Measurement noisy = clean;
  std::mt19937_64 generator(spec.seed);
  std::normal_distribution<double> unit_normal(0.0, 1.0);
  if (noise_std != nullptr) noise_std->clear();
  for (size_t c = 0; c < spec.channels.size(); ++c) {
    double std_dev = ChannelValueOrZero(spec.noise_std, spec.channels[c]);
    const auto target = spec.target_correlation.find(spec.channels[c]);
    if (target != spec.target_correlation.end()) {
      const auto column = clean.values.col(static_cast<Eigen::Index>(c));
      const double signal_std =
          std::sqrt((column.array() - column.mean()).square().sum() / column.size());
      std_dev = signal_std * std::sqrt(1.0 / (target->second * target->second) - 1.0);
    }
    if (noise_std != nullptr) (*noise_std)[spec.channels[c]] = std_dev;
    for (int j = 0; j < samples; ++j) {
      noisy.values(j, static_cast<Eigen::Index>(c)) += std_dev * unit_normal(generator);
    }
  }
  if (exact != nullptr) *exact = clean;
  return noisy;
}

ModalRecordSpec ReadModalRecordSpec(const YamlReader& node) {
  node.ExpectMap({"channels", "sample_rate_hz", "duration_s", "modes", "noise_std_rad",
                  "target_correlation", "seed"});
  ModalRecordSpec spec;
  spec.channels = node.StringList("channels");
  if (spec.channels.empty()) node.FailAt("channels", "no channel", "at least one channel name");
  spec.sample_rate_hz = node.PositiveDouble("sample_rate_hz", spec.sample_rate_hz);
  spec.duration_s = node.PositiveDouble("duration_s", spec.duration_s);
  spec.noise_std = ReadChannelValues(node, "noise_std_rad", spec.channels, true);
  spec.target_correlation = ReadChannelValues(node, "target_correlation", spec.channels, true);
  if (!spec.noise_std.empty() && !spec.target_correlation.empty()) {
    node.FailAt("target_correlation", "given together with noise_std_rad",
                "one of noise_std_rad and target_correlation");
  }
  for (const auto& [channel, k] : spec.target_correlation) {
    if (!(k > 0 && k <= 1)) {
      node.FailAt("target_correlation", channel + " = " + std::to_string(k),
                  "a correlation in (0, 1] per channel");
    }
  }
  const int seed = node.Seed("seed", 1);
  spec.seed = static_cast<std::uint64_t>(seed);
  const YamlReader modes = node.Child("modes");
  if (!modes.node().IsSequence() || modes.node().size() == 0) {
    modes.Fail("not a list of modes", "a list of {frequency_hz, decay_rate_per_s, amplitude_rad}");
  }
  for (size_t k = 0; k < modes.node().size(); ++k) {
    const YamlReader mode(modes.node()[k], node.source(),
                          modes.field() + "[" + std::to_string(k) + "]");
    mode.ExpectMap({"frequency_hz", "decay_rate_per_s", "amplitude_rad", "phase_rad"});
    ModalComponent component;
    component.frequency_hz = mode.PositiveDouble("frequency_hz");
    component.decay_rate_per_s = mode.Double("decay_rate_per_s");
    if (component.frequency_hz >= spec.sample_rate_hz / 2) {
      mode.FailAt("frequency_hz", "at or above the Nyquist frequency",
                  "a frequency below sample_rate_hz / 2");
    }
    component.amplitude = ReadChannelValues(mode, "amplitude_rad", spec.channels, false);
    if (component.amplitude.empty()) {
      mode.FailAt("amplitude_rad", "missing", "the amplitude per channel, rad");
    }
    component.phase_rad = ReadChannelValues(mode, "phase_rad", spec.channels, false);
    spec.modes.push_back(component);
  }
  return spec;
}

}  // namespace mbid::simulation
