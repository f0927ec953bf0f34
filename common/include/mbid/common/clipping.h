#pragma once

// Clipping: a sensor or logger at the end of its range holds the channel at one value, its
// largest or smallest, wherever the motion would have gone beyond. A free decay reaches its
// extremes once; a clipped one sits on them peak after peak. Modes fitted to the flattened
// peaks are wrong (spurious modes, biased damping) with small standard deviations, so the
// identification and the updating say so instead of reporting them as certain.

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "mbid/common/measurement.h"

namespace mbid {

struct Clipping {
  bool at_maximum = false;          // held at the channel's largest value
  bool at_minimum = false;          // held at its smallest
  double maximum = 0, minimum = 0;  // those values (the channel's unit)
  int samples = 0;                  // samples held there
};

// The channel's clipping, if any: samples at its largest or smallest value (within 1e-9 of its
// range) in a run of 3 or more that the channel leaves again, or in 2 or more runs of 2 or more
// (at one extreme or both). A moving channel, noisy or not, cannot hold a value for 3 samples but
// at a rail; `values` is the motion from its start (a free decay from the release: a record's
// rest before it would count). A channel on so coarse a grid that it has fewer than 1000 steps
// between its extremes is not judged (a peak held for one quantization step looks the same);
// nor one with under 8 samples or no range.
std::optional<Clipping> FindClipping(const Eigen::Ref<const Eigen::VectorXd>& values);

// A record clipped only at its start (its first swings beyond a sensor's or logger's range)
// is whole again from the sample after its last clipped one.
struct ClippedStart {
  Eigen::Index first_whole = 0;  // that sample's row in the record
  std::string reason;            // ClippingReason of the channel clipped last
};

// The clipped start of rows [first, last] of `record` (in `channels`, or all if empty): found
// if at least half of those rows are left after it and none of those channels is clipped in
// them (a channel on a rail to the end is a stuck sensor, not a decay back inside its range).
std::optional<ClippedStart> FindClippedStart(const Measurement& record, Eigen::Index first,
                                             Eigen::Index last,
                                             const std::vector<std::string>& channels = {});

// "channel psi stays at its largest and smallest values, 0.00095 and -0.00095 rad, for 49
// samples: the sensor or logger was at the end of its range (clipped)"
std::string ClippingReason(const std::string& channel, const std::string& unit,
                           const Clipping& clipping);

}  // namespace mbid
