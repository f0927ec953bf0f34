#include "mbid/simulation/sensor.h"

#include <fmt/format.h>

#include <cmath>
#include <random>

#include "channel_value.h"

namespace mbid::simulation {
using internal::ChannelValueOrZero;

Measurement ApplySensor(const Measurement& clean, const SensorOptions& options) {
  Measurement measured = clean;
  std::mt19937_64 generator(options.seed);
  std::normal_distribution<double> unit_normal(0.0, 1.0);
  for (int c = 0; c < clean.channel_count(); ++c) {
    const std::string& channel = clean.channels[c];
    const double noise_std = ChannelValueOrZero(options.noise_std, channel);
    const double bias = ChannelValueOrZero(options.bias, channel);
    const double step = ChannelValueOrZero(options.quantization_step, channel);
    for (int j = 0; j < clean.samples(); ++j) {
      // Draw even when noise_std = 0, so adding noise to one channel does not shift the others.
      double value = clean.values(j, c) + bias + noise_std * unit_normal(generator);
      if (step > 0) value = step * std::round(value / step);
      measured.values(j, c) = value;
    }
  }
  return measured;
}

double AliasFrequencyHz(double frequency_hz, double sample_interval_s) {
  const double rate_hz = 1 / sample_interval_s;
  return std::abs(frequency_hz - std::round(frequency_hz / rate_hz) * rate_hz);
}

std::vector<std::string> FindAliasedModes(const std::vector<model::Mode>& modes,
                                          double sample_interval_s) {
  std::vector<std::string> lines;
  const double rate_hz = 1 / sample_interval_s;
  for (size_t k = 0; k < modes.size(); ++k) {
    const double f = modes[k].frequency_hz();
    if (!(f >= 0.5 * rate_hz)) continue;
    const double alias = AliasFrequencyHz(f, sample_interval_s);
    lines.push_back(fmt::format(
        "the model's mode {} at {:.4g} Hz lies above the Nyquist frequency {:.4g} Hz of the "
        "sampling: the record aliases it to {:.4g} Hz; sampling at {:.4g} Hz or more records it",
        k + 1, f, 0.5 * rate_hz, alias, std::ceil(2.1 * f)));
  }
  return lines;
}

}  // namespace mbid::simulation
