#include "mbid/simulation/sensor.h"

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

}  // namespace mbid::simulation
