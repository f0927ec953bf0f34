#include "mbid/campaign/damper_sizing.h"

#include <fmt/format.h>

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <utility>

#include "damper_window.h"
#include "mbid/campaign/campaign.h"
#include "mbid/campaign/campaign_case.h"
#include "mbid/common/error.h"
#include "mbid/simulation/scenario_sections.h"
#include "mbid/validation/result_writers.h"
#include "vectors.h"

namespace mbid::campaign {
namespace {

using internal::FindWindow;
using internal::kNaN;
using internal::SizingEvaluator;
using internal::SizingPoint;
using internal::Window;
constexpr double kInf = std::numeric_limits<double>::infinity();

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

using internal::ToVector;

// A joint's curves from the cases' summary rows (the cases that swept its damper, in campaign
// order); `damping` and `points` receive the sweep for the bisection.
JointSizing ReadCurves(const DamperSizingSpec& spec, const std::string& joint,
                       const std::vector<nlohmann::ordered_json>& rows,
                       std::vector<double>* damping_out, std::vector<SizingPoint>* points_out) {
  const std::string key = spec.DampingKey(joint);
  JointSizing sizing;
  sizing.joint = joint;
  std::vector<double>& damping = *damping_out;
  std::vector<SizingPoint>& points = *points_out;
  std::vector<std::vector<double>> ratios;
  size_t modes = 0;
  for (const auto& row : rows) {
    if (!row.contains(key)) continue;
    damping.push_back(RowNumber(row, key));
    SizingPoint point;
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
    units = simulation::ChannelUnits(*model);
    for (const std::string& channel : channels) {
      if (spec->settling_bands.count(channel) == 0) {
        targets.Fail(fmt::format("no band for channel '{}' (in {})", channel, units[channel]),
                     "an absolute band for every channel, each in its unit's key "
                     "(settling_band_rad, _m, _mps, _mps2, _radps), or settling_band_fraction "
                     "alone");
      }
    }
  }
  // The outputs must be seen inside their band for SettlingHold after the target, counted from
  // the forcing's end: a shorter record cannot tell a settled output from one ringing through
  // zero.
  std::vector<double> frequencies, decay_rates;
  for (const model::Mode& mode : validation::CalcModelTruth(*model).modes) {
    frequencies.push_back(mode.frequency_hz());
    decay_rates.push_back(mode.decay_rate_per_s());
  }
  const double hold = SettlingHold(frequencies, decay_rates);
  const double forcing =
      probe.has_excitation
          ? simulation::CalcFreeDecayStart(*model, probe.excitation, probe.simulation.integrator)
                .time_s
          : 0.0;
  const double duration = probe.simulation.duration_s;
  const double needed = forcing + spec->max_settling_time_s + hold;
  if (duration < needed) {
    targets.FailAt("max_settling_time_s",
                   fmt::format("a target of {} s in a record of {} s (simulation.duration_s)",
                               spec->max_settling_time_s, duration),
                   fmt::format("a record of the forcing ({:.3g} s), the target and {:.3g} s "
                               "after it (the outputs seen to stay in their band, at the base "
                               "damping): duration_s >= {:.4g}",
                               forcing, hold, needed));
  }
}

double SettlingHold(const std::vector<double>& frequencies_hz,
                    const std::vector<double>& decay_rates_per_s) {
  double hold = 0;
  for (size_t k = 0; k < frequencies_hz.size(); ++k) {
    if (!(frequencies_hz[k] > 0)) continue;
    const double decay = k < decay_rates_per_s.size() ? decay_rates_per_s[k] : 0.0;
    const double period = 1.0 / frequencies_hz[k];
    hold = std::max(hold, decay > 0 ? std::min(period, 3.0 / decay) : period);
  }
  return hold;
}

namespace {

// Whether the outputs, continued past the record's end by their modes, stay within their bands:
// the exact modes' exponentials are fitted to each channel's free decay by least squares and
// evaluated forward until their envelope sum_k |r_k| e^(-sigma_k t), which bounds them, is
// inside. Two lightly damped modes beating leave the band again after a node that can outlast
// any stay (a re-audit's two tuned turntables: inside for 1.1 s near 4.7 s, six times the band
// at 10 s, settled at 62 s). Where the modes do not describe the decay near its end (a
// nonlinear output), the check cannot speak and passes.
bool ModesStayInside(const Eigen::VectorXd& t, Eigen::Index first, Eigen::Index settled,
                     const Eigen::MatrixXd& values, const std::vector<double>& bands,
                     const std::vector<double>& frequencies_hz,
                     const std::vector<double>& decay_rates_per_s) {
  struct Term {
    double sigma, omega;  // omega 0: a real pole
    bool sine;
  };
  std::vector<Term> terms;
  double shortest_period = std::numeric_limits<double>::infinity();
  for (size_t k = 0; k < frequencies_hz.size() && k < decay_rates_per_s.size(); ++k) {
    const double sigma = decay_rates_per_s[k], omega = 2 * M_PI * frequencies_hz[k];
    if (!(sigma > 0)) return true;  // an undamped or unstable mode: nothing to bound with
    terms.push_back({sigma, omega, false});
    if (omega > 0) {
      terms.push_back({sigma, omega, true});
      shortest_period = std::min(shortest_period, 2 * M_PI / omega);
    }
  }
  const Eigen::Index n = t.size() - first;
  const Eigen::Index m = static_cast<Eigen::Index>(terms.size());
  if (m == 0 || n <= 2 * m) return true;
  const auto basis = [&](double tau, Eigen::Index j) {
    const Term& term = terms[static_cast<size_t>(j)];
    const double decay = std::exp(-term.sigma * tau);
    if (term.omega == 0) return decay;
    return decay * (term.sine ? std::sin(term.omega * tau) : std::cos(term.omega * tau));
  };
  Eigen::MatrixXd design(n, m);
  for (Eigen::Index i = 0; i < n; ++i) {
    for (Eigen::Index j = 0; j < m; ++j) design(i, j) = basis(t[first + i] - t[first], j);
  }
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(design);
  const double end = t[t.size() - 1] - t[first];
  const double step = std::min(t.size() > 1 ? t[1] - t[0] : 1.0, shortest_period / 20);
  constexpr long kMaxSteps = 2000000;
  for (Eigen::Index c = 0; c < values.cols(); ++c) {
    const Eigen::VectorXd y = values.col(c).tail(n);
    const Eigen::VectorXd amplitude = qr.solve(y);
    const double band = bands[static_cast<size_t>(c)];
    const Eigen::VectorXd residual = y - design * amplitude;
    if (residual.tail(t.size() - settled).cwiseAbs().maxCoeff() > 0.5 * band) continue;
    std::vector<double> envelope(terms.size(), 0.0);  // |r_k| per term pair, on its cosine
    for (size_t j = 0; j < terms.size(); ++j) {
      if (terms[j].sine) continue;
      const double sine = j + 1 < terms.size() && terms[j + 1].sine ? amplitude[j + 1] : 0.0;
      envelope[j] = std::hypot(amplitude[static_cast<Eigen::Index>(j)], sine);
    }
    for (long s = 1; s <= kMaxSteps; ++s) {
      const double tau = end + s * step;
      double bound = 0, value = 0;
      for (size_t j = 0; j < terms.size(); ++j) {
        if (!terms[j].sine) bound += envelope[j] * std::exp(-terms[j].sigma * tau);
        value += amplitude[static_cast<Eigen::Index>(j)] * basis(tau, static_cast<Eigen::Index>(j));
      }
      if (std::abs(value) > band) return false;
      if (bound <= band) break;
      if (s == kMaxSteps) return false;  // too slow a decay to show within the horizon
    }
  }
  return true;
}

}  // namespace

double CalcSettlingTime(const Measurement& exact, double after_s, double band_fraction,
                        const std::map<std::string, double>& bands, double hold_s,
                        const std::vector<double>& frequencies_hz,
                        const std::vector<double>& decay_rates_per_s) {
  const Eigen::VectorXd t = exact.CalcTime();
  Eigen::Index first = 0;
  while (first < t.size() && t[first] < after_s - 1e-12) ++first;
  if (first >= t.size()) return kNaN;
  Eigen::Index last_outside = -1;
  std::vector<double> channel_bands;
  for (int c = 0; c < exact.channel_count(); ++c) {
    const auto y = exact.values.col(c).tail(t.size() - first);
    const auto given = bands.find(exact.channels[static_cast<size_t>(c)]);
    const double band =
        given != bands.end() ? given->second : band_fraction * y.cwiseAbs().maxCoeff();
    channel_bands.push_back(band);
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
  if (!ModesStayInside(t, first, last_outside + 1, exact.values, channel_bands, frequencies_hz,
                       decay_rates_per_s)) {
    return kInf;
  }
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
    std::vector<SizingPoint> points;
    JointSizing sizing = ReadCurves(spec, joint, rows, &damping, &points);
    const SizingEvaluator evaluate(campaign, spec, joint);
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
  // A target not given is NaN (0 would read as a target of 0).
  file.WriteDoubleAttribute(root, "min_damping_ratio",
                            spec.min_damping_ratio > 0 ? spec.min_damping_ratio : kNaN);
  file.WriteDoubleAttribute(root, "max_settling_time_s",
                            spec.has_settling_target() ? spec.max_settling_time_s : kNaN);
  // The band that applied: a fraction of each output's peak, or a band per channel in its unit.
  file.WriteDoubleAttribute(root, "settling_band_fraction",
                            spec.has_settling_target() && spec.settling_bands.empty()
                                ? spec.settling_band_fraction
                                : kNaN);
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
