#pragma once

#include <optional>
#include <string>
#include <vector>

#include "mbid/common/measurement.h"

namespace mbid::identification {

struct ModalResult;

// Where the free decay of a record starts: the load or pull release, the impact, the end of
// leading zeros or of a pre-trigger segment. Before it the structure is at rest (a constant per
// channel plus noise); after it the response sets off from that constant like
//   c + j H(t - t0) + b (t - t0) + a (t - t0)^2,
// continuous in position for angles and lengths (at rest at a release, moving off at an impact)
// and free to jump for rate channels (units ".../s", ".../s^2"), whose step is the release.
struct ReleaseDetection {
  double release_time_s = 0;  // in the record's own time
  // true: a segment at rest precedes the decay and release_time_s is where it ends (to a
  // fraction of a sample); false: the record starts in the decay, release_time_s is its start.
  bool detected = false;
  int rest_samples = 0;  // samples at rest before the release
  // Per channel of the record, its level at rest: the median before the release (glitches
  // bridged). Empty unless detected.
  std::vector<double> rest_level;
  // true when the structure set off from rest in every channel (positions, no jump): a load or
  // pull release, whose instant the identified modes then refine (RefineReleaseFromModes).
  bool from_rest = false;
  std::string description;  // one line for the user
};

// Finds the release in `record`'s channels (all of them). Never throws on a valid record.
ReleaseDetection DetectRelease(const Measurement& record);

// A second excitation in the record after the free decay that starts at `release_time_s`: the
// structure comes to rest (a window as long as a quarter of the time since the release, at least
// 20 samples, within 12 noise standard deviations, no drift) and then leaves that rest by 8 of
// them, swinging again or moving within the rest's length by a tenth of the decay's range (at
// least 20 noise std): a reload and a second drop, a knock. A sensor's drift is none. Where the
// decay never comes to rest within the record, none is looked for.
struct NextExcitation {
  double rest_s = 0;        // where the structure is at rest again, in the record's time
  double time_s = 0;        // where it sets off again: the free decay's samples end before it
  std::string description;  // one line for the user
};
std::optional<NextExcitation> FindNextExcitation(const Measurement& record, double release_time_s);

// A release from rest is where the velocity of every channel vanishes: the reconstruction of
// `modes` (identified on the decay after `coarse_time_s`) differentiated in time. Searched from
// twice the reach before the coarse instant to once after it (an onset comes late), the reach
// being 3 samples or an eighth of the period of the fastest mode that carries a tenth of some
// channel's velocity, whichever is longer. Uses the whole record's information instead of the
// few samples around the onset: on the crane at 1e-5 rad noise, a tenth of a sample at 100 Hz.
// Where the least sum of squared velocities is at an end of the range or not below a tenth of
// the largest (the modes miss one that the noise hid), the coarse instant is returned; so too
// where the modes (with the offset) are not back at `rest_level` (per channel of `modes`, the
// record's level before the release; empty: not checked) there within a tenth of their summed
// amplitudes: modes that miss one (two of the crane's four heavily damped ones in a 1 s record)
// have velocities that vanish together elsewhere (6 samples early at 1 kHz).
double RefineReleaseFromModes(const ModalResult& modes, double coarse_time_s,
                              const std::vector<double>& rest_level = {});

// The part of `record` from `release_time_s` on, with the release as time origin: samples at
// t >= release_time_s (less a millionth of a sample for round-off) keep their values, and
// start_time_s becomes their time since the release (in [0, tau)). Throws InputError naming
// `origin` if fewer than 2 samples remain.
Measurement CutAtRelease(const Measurement& record, double release_time_s,
                         const std::string& origin);

}  // namespace mbid::identification
