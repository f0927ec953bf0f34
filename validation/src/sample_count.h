// The size of a test's record, checked before anything allocates it (the scenario's test and
// each planned test alike).
#pragma once

#include <fmt/format.h>

#include <cmath>
#include <string>

#include "mbid/common/error.h"

namespace mbid::validation::internal {

// 1e8 samples per channel (0.8 GB of doubles) is beyond any test this tool is for.
inline constexpr double kMaxSamples = 1e8;

// Throws InputError at `source`, `field` (the two keys' path) unless `duration_s` at
// `sample_rate_hz` gives 2 to kMaxSamples samples per channel. Either key may be the wrong one:
// the message gives both values.
inline void CheckSampleCount(const std::string& source, const std::string& field, double duration_s,
                             double sample_rate_hz) {
  const double samples = std::floor(duration_s * sample_rate_hz + 1e-9) + 1;
  if (!(samples <= kMaxSamples && samples >= 2)) {
    throw InputError(
        source, field,
        fmt::format("{:g} s at {:g} Hz is {:.3g} samples per channel", duration_s, sample_rate_hz,
                    samples),
        fmt::format("2 to {:g} samples (duration_s x sample_rate_hz + 1)", kMaxSamples));
  }
}

}  // namespace mbid::validation::internal
