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
  // Settling band: a fraction of each channel's peak deviation after the excitation, or (if
  // positive) an absolute band in the channels' unit (rad).
  double settling_band_fraction = 0.02;
  double settling_band_rad = 0;
  double relative_tolerance = 1e-6;  // bisection stops at this relative bracket width

  bool has_settling_target() const { return max_settling_time_s > 0; }
  // The scenario key of each joint's damping: model.joints.<joint>.damping_Nms_per_rad (the
  // truck crane) or model.springs.<coordinate>.damping_Nms_per_rad (a machine description).
  std::map<std::string, std::string> damping_keys;
  const std::string& DampingKey(const std::string& joint) const { return damping_keys.at(joint); }
};

// Reads the `damper_sizing:` section; joints must exist in the base scenario's model.joints (the
// truck crane) or be revolute coordinates with a spring in model.springs (a description).
DamperSizingSpec ReadDamperSizing(const YamlReader& section, const YAML::Node& base);

// The cases of the sweep: for each joint, `points` values of its damping (log or linear).
std::vector<std::vector<Assignment>> DamperSizingCases(const DamperSizingSpec& spec,
                                                       const std::string& field);

// The settling time (s) of a free decay about zero: the first sample time after which every
// channel stays within its band (|y| <= fraction * max|y| after `after_s`, or <= band_rad), or
// +inf if the last sample is still outside. Times before `after_s` (a forcing) are ignored.
double CalcSettlingTime(const Measurement& exact, double after_s, double band_fraction,
                        double band_rad);

// The sizing of one joint: its curves and the smallest damping meeting each target.
struct JointSizing {
  std::string joint;
  Eigen::VectorXd damping_Nms_per_rad;  // sweep points
  Eigen::MatrixXd damping_ratio;        // points x modes (NaN where a case has fewer modes)
  Eigen::VectorXd min_damping_ratio;    // per point
  Eigen::VectorXd settling_time_s;      // per point (NaN without a settling target)
  // Per target ("min_damping_ratio", "max_settling_time_s", "all"): the smallest damping that
  // meets it, NaN if no sweep point does; and how it was found.
  std::vector<std::string> targets;
  std::vector<double> smallest_Nms_per_rad;
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
