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
#include "mbid/simulation/scenario_sections.h"
#include "mbid/validation/result_writers.h"
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

// How far a point is inside the target, relative to it: >= 0 where it meets it, NaN where its
// evaluation failed. "all" is the smaller of the two.
double Margin(const DamperSizingSpec& spec, const std::string& target, const Point& point) {
  const double ratio = point.min_damping_ratio / spec.min_damping_ratio - 1;
  const double settling = spec.max_settling_time_s / point.settling_time_s - 1;  // never: -1
  if (target == "min_damping_ratio") return ratio;
  if (target == "max_settling_time_s") return settling;
  if (std::isnan(ratio) || std::isnan(settling)) return kNaN;
  return std::min(ratio, settling);
}

// What a point achieves of the target, for the notes.
std::string Achieved(const std::string& target, const Point& point) {
  std::vector<std::string> parts;
  if (target != "max_settling_time_s") {
    parts.push_back(fmt::format("smallest damping ratio {:.4g}", point.min_damping_ratio));
  }
  if (target != "min_damping_ratio") {
    parts.push_back(std::isinf(point.settling_time_s)
                        ? std::string("not settled within the record")
                        : fmt::format("settling time {:.4g} s", point.settling_time_s));
  }
  return fmt::format("{}", fmt::join(parts, ", "));
}

// Searches the model between sweep points for the dampings the sweep's samples cannot show.
class WindowSearch {
 public:
  WindowSearch(const DamperSizingSpec& spec, const std::string& target, const Evaluator& evaluate)
      : spec_(spec), target_(target), evaluate_(evaluate) {}

  int evaluations() const { return evaluations_; }
  const std::string& failure() const { return failure_; }

  Point At(double damping) { return evaluate_(damping, &evaluations_, &failure_); }
  bool Meets(double damping) { return mbid::campaign::Meets(spec_, target_, At(damping)); }

  double Middle(double a, double b) const {
    return spec_.log_spacing && a > 0 && b > 0 ? std::sqrt(a * b) : 0.5 * (a + b);
  }

  // The edge between a damping that meets the target and one that does not (either order),
  // to the relative tolerance; returns the admissible end.
  double Bisect(double meets, double fails) {
    for (int i = 0; i < kMaxBisections &&
                    std::abs(fails - meets) > spec_.relative_tolerance * std::max(meets, fails);
         ++i) {
      const double middle = Middle(meets, fails);
      (Meets(middle) ? meets : fails) = middle;
    }
    return meets;
  }

  // Golden-section search for the largest margin between `low` and `high` (on a log axis for log
  // spacing), to 1e-4 of the bracket; it stops at the first damping that meets the target.
  std::pair<double, Point> Best(double low, double high) {
    const bool log = spec_.log_spacing && low > 0;
    const auto to_x = [&](double d) { return log ? std::log(d) : d; };
    const auto to_d = [&](double x) { return log ? std::exp(x) : x; };
    const double ratio = 0.5 * (std::sqrt(5.0) - 1);
    double a = to_x(low), b = to_x(high);
    double c = b - ratio * (b - a), d = a + ratio * (b - a);
    Point pc = At(to_d(c)), pd = At(to_d(d));
    const auto margin = [&](const Point& p) {
      const double m = Margin(spec_, target_, p);
      return std::isnan(m) ? -std::numeric_limits<double>::infinity() : m;
    };
    const double width = b - a;
    while (b - a > 1e-4 * width && margin(pc) < 0 && margin(pd) < 0) {
      if (margin(pc) >= margin(pd)) {
        b = d, d = c, pd = pc;
        c = b - ratio * (b - a);
        pc = At(to_d(c));
      } else {
        a = c, c = d, pc = pd;
        d = a + ratio * (b - a);
        pd = At(to_d(d));
      }
    }
    return margin(pc) >= margin(pd) ? std::make_pair(to_d(c), pc) : std::make_pair(to_d(d), pd);
  }

 private:
  const DamperSizingSpec& spec_;
  const std::string& target_;
  const Evaluator& evaluate_;
  int evaluations_ = 0;
  std::string failure_;
};

struct Window {
  double smallest = kNaN;
  double largest = kNaN;
  std::string note;
};

// The smallest damping that meets `target` and the largest of the window that meets it from
// there (NaN, NaN if none was found), and how they were found. Edges are bisected between
// sweep points; where no sweep point meets the target, the model is searched around the
// sweep's best interior points (a window narrower than the sweep's spacing).
Window FindWindow(const DamperSizingSpec& spec, const std::string& target,
                  const std::vector<double>& damping, const std::vector<Point>& points,
                  const Evaluator& evaluate, int* evaluations_total) {
  Window window;
  WindowSearch search(spec, target, evaluate);
  const size_t n = points.size();
  std::vector<std::string> notes;
  size_t first = 0;
  while (first < n && !Meets(spec, target, points[first])) ++first;
  size_t after = n;  // the first sweep point after the window that fails
  if (first == n) {
    // Interior local maxima of the sampled margin, best first: the model between their
    // neighbours may meet the target where no sample does.
    std::vector<size_t> peaks;
    for (size_t i = 1; i + 1 < n; ++i) {
      const double m = Margin(spec, target, points[i]);
      const double before = Margin(spec, target, points[i - 1]);
      const double after_peak = Margin(spec, target, points[i + 1]);
      if (m >= before && m >= after_peak && (m > before || m > after_peak)) peaks.push_back(i);
    }
    std::sort(peaks.begin(), peaks.end(), [&](size_t i, size_t j) {
      return Margin(spec, target, points[i]) > Margin(spec, target, points[j]);
    });
    std::pair<double, Point> best{kNaN, Point()};
    for (size_t k = 0; k < std::min<size_t>(peaks.size(), 3); ++k) {
      const size_t i = peaks[k];
      const auto found = search.Best(damping[i - 1], damping[i + 1]);
      if (std::isnan(best.first) ||
          Margin(spec, target, found.second) > Margin(spec, target, best.second)) {
        best = found;
      }
      if (Meets(spec, target, found.second)) {
        window.smallest = search.Bisect(found.first, damping[i - 1]);
        window.largest = search.Bisect(found.first, damping[i + 1]);
        notes.push_back(fmt::format(
            "met only between {:.6g} and {:.6g} N*m*s/rad, where no sweep point is: found by a "
            "search of the model around the sweep's best point ({:.6g} N*m*s/rad: {}) and "
            "bisection",
            window.smallest, window.largest, damping[i], Achieved(target, points[i])));
        break;
      }
    }
    if (std::isnan(window.smallest)) {
      size_t best_point = 0;
      for (size_t i = 1; i < n; ++i) {
        if (Margin(spec, target, points[i]) > Margin(spec, target, points[best_point])) {
          best_point = i;
        }
      }
      std::string note = fmt::format("not met by any damping from {:.6g} to {:.6g} N*m*s/rad",
                                     damping.empty() ? kNaN : damping.front(),
                                     damping.empty() ? kNaN : damping.back());
      if (target == "max_settling_time_s" && n > 0 &&
          !(Margin(spec, target, points[best_point]) > -1) &&
          !(Margin(spec, target, best.second) > -1)) {
        note += ": the outputs settled within the record at no damping tried";
      } else if (!std::isnan(best.first) &&
                 !(Margin(spec, target, points[best_point]) > Margin(spec, target, best.second))) {
        note += fmt::format(
            ": the best found is {} at {:.6g} N*m*s/rad (a search of the model "
            "around the sweep's best points)",
            Achieved(target, best.second), best.first);
      } else if (n > 0) {
        note += fmt::format(": the sweep's best is {} at {:.6g} N*m*s/rad{}",
                            Achieved(target, points[best_point]), damping[best_point],
                            best_point == 0       ? ", the range's smallest (smaller not tried)"
                            : best_point == n - 1 ? ", the range's largest (larger not tried)"
                                                  : "");
      }
      notes.push_back(note);
    }
  } else {
    if (first == 0) {
      window.smallest = damping[0];
      notes.push_back("met at the smallest damping of the range; smaller not tried");
    } else {
      const int before = search.evaluations();
      window.smallest = search.Bisect(damping[first], damping[first - 1]);
      notes.push_back(fmt::format(
          "from {:.6g}: bisection between {:.6g} and {:.6g} N*m*s/rad "
          "({} steps)",
          window.smallest, damping[first - 1], damping[first], search.evaluations() - before));
    }
    after = first + 1;
    while (after < n && Meets(spec, target, points[after])) ++after;
    if (after == n) {
      window.largest = damping[n - 1];
      notes.push_back("met up to the range's largest damping; larger not tried");
    } else {
      const int before = search.evaluations();
      window.largest = search.Bisect(damping[after - 1], damping[after]);
      notes.push_back(fmt::format(
          "up to {:.6g}: larger dampers fail it again ({}; bisection between {:.6g} and {:.6g} "
          "N*m*s/rad, {} steps)",
          window.largest, Achieved(target, points[after]), damping[after - 1], damping[after],
          search.evaluations() - before));
    }
  }
  for (size_t i = after; i < n; ++i) {
    if (Meets(spec, target, points[i])) {
      notes.push_back(
          fmt::format("met again from the sweep point {:.6g} N*m*s/rad: more than "
                      "one window",
                      damping[i]));
      break;
    }
  }
  if (!search.failure().empty()) notes.push_back("some evaluations failed: " + search.failure());
  *evaluations_total += search.evaluations();
  window.note = fmt::format("{}", fmt::join(notes, "; "));
  return window;
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
    if (!spec.damping_keys.emplace(joint, where + "." + joint + ".damping_Nms_per_rad").second) {
      section.FailAt("joints", "'" + joint + "' twice", "each joint once");
    }
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
  spec.points = section.IntInRange("points", spec.points, 2, 10000);
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
  std::vector<std::string> target_keys{"min_damping_ratio", "max_settling_time_s",
                                       "settling_band_fraction"};
  for (const std::string& key : simulation::UnitKeys("settling_band")) target_keys.push_back(key);
  targets.ExpectMap(target_keys);
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
  if (!spec.has_settling_target()) {
    for (size_t k = 2; k < target_keys.size(); ++k) {
      if (targets.Has(target_keys[k])) {
        targets.FailAt(target_keys[k], "a settling band without a settling target",
                       "max_settling_time_s beside it (or no band)");
      }
    }
  }
  spec.settling_band_fraction = targets.Double("settling_band_fraction", 0.02);
  if (!(spec.settling_band_fraction > 0 && spec.settling_band_fraction < 1)) {
    targets.FailAt("settling_band_fraction", fmt::format("{}", spec.settling_band_fraction),
                   "a fraction in (0, 1)");
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

void ReadSettlingBands(const YamlReader& section, const validation::Scenario& probe,
                       DamperSizingSpec* spec) {
  if (!spec->has_settling_target()) return;
  const YamlReader targets = section.Child("targets");
  const std::unique_ptr<model::MechanicalModel> model = probe.MakeModel();
  const std::vector<std::string>& channels = probe.sensors.channels;
  for (const std::string& key : simulation::UnitKeys("settling_band")) {
    if (!targets.Has(key)) continue;
    const YamlReader band = targets.Child(key);
    for (const std::string& channel : band.IsMap() ? band.Keys() : std::vector<std::string>{}) {
      if (!(band.Double(channel) > 0)) {
        band.FailAt(channel, fmt::format("{}", band.Double(channel)),
                    "a positive band in the channel's unit");
      }
    }
    if (!band.IsMap() && !(targets.Double(key) > 0)) {
      targets.FailAt(key, fmt::format("{}", targets.Double(key)),
                     "a positive band in the unit of the key (or none: a fraction of the peak)");
    }
  }
  spec->settling_bands = simulation::ReadPerUnitChannelValues(targets, "settling_band", channels,
                                                              *model, /*non_negative=*/false);
  if (!spec->settling_bands.empty()) {
    if (targets.Has("settling_band_fraction")) {
      targets.FailAt("settling_band_fraction", "a fraction beside absolute bands",
                     "either absolute bands (settling_band_<unit>) or a fraction of the peak");
    }
    std::map<std::string, std::string>& units = spec->settling_band_units;
    for (int i = 0; i < model->output_count(); ++i) {
      units[model->output_names()[static_cast<size_t>(i)]] =
          model->output_units()[static_cast<size_t>(i)];
    }
    for (int i = 0; i < model->coordinate_count(); ++i) {
      units.emplace(model->coordinate_names()[static_cast<size_t>(i)],
                    model->coordinate_units()[static_cast<size_t>(i)]);
    }
    for (const std::string& channel : channels) {
      if (spec->settling_bands.count(channel) == 0) {
        targets.Fail(fmt::format("no band for channel '{}' (in {})", channel, units[channel]),
                     "an absolute band for every channel, each in its unit's key "
                     "(settling_band_rad, _m, _mps, _mps2, _radps), or settling_band_fraction "
                     "alone");
      }
    }
  }
  // The outputs must be seen inside their band for a period of the slowest mode after the
  // target: a shorter record cannot tell a settled output from one ringing through zero.
  std::vector<double> frequencies;
  for (const model::Mode& mode : validation::CalcModelTruth(*model).modes) {
    frequencies.push_back(mode.frequency_hz());
  }
  const double period = SlowestPeriod(frequencies);
  const double duration = probe.simulation.duration_s;
  if (duration < spec->max_settling_time_s + period) {
    targets.FailAt("max_settling_time_s",
                   fmt::format("a target of {} s in a record of {} s (simulation.duration_s)",
                               spec->max_settling_time_s, duration),
                   fmt::format("a record at least the target plus the slowest mode's period "
                               "({:.3g} s at the base damping) long: duration_s >= {:.4g}",
                               period, spec->max_settling_time_s + period));
  }
}

double SlowestPeriod(const std::vector<double>& frequencies_hz) {
  double period = 0;
  for (const double f : frequencies_hz) {
    if (f > 0) period = std::max(period, 1.0 / f);
  }
  return period;
}

double CalcSettlingTime(const Measurement& exact, double after_s, double band_fraction,
                        const std::map<std::string, double>& bands, double hold_s) {
  const Eigen::VectorXd t = exact.CalcTime();
  Eigen::Index first = 0;
  while (first < t.size() && t[first] < after_s - 1e-12) ++first;
  if (first >= t.size()) return kNaN;
  Eigen::Index last_outside = -1;
  for (int c = 0; c < exact.channel_count(); ++c) {
    const auto y = exact.values.col(c).tail(t.size() - first);
    const auto given = bands.find(exact.channels[static_cast<size_t>(c)]);
    const double band =
        given != bands.end() ? given->second : band_fraction * y.cwiseAbs().maxCoeff();
    for (Eigen::Index j = y.size() - 1; j >= 0; --j) {
      if (std::abs(y[j]) > band) {
        last_outside = std::max(last_outside, first + j);
        break;
      }
    }
  }
  if (last_outside < 0) return 0.0;
  if (last_outside == t.size() - 1) return kInf;
  const double settled = t[last_outside + 1];
  if (t[t.size() - 1] - settled < hold_s) return kInf;
  return settled - after_s;
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
      const Window window =
          FindWindow(spec, target, damping, points, evaluate, &result.refinement_evaluations);
      sizing.smallest_Nms_per_rad.push_back(window.smallest);
      sizing.largest_Nms_per_rad.push_back(window.largest);
      sizing.notes.push_back(window.note);
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
  // The band that applied: a fraction of each output's peak, or a band per channel in its unit.
  file.WriteDoubleAttribute(root, "settling_band_fraction",
                            spec.settling_bands.empty() ? spec.settling_band_fraction : kNaN);
  for (const auto& [channel, band] : spec.settling_bands) {
    file.WriteDoubleAttribute(root, "settling_band." + channel, band);
  }
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
    file.WriteVector(group, "largest_Nms_per_rad", ToVector(joint.largest_Nms_per_rad),
                     "N*m*s/rad");
    file.WriteStrings(group, "notes", joint.notes);
  }
}

}  // namespace mbid::campaign
