#pragma once

#include <Eigen/Core>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "mbid/campaign/campaign_sweep.h"
#include "mbid/common/hdf5_io.h"
#include "mbid/common/measurement.h"
#include "mbid/common/yaml_reader.h"
#include "mbid/validation/scenario.h"

namespace mbid::campaign {

struct Campaign;

// `study: damper_sizing` (docs/campaigns.md): for each chosen joint k, the damping d_k alone is
// swept over a range (the other joints keep the base values), and the smallest d_k is sought
// that meets every target:
//   min_damping_ratio      the smallest damping ratio of the exact modes >= this
//   max_settling_time_s    the settling time of the outputs <= this (needs an excitation)
// The sweep gives the curves; the smallest admissible d_k is then bracketed between the last
// sweep point that fails and the first that meets, and refined by bisection on the model.
struct DamperSizingSpec {
  std::vector<std::string> joints;
  std::map<std::string, std::pair<double, double>> range_Nms_per_rad;  // per joint
  int points = 21;
  bool log_spacing = true;
  double min_damping_ratio = 0;    // target; 0 = none
  double max_settling_time_s = 0;  // target; 0 = none
  // Settling band: a fraction of each channel's peak deviation after the excitation, or
  // absolute bands in each channel's unit (`settling_band_rad`, `_m`, `_mps`, `_mps2`,
  // `_radps`; a number per unit or a map per channel), then one for every channel.
  double settling_band_fraction = 0.02;
  std::map<std::string, double> settling_bands;  // channel -> band in its unit; empty: fraction
  std::map<std::string, std::string> settling_band_units;  // channel -> its unit
  double relative_tolerance = 1e-6;  // bisection stops at this relative bracket width

  bool has_settling_target() const { return max_settling_time_s > 0; }
  // The scenario key of each joint's damping: model.joints.<joint>.damping_Nms_per_rad (the
  // truck crane) or model.springs.<coordinate>.damping_Nms_per_rad (a machine description).
  std::map<std::string, std::string> damping_keys;
  const std::string& DampingKey(const std::string& joint) const { return damping_keys.at(joint); }
};

// Reads the `damper_sizing:` section; joints must exist in the base scenario's model.joints (the
// truck crane) or be revolute coordinates with a spring in model.springs (a description). The
// absolute settling bands need the channels' units: ReadSettlingBands.
DamperSizingSpec ReadDamperSizing(const YamlReader& section, const YAML::Node& base);

// The absolute settling bands of `damper_sizing.targets` for the channels of the cases' scenario
// (`probe`: the base with the campaign's `set:`): a band for every channel in its unit or none;
// and a record long enough to show the settling target (the forcing, the target and
// SettlingHold at the base damping).
void ReadSettlingBands(const YamlReader& section, const validation::Scenario& probe,
                       DamperSizingSpec* spec);

// The cases of the sweep: for each joint, `points` values of its damping (log or linear).
std::vector<std::vector<Assignment>> DamperSizingCases(const DamperSizingSpec& spec,
                                                       const std::string& field);

// The settling time (s) of a free decay about zero: the first sample time after which every
// channel stays within its band (`bands` by channel, else |y| <= fraction * max|y| after
// `after_s`), +inf if the last sample is still outside, and +inf too if the outputs stay inside
// for less than `hold_s` (SettlingHold) before the record ends: a ringing output passes inside
// its band near each zero crossing, so only a longer stay shows that it has settled. With the
// model's exact modes, +inf also where the modes fitted to the free decay, continued past the
// record's end, leave a band again (modes beating: a node can outlast any stay). Times before
// `after_s` (a forcing) are ignored.
double CalcSettlingTime(const Measurement& exact, double after_s, double band_fraction,
                        const std::map<std::string, double>& bands, double hold_s,
                        const std::vector<double>& frequencies_hz = {},
                        const std::vector<double>& decay_rates_per_s = {});

// How long outputs must stay inside their band to count as settled: over the oscillatory modes
// (frequency > 0), the longest of min(damped period, 3 / decay rate). A lightly damped mode
// must be seen for a whole period; a nearly critically damped one, whose period grows without
// bound, decays by e^-3 in 3 / decay rate and rings no more (its overshoot past zero is below
// e^-1.5 of its envelope wherever the period is longer).
double SettlingHold(const std::vector<double>& frequencies_hz,
                    const std::vector<double>& decay_rates_per_s);

// The sizing of one joint: its curves and the smallest damping meeting each target.
struct JointSizing {
  std::string joint;
  Eigen::VectorXd damping_Nms_per_rad;  // sweep points
  Eigen::MatrixXd damping_ratio;        // points x modes (NaN where a case has fewer modes)
  Eigen::VectorXd min_damping_ratio;    // per point
  Eigen::VectorXd settling_time_s;      // per point (NaN without a settling target)
  // Per target ("min_damping_ratio", "max_settling_time_s", "all"): the smallest damping that
  // meets it, NaN if none was found; the largest of the window of dampings that meet it from
  // there (a damper that locks its joint lowers the damping ratios again), the range's end when
  // it is met up to there; and how they were found.
  std::vector<std::string> targets;
  std::vector<double> smallest_Nms_per_rad;
  std::vector<double> largest_Nms_per_rad;
  std::vector<std::string> notes;
};

struct DamperSizingResult {
  std::vector<JointSizing> joints;
  int refinement_evaluations = 0;
};

// The curves from the cases' summary rows (in campaign order) and the refined smallest
// dampers; the refinement evaluates ad-hoc cases of `campaign` (serially).
DamperSizingResult SizeDampers(const Campaign& campaign, const DamperSizingSpec& spec,
                               const std::vector<nlohmann::ordered_json>& rows);

// /damper_sizing/<joint>/...: damping_Nms_per_rad, damping_ratio (points x modes),
// min_damping_ratio, settling_time_s, targets, smallest_Nms_per_rad, notes.
void WriteDamperSizing(H5Writer& file, const DamperSizingSpec& spec,
                       const DamperSizingResult& result);

// The report section (Markdown) with its figures drawn into `folder` (damping ratio of every
// mode vs d_k, settling time vs d_k); `figures` receives the PNG file names.
std::string DamperSizingReport(const DamperSizingSpec& spec, const DamperSizingResult& result,
                               const std::string& folder, std::vector<std::string>* figures);

}  // namespace mbid::campaign
