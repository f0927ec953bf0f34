#pragma once

// A recorded channel's own fault, whatever the model: clipping (clipping.h), else glitches
// (outliers.h). The identification and the updating judge records by it alike.

#include <Eigen/Core>
#include <limits>
#include <optional>
#include <string>

namespace mbid {

struct ChannelFault {
  enum class Kind { kClipped, kGlitch };
  Kind kind = Kind::kClipped;
  std::string reason;  // ClippingReason or OutlierReason
};

// The channel's fault, if any. Clipping first: a rail's edges would read as jumps too. Jumps at
// or before `jumps_from_s` are not judged (a hammer blow or a burst makes them, and a model of
// the test reproduces them).
std::optional<ChannelFault> FindChannelFault(
    const Eigen::Ref<const Eigen::VectorXd>& values, const std::string& channel,
    const std::string& unit, double sample_interval_s, double start_time_s,
    double jumps_from_s = -std::numeric_limits<double>::infinity());

}  // namespace mbid
