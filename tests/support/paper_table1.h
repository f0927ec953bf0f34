#pragma once

// The paper's Table 1 (docs/method.md) and the record scenarios/paper-ks5579.yaml makes
// of it, for the tests that check Route 1 and the identifier against it.
#include <cmath>
#include <cstdint>

#include "mbid/simulation/modal_record.h"

namespace mbid::testing {

// Frequency (Hz), decay rate -beta (1/s), peak amplitudes A_psi, A_phi (rad).
struct PaperMode {
  double frequency_hz, decay_rate_per_s, a_psi, a_phi;
};
inline constexpr PaperMode kTable1[] = {{1.155, 6.77, 0.0112, 0.0055},
                                        {2.169, 1.52, 0.0046, 0.0008},
                                        {3.179, 3.67, 0.0010, 0.0062},
                                        {3.766, 1.98, 0.0035, 0.0069}};

// 2.5 s at 100 Hz, psi and phi, each mode released from rest (phase -atan(decay / omega));
// `target_correlation` 1 means no noise.
inline simulation::ModalRecordSpec PaperRecordSpec(double target_correlation = 1.0,
                                                   std::uint64_t seed = 1) {
  simulation::ModalRecordSpec spec;
  spec.channels = {"psi", "phi"};
  spec.sample_rate_hz = 100;
  spec.duration_s = 2.5;
  spec.seed = seed;
  if (target_correlation < 1) {
    spec.target_correlation = {{"psi", target_correlation}, {"phi", target_correlation}};
  }
  for (const PaperMode& mode : kTable1) {
    const double phase = -std::atan(mode.decay_rate_per_s / (2 * M_PI * mode.frequency_hz));
    spec.modes.push_back({mode.frequency_hz,
                          mode.decay_rate_per_s,
                          {{"psi", mode.a_psi}, {"phi", mode.a_phi}},
                          {{"psi", phase}, {"phi", phase}}});
  }
  return spec;
}

}  // namespace mbid::testing
