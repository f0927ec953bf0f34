#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "mbid/common/measurement.h"
#include "mbid/common/yaml_reader.h"

namespace mbid::simulation {

// One damped mode as it appears in a record: y_c(t) = A_c e^{-decay t} cos(2 pi f t + phase_c).
// The amplitudes are the peak values at t = 0 of the paper's Table 1.
struct ModalComponent {
  double frequency_hz = 0.0;
  double decay_rate_per_s = 0.0;
  std::map<std::string, double> amplitude;  // per channel, channel unit
  std::map<std::string, double> phase_rad;  // per channel; absent = 0
};

// A record made from modes rather than from a model (the paper's Table 1 turned back into a
// signal), with white Gaussian noise per channel drawn from `seed`.
struct ModalRecordSpec {
  std::vector<std::string> channels;
  double sample_rate_hz = 100.0;
  double duration_s = 10.0;
  std::vector<ModalComponent> modes;
  std::map<std::string, double> noise_std;  // per channel; absent = 0
  // Per channel, instead of noise_std: the noise is scaled so that the noise-free record
  // correlates with the noisy one by K, i.e. std = std(exact) * sqrt(1 / K^2 - 1). This is how
  // a record with the paper's correlations (0.883, 0.895) is made.
  std::map<std::string, double> target_correlation;
  std::uint64_t seed = 1;
};

// Samples t_j = j / rate, j = 0..floor(duration * rate); units "rad"; source "synthetic".
// `exact` (if not null) receives the noise-free record, `noise_std` (if not null) the noise std
// used per channel (rad).
Measurement SynthesizeModalRecord(const ModalRecordSpec& spec, Measurement* exact = nullptr,
                                  std::map<std::string, double>* noise_std = nullptr);

// `record: {synthetic_modes: {...}}` of a scenario (docs/scenarios.md), read strictly.
ModalRecordSpec ReadModalRecordSpec(const YamlReader& node);

}  // namespace mbid::simulation
