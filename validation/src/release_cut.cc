#include "mbid/validation/release_cut.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "mbid/common/clipping.h"
#include "mbid/common/error.h"
#include "mbid/identification/identify.h"
#include "mbid/identification/release.h"

namespace mbid::validation {

ReleaseChoice ReadReleaseChoice(const YamlReader& entry) {
  ReleaseChoice choice;
  if (entry.Has("release") && entry.Has("release_time_s")) {
    entry.Fail("both release and release_time_s",
               "at most one of release: none and release_time_s");
  }
  if (entry.Has("release")) choice.none = entry.Choice("release", {"none", "detect"}, "") == "none";
  if (entry.Has("release_time_s")) choice.time_s = entry.Double("release_time_s");
  if (entry.Has("end_time_s")) {
    choice.end_time_s = entry.Double("end_time_s");
    if (choice.time_s && !(*choice.end_time_s > *choice.time_s)) {
      entry.FailAt("end_time_s", fmt::format("{} s, not after release_time_s", *choice.end_time_s),
                   "the test's end after its release, in the record's own time");
    }
  }
  return choice;
}

ReleaseChoice OverrideRelease(const ReleaseChoice& entry, const ImportOverrides& overrides) {
  ReleaseChoice choice = entry;
  if (overrides.release_none) choice = {true, std::nullopt, choice.end_time_s};
  if (overrides.release_time_s) choice = {false, overrides.release_time_s, choice.end_time_s};
  if (overrides.end_time_s) choice.end_time_s = overrides.end_time_s;
  return choice;
}

void EndRecordAt(Measurement* record, double end_time_s, const std::string& origin,
                 const std::string& field) {
  const double tau = record->sample_interval_s;
  // The samples at or before the end (a printed end within 1e-6 samples of one keeps it).
  const double kept = std::floor((end_time_s - record->start_time_s) / tau + 1e-6) + 1;
  if (!(kept >= 10)) {
    throw InputError(origin, field,
                     fmt::format("{:.6g} s leaves {} of the record's samples (it starts at {:.6g} "
                                 "s)",
                                 end_time_s, std::max(0.0, kept), record->start_time_s),
                     "the test's end after at least 10 samples, in the record's own time");
  }
  if (kept < static_cast<double>(record->samples())) {
    record->values = record->values.topRows(static_cast<Eigen::Index>(kept)).eval();
  }
}

nlohmann::json AppliedRelease::ToJson() const {
  nlohmann::json json = {{"release_time_s", free_decay_start_s()}, {"release", how}};
  // A forced test starts before its free decay: where the record's t = 0 is.
  if (forcing_end_s > 0) json["test_start_s"] = release_time_s;
  if (clipped_until_s) json["clipped_until_s"] = *clipped_until_s;
  if (next_excitation_s) json["next_excitation_s"] = *next_excitation_s;
  if (end_time_s) json["end_time_s"] = *end_time_s;
  if (detected_time_s) json["detected_release_time_s"] = *detected_time_s;
  if (std_s) json["release_std_s"] = *std_s;
  return json;
}

void AppliedRelease::Place(const updating::TestFit& fit) {
  if (how != "detected" || !std::isfinite(fit.release_shift_std_s)) return;
  if (!detected_time_s) detected_time_s = release_time_s;
  release_time_s = *detected_time_s + fit.release_shift_s;
  std_s = fit.release_shift_std_s;
}

std::string AppliedRelease::DescribeClipped() const {
  if (!clipped_until_s) return "";
  return fmt::format("{}; the test is analysed from t = {:.6g} s, after its last clipped sample",
                     clipped, *clipped_until_s);
}

namespace {

AppliedRelease CutAtReleaseOnly(Measurement* record, const std::string& origin,
                                const ReleaseChoice& choice,
                                const simulation::Excitation& excitation) {
  AppliedRelease applied;
  applied.release_time_s = record->start_time_s;
  if (choice.time_s) {
    applied.how = "given";
    applied.release_time_s = *choice.time_s;
    // A forced test's given instant is its forcing's start (the test's t = 0).
    applied.forcing_end_s = std::max(0.0, excitation.CalcForcingEndTime());
  } else if (choice.none) {
    applied.how = "none";
    return applied;
  } else if (excitation.CalcForcingEndTime() > 0) {
    applied.how = "forced test";
    applied.forcing_end_s = excitation.CalcForcingEndTime();
    if (record->made_by_mbid()) return applied;  // starts at the excitation by construction
    // A logger's pre-trigger before the blow: the onset of a force that rises from zero is found
    // only to about a sample, and the pulse's timing must be known to a fraction of one (a
    // half-sample error failed a shear frame's fit outright). Never guessed: the user says.
    const identification::ReleaseDetection detection = identification::DetectRelease(*record);
    if (detection.detected) {
      throw InputError(origin, "release_time_s",
                       fmt::format("the record rests until about {:.6g} s before it responds, and "
                                   "for a forced test ({}) the forcing's start cannot be found "
                                   "from the record to a fraction of a sample",
                                   detection.release_time_s, excitation.type_name()),
                       "the forcing's start in the record's time as the record entry's "
                       "release_time_s (or --release-time-s), or release: none for a record "
                       "that starts with the forcing");
    }
    return applied;
  } else if (record->made_by_mbid()) {
    // mbid's own records start at the excitation by construction.
    applied.how = "record start";
    return applied;
  } else {
    const identification::ReleaseDetection detection = identification::DetectRelease(*record);
    applied.how = detection.detected ? "detected" : "record start";
    applied.release_time_s = detection.release_time_s;
    if (!detection.detected) return applied;
    if (detection.from_rest) {
      // The identified decay places a release from rest to a fraction of a sample: the test's
      // simulation starts there, and a sample's error is a phase error of every mode.
      identification::IdentificationOptions options;
      options.compute_spectrum = false;
      options.compute_stabilization = false;
      try {
        applied.release_time_s = identification::Identify(*record, options, origin).release_time_s;
      } catch (const NumericalError&) {
        // No modes to refine with: the onset fit's instant stands (identification will say why).
      }
    }
  }
  *record = identification::CutAtRelease(*record, applied.release_time_s, origin);
  return applied;
}

}  // namespace

AppliedRelease CutRecordAtRelease(Measurement* record, const std::string& origin,
                                  const ReleaseChoice& choice,
                                  const simulation::Excitation& excitation) {
  if (choice.end_time_s) {
    // The release given, or the one the whole record shows (an end before it leaves a record at
    // rest, which was analysed as one: "too little signal", exit 0).
    std::optional<double> release_s = choice.time_s;
    if (!release_s && !choice.none && !record->made_by_mbid() &&
        !(excitation.CalcForcingEndTime() > 0)) {
      const identification::ReleaseDetection found = identification::DetectRelease(*record);
      if (found.detected) release_s = found.release_time_s;
    }
    if (release_s && !(*choice.end_time_s > *release_s)) {
      throw InputError(
          origin, "end_time_s",
          fmt::format("{:.6g} s, not after the release at {:.6g} s{}", *choice.end_time_s,
                      *release_s, choice.time_s ? "" : " (found in the record)"),
          "the test's end after its release, in the record's own time");
    }
    EndRecordAt(record, *choice.end_time_s, origin, "end_time_s");
  }
  AppliedRelease applied = CutAtReleaseOnly(record, origin, choice, excitation);
  applied.end_time_s = choice.end_time_s;
  if (applied.how != "none") {
    // A second test in the same record (a reload and a second drop, a knock) after this decay
    // came to rest is no part of it: the fit ends before it.
    // In the record's time as it now is: a cut record's origin is its release (or a forced
    // test's start), a forced test's uncut record keeps the file's.
    const bool uncut = applied.how == "forced test";
    const double decay_start_s = (uncut ? record->start_time_s : 0.0) + applied.forcing_end_s;
    const std::optional<identification::NextExcitation> next =
        identification::FindNextExcitation(*record, decay_start_s);
    if (next) {
      const double tau = record->sample_interval_s;
      const auto kept =
          static_cast<Eigen::Index>(std::ceil((next->time_s - record->start_time_s) / tau - 1e-6));
      record->values = record->values.topRows(kept).eval();
      // In the record's own time, as read from the file.
      const double origin_s = uncut ? 0.0 : applied.release_time_s;
      applied.next_excitation_s = next->time_s + origin_s;
      applied.next_excitation = fmt::format(
          "the structure is at rest again from {:.6g} s and set off again at {:.6g} s (in the "
          "file's time): a second excitation (a reload and release, a knock) or a change of a "
          "sensor (a re-zero, hum switching on) that is no part of this test; the fit ends "
          "before it",
          next->rest_s + origin_s, *applied.next_excitation_s);
    }
  }
  if (applied.how == "forced test") return applied;  // its forcing belongs to the fit
  // Clipped samples are no measured values: the fit and the identification both start after
  // the last one (the simulation still starts at the release).
  const std::optional<ClippedStart> clipped = FindClippedStart(*record, 0, record->samples() - 1);
  if (!clipped) return applied;
  const Eigen::Index kept = record->values.rows() - clipped->first_whole;
  record->values = record->values.bottomRows(kept).eval();
  record->start_time_s += static_cast<double>(clipped->first_whole) * record->sample_interval_s;
  applied.clipped_until_s = record->start_time_s;
  applied.clipped = clipped->reason;
  return applied;
}

}  // namespace mbid::validation
