#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "mbid/common/measurement.h"
#include "mbid/model/linear_model.h"

namespace mbid::simulation {

// The sensors of a virtual test (docs/scenarios.md, `sensors:`): sampling, and per channel a
// constant bias, Gaussian noise and quantization, all in the channel's unit (rad for angles).
// Every random draw comes from `seed`: the same options give the same bits.
struct SensorOptions {
  double sample_rate_hz = 100.0;
  // Time of the first sample after the excitation's t = 0 (s, >= 0): a record cut at a release
  // between two samples. Samples t_j = start + j tau up to the duration. A start within 1e-6
  // tau of a whole k tau samples at (k + j) tau: the rows of a record from 0 from row k on,
  // bit for bit.
  double start_time_s = 0.0;
  std::vector<std::string> channels{"psi", "phi"};
  std::map<std::string, double> noise_std;          // per channel; absent = 0
  std::map<std::string, double> bias;               // per channel; absent = 0
  std::map<std::string, double> quantization_step;  // per channel; absent or 0 = none
  std::uint64_t seed = 1;

  double sample_interval_s() const { return 1.0 / sample_rate_hz; }
};

// A sampling start within this many sample intervals of a whole k tau counts as k tau (the
// tolerance of a record's time column, kTimeUniformityTolerance).
inline constexpr double kWholeSampleTolerance = kTimeUniformityTolerance;

// measured = Q(clean + bias + noise), with Q rounding to the nearest multiple of the step.
// Noise is drawn channel by channel, sample by sample, from a 64-bit Mersenne twister seeded
// with `seed`.
Measurement ApplySensor(const Measurement& clean, const SensorOptions& options);

// The frequency at which samples every `sample_interval_s` show an oscillation of `frequency_hz`:
// its alias |f - k / tau| in [0, Nyquist].
double AliasFrequencyHz(double frequency_hz, double sample_interval_s);

// One line per mode of `modes` at or above the Nyquist frequency of `sample_interval_s`: the
// record shows it at its alias |f - k / tau|, as a mode of its own that the data cannot tell
// from a real one ("the model's mode 3 at 7.107 Hz lies above the Nyquist frequency 5 Hz: the
// record aliases it to 2.893 Hz; sampling at 15 Hz or more records it").
std::vector<std::string> FindAliasedModes(const std::vector<model::Mode>& modes,
                                          double sample_interval_s);

}  // namespace mbid::simulation
