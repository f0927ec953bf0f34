#pragma once

// The time origin of a measured test is the release (docs/identification.md): update and run cut
// an imported record there before the test is simulated and fitted.

#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "mbid/common/measurement.h"
#include "mbid/common/yaml_reader.h"
#include "mbid/simulation/excitation.h"
#include "mbid/updating/output_error.h"
#include "mbid/validation/record_import.h"

namespace mbid::validation {

// What the user said: `release: none` / `release_time_s: T` in a record entry, or
// --release none / --release-time-s T (which win).
struct ReleaseChoice {
  bool none = false;
  std::optional<double> time_s;  // in the record's own time
  // `end_time_s: T` / --end-time-s T: the test ends there, in the record's own time; what
  // follows is no part of it (a second drop a few seconds after the first came to rest).
  std::optional<double> end_time_s;
};

// Drops the samples of `record` after `end_time_s` (its own time). An InputError naming
// `origin` and `field` for an end at or before the first sample or one that leaves fewer than
// 10 samples; an end after the last sample keeps the record whole.
void EndRecordAt(Measurement* record, double end_time_s, const std::string& origin,
                 const std::string& field);

// The record entry's `release` and `release_time_s` keys (exclusive).
ReleaseChoice ReadReleaseChoice(const YamlReader& entry);
// `entry` with the command line's --release none / --release-time-s on top.
ReleaseChoice OverrideRelease(const ReleaseChoice& entry, const ImportOverrides& overrides);

struct AppliedRelease {
  double release_time_s = 0;  // in the record's own time, as read from the file
  // "detected", "given", "record start" (nothing at rest before the decay, or a record mbid
  // simulated), "none" (--release none) or "forced test" (the excitation forces the structure
  // from t = 0, which is then the origin).
  std::string how;
  // A forced test: where its forcing ends after t = 0, and so where its free decay starts.
  double forcing_end_s = 0;
  // The contract's release_time_s, where the free decay starts in the record's own time: the
  // release, or a forced test's forcing end.
  double free_decay_start_s() const { return release_time_s + forcing_end_s; }
  // A record clipped at its start (common/clipping.h) is used from the sample after its last
  // clipped one, this many seconds after the release; `clipped` says which channel and how.
  std::optional<double> clipped_until_s;
  std::string clipped;
  // A second excitation after the decay came to rest (identification/release.h:
  // FindNextExcitation), in the record's own time: the record is cut before it; the line says so.
  std::optional<double> next_excitation_s;
  std::string next_excitation;
  // Where the user ended the test (ReleaseChoice::end_time_s), in the record's own time.
  std::optional<double> end_time_s;
  // A detected release the fit placed (Place): the instant as detected, and the placed one's
  // standard deviation; release_time_s is then the placed instant.
  std::optional<double> detected_time_s;
  std::optional<double> std_s;
  // Takes the fit's placement of a detected release (TestFit::release_shift_s) when it made one.
  void Place(const updating::TestFit& fit);
  nlohmann::json ToJson() const;
  // "<clipped>; the test is analysed from t = 0.55 s, after its last clipped sample", or "".
  std::string DescribeClipped() const;
};

// Cuts `record` at its release with the release as time origin (start_time_s in [0, tau)):
// given, or found (identification/release.h) in records mbid did not simulate when the excitation
// is a release (a load drop or an initial deflection). Forced tests and --release none are left
// whole. A record clipped at its start (but a forced test's) then keeps only the samples after
// its last clipped one (common/clipping.h: FindClippedStart).
AppliedRelease CutRecordAtRelease(Measurement* record, const std::string& origin,
                                  const ReleaseChoice& choice,
                                  const simulation::Excitation& excitation);

}  // namespace mbid::validation
