#include "mbid/campaign/damper_sizing.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <utility>

#include "mbid/campaign/campaign.h"
#include "mbid/campaign/campaign_case.h"
#include "mbid/common/error.h"
#include "vectors.h"

namespace mbid::campaign {
namespace {

using internal::kNaN;
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr int kMaxBisections = 200;  // log2 of any range over any tolerance above 1e-15

std::pair<double, double> ReadRange(const YamlReader& range) {
  if (!range.node().IsSequence() || range.node().size() != 2) {
    range.Fail("is not a pair", "[smallest, largest] damping in N*m*s/rad");
  }
  const double low = YamlReader(range.node()[0], range.source(), range.field() + "[0]").AsDouble();
  const double high = YamlReader(range.node()[1], range.source(), range.field() + "[1]").AsDouble();
  if (!(low >= 0 && low < high)) {
    range.Fail(fmt::format("[{}, {}]", low, high), "0 <= smallest < largest");
  }
  return {low, high};
}

// The sweep point's metrics against one target.
struct Point {
  double min_damping_ratio = kNaN;
  double settling_time_s = kNaN;
};

bool Meets(const DamperSizingSpec& spec, const std::string& target, const Point& point) {
  const bool ratio = point.min_damping_ratio >= spec.min_damping_ratio;
  const bool settling = point.settling_time_s <= spec.max_settling_time_s;
  if (target == "min_damping_ratio") return ratio;
  if (target == "max_settling_time_s") return settling;
  return ratio && settling;
}

// Evaluates the model with d_joint = damping: an ad-hoc case of the campaign.
class Evaluator {
 public:
  Evaluator(const Campaign& campaign, const DamperSizingSpec& spec, const std::string& joint)
      : campaign_(campaign) {
    campaign_.cases.clear();
    key_ = spec.DampingKey(joint);
    // The damping ratio alone needs no simulation.
    if (!spec.has_settling_target()) campaign_.steps = {false, false, false};
  }
  // Targets bisect over the same brackets ("all" repeats another target's): each damping is
  // evaluated once.
  Point operator()(double damping, int* evaluations, std::string* failure) const {
    ++*evaluations;
    const auto cached = cache_.find(damping);
    if (cached != cache_.end()) return cached->second;
    const CampaignCase one_case = MakeAdHocCase(
        campaign_, {{key_, NumberNode(damping), "damper_sizing.range_Nms_per_rad"}}, "sizing");
    const CaseOutcome outcome = ComputeCase(campaign_, one_case);
    Point point;
    if (!outcome.ok()) {
      *failure = outcome.reason;
      return point;
    }
    point.min_damping_ratio =
        *std::min_element(outcome.exact_damping_ratios.begin(), outcome.exact_damping_ratios.end());
    point.settling_time_s = outcome.settling_time_s;
    cache_.emplace(damping, point);
    return point;
  }

 private:
  Campaign campaign_;
  std::string key_;
  mutable std::map<double, Point> cache_;
};

using internal::ToVector;

// A joint's curves from the cases' summary rows (the cases that swept its damper, in campaign
// order); `damping` and `points` receive the sweep for the bisection.
JointSizing ReadCurves(const DamperSizingSpec& spec, const std::string& joint,
                       const std::vector<nlohmann::ordered_json>& rows,
                       std::vector<double>* damping_out, std::vector<Point>* points_out) {
  const std::string key = spec.DampingKey(joint);
  JointSizing sizing;
  sizing.joint = joint;
  std::vector<double>& damping = *damping_out;
  std::vector<Point>& points = *points_out;
  std::vector<std::vector<double>> ratios;
  size_t modes = 0;
  for (const auto& row : rows) {
    if (!row.contains(key)) continue;
    damping.push_back(RowNumber(row, key));
    Point point;
    std::vector<double> mode_ratios;
    if (row["status"] == "ok") {
      point.min_damping_ratio = RowNumber(row, "exact.min_damping_ratio");
      point.settling_time_s = RowNumber(row, "settling_time_s");
      if (row.contains("settling_time_s") && row["settling_time_s"].is_null()) {
        point.settling_time_s = kInf;  // not settled within the record
      }
      for (int k = 1; row.contains(fmt::format("exact.mode{}.damping_ratio", k)); ++k) {
        mode_ratios.push_back(RowNumber(row, fmt::format("exact.mode{}.damping_ratio", k)));
      }
    }
    modes = std::max(modes, mode_ratios.size());
    points.push_back(point);
    ratios.push_back(mode_ratios);
  }
  const Eigen::Index n = static_cast<Eigen::Index>(damping.size());
  sizing.damping_Nms_per_rad = ToVector(damping);
  sizing.damping_ratio = Eigen::MatrixXd::Constant(n, static_cast<Eigen::Index>(modes), kNaN);
  sizing.min_damping_ratio.resize(n);
  sizing.settling_time_s.resize(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto& mode_ratios = ratios[static_cast<size_t>(i)];
    for (size_t k = 0; k < mode_ratios.size(); ++k) {
      sizing.damping_ratio(i, static_cast<Eigen::Index>(k)) = mode_ratios[k];
    }
    sizing.min_damping_ratio[i] = points[static_cast<size_t>(i)].min_damping_ratio;
    sizing.settling_time_s[i] = points[static_cast<size_t>(i)].settling_time_s;
  }
  return sizing;
}

// The smallest damping that meets `target` (NaN if no sweep point does) and how it was found;
// `evaluations` counts the bisection's evaluations of the model.
std::pair<double, std::string> FindSmallest(const DamperSizingSpec& spec, const std::string& target,
                                            const std::vector<double>& damping,
                                            const std::vector<Point>& points,
                                            const Evaluator& evaluate, int* evaluations_total) {
  size_t first = 0;
  while (first < points.size() && !Meets(spec, target, points[first])) ++first;
  if (first == points.size()) {
    return {kNaN, fmt::format("not met by any damping up to {:.6g} N*m*s/rad",
                              damping.empty() ? kNaN : damping.back())};
  }
  if (first == 0) {
    return {damping[0], "met at the smallest damping of the range; smaller not tried"};
  }
  // Bisection between the last failing and the first admissible sweep point: it finds the
  // smallest admissible damping when the target holds on one side of a single crossing,
  // and a crossing inside the bracket otherwise.
  double low = damping[first - 1];
  double high = damping[first];
  int evaluations = 0;
  std::string failure;
  for (int i = 0; i < kMaxBisections && (high - low) > spec.relative_tolerance * high; ++i) {
    const double middle = spec.log_spacing && low > 0 ? std::sqrt(low * high) : 0.5 * (low + high);
    (Meets(spec, target, evaluate(middle, &evaluations, &failure)) ? high : low) = middle;
  }
  *evaluations_total += evaluations;
  std::string note = fmt::format("bisection between {:.6g} and {:.6g} N*m*s/rad ({} steps)",
                                 damping[first - 1], damping[first], evaluations);
  if (!failure.empty()) note += "; some evaluations failed: " + failure;
  return {high, note};
}

}  // namespace

DamperSizingSpec ReadDamperSizing(const YamlReader& section, const YAML::Node& base) {
  section.ExpectMap(
      {"joints", "range_Nms_per_rad", "points", "spacing", "targets", "relative_tolerance"});
  DamperSizingSpec spec;
  spec.joints = section.StringList("joints");
  if (spec.joints.empty())
    section.FailAt("joints", "empty list", "the joints whose dampers to size");
  // The truck crane names its joints in model.joints; a machine description its compliant
  // coordinates in model.springs (a revolute one's damper is in N*m*s/rad, as the range).
  const YAML::Node model = base["model"];
  const bool described = model && model.IsMap() && model["type"] && model["type"].IsScalar() &&
                         model["type"].Scalar() == "multibody";
  const YAML::Node joints =
      model && model.IsMap() ? model[described ? "springs" : "joints"] : YAML::Node();
  std::vector<std::string> known;
  if (joints && joints.IsMap()) {
    for (const auto& item : joints) known.push_back(item.first.Scalar());
  }
  const std::string where = described ? "model.springs" : "model.joints";
  for (const std::string& joint : spec.joints) {
    if (std::find(known.begin(), known.end(), joint) == known.end()) {
      section.FailAt("joints", "unknown joint '" + joint + "'",
                     known.empty()
                         ? "a joint of the base scenario's " + where + " (it has none)"
                         : fmt::format("joints of the base scenario's {}: {}; did you "
                                       "mean '{}'?",
                                       where, fmt::join(known, ", "), ClosestMatch(joint, known)));
    }
    if (described && joints[joint].IsMap() && !joints[joint]["stiffness_Nm_per_rad"] &&
        !joints[joint]["damping_Nms_per_rad"]) {
      section.FailAt("joints",
                     "'" + joint + "' is a prismatic coordinate (its spring in N/m and N*s/m)",
                     "revolute coordinates: the study sizes dampers in N*m*s/rad");
    }
    spec.damping_keys[joint] = where + "." + joint + ".damping_Nms_per_rad";
  }
  const YamlReader range = section.Child("range_Nms_per_rad");
  if (range.node().IsMap()) {
    range.ExpectMap(spec.joints);
    for (const std::string& joint : spec.joints) {
      spec.range_Nms_per_rad[joint] = ReadRange(range.Child(joint));
    }
  } else {
    const auto both = ReadRange(range);
    for (const std::string& joint : spec.joints) spec.range_Nms_per_rad[joint] = both;
  }
  spec.points = section.Int("points", spec.points);
  if (spec.points < 2 || spec.points > 10000) {
    section.FailAt("points", std::to_string(spec.points), "an integer between 2 and 10000");
  }
  spec.log_spacing = section.Choice("spacing", {"log", "linear"}, "log") == "log";
  if (spec.log_spacing) {
    for (const auto& [joint, bounds] : spec.range_Nms_per_rad) {
      if (!(bounds.first > 0)) {
        section.FailAt("range_Nms_per_rad", fmt::format("{} starts at 0", joint),
                       "a positive smallest damping for spacing: log");
      }
    }
  }
  const YamlReader targets = section.Child("targets");
  targets.ExpectMap(
      {"min_damping_ratio", "max_settling_time_s", "settling_band_fraction", "settling_band_rad"});
  spec.min_damping_ratio = targets.Double("min_damping_ratio", 0.0);
  spec.max_settling_time_s = targets.Double("max_settling_time_s", 0.0);
  if (spec.min_damping_ratio < 0 || spec.min_damping_ratio > 1) {
    targets.FailAt("min_damping_ratio", fmt::format("{}", spec.min_damping_ratio),
                   "a damping ratio in (0, 1]");
  }
  if (spec.max_settling_time_s < 0) {
    targets.FailAt("max_settling_time_s", fmt::format("{}", spec.max_settling_time_s),
                   "a positive time in s");
  }
  if (spec.min_damping_ratio == 0 && spec.max_settling_time_s == 0) {
    targets.Fail("no target", "min_damping_ratio and/or max_settling_time_s");
  }
  spec.settling_band_fraction = targets.Double("settling_band_fraction", 0.02);
  if (!(spec.settling_band_fraction > 0 && spec.settling_band_fraction < 1)) {
    targets.FailAt("settling_band_fraction", fmt::format("{}", spec.settling_band_fraction),
                   "a fraction in (0, 1)");
  }
  spec.settling_band_rad = targets.Double("settling_band_rad", 0.0);
  if (spec.settling_band_rad < 0) {
    targets.FailAt("settling_band_rad", fmt::format("{}", spec.settling_band_rad),
                   "a positive band in rad (or none: a fraction of the peak)");
  }
  if (spec.has_settling_target() && !base["excitation"].IsDefined()) {
    targets.FailAt("max_settling_time_s", "a settling target without an excitation",
                   "an excitation in the base scenario (the test that settles)");
  }
  spec.relative_tolerance = section.PositiveDouble("relative_tolerance", spec.relative_tolerance);
  return spec;
}

std::vector<std::vector<Assignment>> DamperSizingCases(const DamperSizingSpec& spec,
                                                       const std::string& field) {
  std::vector<std::vector<Assignment>> cases;
  for (const std::string& joint : spec.joints) {
    const auto [low, high] = spec.range_Nms_per_rad.at(joint);
    for (int k = 0; k < spec.points; ++k) {
      const double u = static_cast<double>(k) / (spec.points - 1);
      const double value = k == spec.points - 1 ? high
                           : spec.log_spacing   ? low * std::pow(high / low, u)
                                                : low + u * (high - low);
      cases.push_back({{spec.DampingKey(joint), NumberNode(value), field + ".range_Nms_per_rad"}});
    }
  }
  return cases;
}

double CalcSettlingTime(const Measurement& exact, double after_s, double band_fraction,
                        double band_rad) {
  const Eigen::VectorXd t = exact.CalcTime();
  Eigen::Index first = 0;
  while (first < t.size() && t[first] < after_s - 1e-12) ++first;
  if (first >= t.size()) return kNaN;
  Eigen::Index last_outside = -1;
  for (int c = 0; c < exact.channel_count(); ++c) {
    const auto y = exact.values.col(c).tail(t.size() - first);
    const double band = band_rad > 0 ? band_rad : band_fraction * y.cwiseAbs().maxCoeff();
    for (Eigen::Index j = y.size() - 1; j >= 0; --j) {
      if (std::abs(y[j]) > band) {
        last_outside = std::max(last_outside, first + j);
        break;
      }
    }
  }
  if (last_outside < 0) return 0.0;
  if (last_outside == t.size() - 1) return kInf;
  return t[last_outside + 1] - after_s;
}

DamperSizingResult SizeDampers(const Campaign& campaign, const DamperSizingSpec& spec,
                               const std::vector<nlohmann::ordered_json>& rows) {
  DamperSizingResult result;
  std::vector<std::string> targets;
  if (spec.min_damping_ratio > 0) targets.push_back("min_damping_ratio");
  if (spec.has_settling_target()) targets.push_back("max_settling_time_s");
  if (targets.size() == 2) targets.push_back("all");

  for (const std::string& joint : spec.joints) {
    std::vector<double> damping;
    std::vector<Point> points;
    JointSizing sizing = ReadCurves(spec, joint, rows, &damping, &points);
    const Evaluator evaluate(campaign, spec, joint);
    for (const std::string& target : targets) {
      sizing.targets.push_back(target);
      const auto [smallest, note] =
          FindSmallest(spec, target, damping, points, evaluate, &result.refinement_evaluations);
      sizing.smallest_Nms_per_rad.push_back(smallest);
      sizing.notes.push_back(note);
    }
    result.joints.push_back(std::move(sizing));
  }
  return result;
}

void WriteDamperSizing(H5Writer& file, const DamperSizingSpec& spec,
                       const DamperSizingResult& result) {
  const std::string root = "/damper_sizing";
  file.WriteDoubleAttribute(root, "min_damping_ratio", spec.min_damping_ratio);
  file.WriteDoubleAttribute(root, "max_settling_time_s", spec.max_settling_time_s);
  file.WriteDoubleAttribute(root, "settling_band_fraction", spec.settling_band_fraction);
  file.WriteDoubleAttribute(root, "settling_band_rad", spec.settling_band_rad);
  file.WriteDoubleAttribute(root, "relative_tolerance", spec.relative_tolerance);
  for (const JointSizing& joint : result.joints) {
    const std::string group = root + "/" + joint.joint;
    file.WriteVector(group, "damping_Nms_per_rad", joint.damping_Nms_per_rad, "N*m*s/rad");
    file.WriteMatrix(group, "damping_ratio", joint.damping_ratio, "1");
    file.WriteVector(group, "min_damping_ratio", joint.min_damping_ratio, "1");
    if (spec.has_settling_target()) {
      file.WriteVector(group, "settling_time_s", joint.settling_time_s, "s");
    }
    file.WriteStrings(group, "targets", joint.targets);
    file.WriteVector(group, "smallest_Nms_per_rad", ToVector(joint.smallest_Nms_per_rad),
                     "N*m*s/rad");
    file.WriteStrings(group, "notes", joint.notes);
  }
}

}  // namespace mbid::campaign
