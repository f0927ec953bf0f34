#include "mbid/updating/settings.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <thread>
#include <tuple>
#include <utility>

#include "mbid/simulation/scenario_sections.h"

namespace mbid::updating {
namespace {

// Local fits of the global search in parallel: its result does not depend on the count.
int DefaultSearchThreads() {
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

std::vector<std::string> ParameterNames(const model::MechanicalModel& model) {
  std::vector<std::string> names;
  for (const model::Parameter& parameter : model.parameters()) names.push_back(parameter.name);
  return names;
}

ParameterSetting* FindSetting(UpdateOptions& options, const std::string& name) {
  for (ParameterSetting& setting : options.parameters) {
    if (setting.name == name) return &setting;
  }
  return nullptr;
}

// A map parameter -> value whose names must be tuned parameters.
void CheckParameterKeys(const YamlReader& node, const UpdateOptions& options) {
  std::vector<std::string> tuned;
  for (const ParameterSetting& setting : options.parameters) tuned.push_back(setting.name);
  for (const std::string& key : node.Keys()) {
    if (std::find(tuned.begin(), tuned.end(), key) == tuned.end()) {
      node.FailAt(key, "'" + key + "' is not among the tuned parameters",
                  "one of updating.parameters; did you mean '" + ClosestMatch(key, tuned) + "'?");
    }
  }
}

simulation::SensitivityOptions ReadSensitivity(const YamlReader& node,
                                               simulation::SensitivityOptions o) {
  using simulation::SensitivityOptions;
  node.ExpectMap({"right_hand_side", "corrector", "difference_quotient", "relative_tolerance",
                  "absolute_tolerance", "error_control"});
  // The scenario's name of each right-hand side, once for both directions.
  using RightHandSide = SensitivityOptions::RightHandSide;
  const std::vector<std::pair<std::string, RightHandSide>> right_hand_sides{
      {"auto", RightHandSide::kAuto},
      {"quotients", RightHandSide::kCvodesQuotients},
      {"state_jacobian", RightHandSide::kStateJacobian}};
  std::vector<std::string> names;
  std::string current;
  for (const auto& [name, value] : right_hand_sides) {
    names.push_back(name);
    if (value == o.right_hand_side) current = name;
  }
  const std::string rhs = node.Choice("right_hand_side", names, current);
  for (const auto& [name, value] : right_hand_sides) {
    if (name == rhs) o.right_hand_side = value;
  }
  const bool staggered = o.corrector == SensitivityOptions::Corrector::kStaggered;
  o.corrector = node.Choice("corrector", {"simultaneous", "staggered"},
                            staggered ? "staggered" : "simultaneous") == "staggered"
                    ? SensitivityOptions::Corrector::kStaggered
                    : SensitivityOptions::Corrector::kSimultaneous;
  const bool forward = o.difference_quotient == SensitivityOptions::DifferenceQuotient::kForward;
  o.difference_quotient = node.Choice("difference_quotient", {"centered", "forward"},
                                      forward ? "forward" : "centered") == "forward"
                              ? SensitivityOptions::DifferenceQuotient::kForward
                              : SensitivityOptions::DifferenceQuotient::kCentered;
  o.relative_tolerance = node.PositiveDouble("relative_tolerance", o.relative_tolerance);
  o.absolute_tolerance = node.PositiveDouble("absolute_tolerance", o.absolute_tolerance);
  o.error_control = node.Bool("error_control", o.error_control);
  std::string why;
  if (!o.IsValid(&why)) node.Fail(why, "valid sensitivity options (docs/scenarios.md)");
  return o;
}

std::uint64_t ReadSeed(const YamlReader& node, std::uint64_t fallback) {
  const int seed = node.Seed("seed", static_cast<int>(fallback));
  return static_cast<std::uint64_t>(seed);
}

CharacteristicOptions ReadAlgebraic(const YamlReader& node, CharacteristicOptions o) {
  node.ExpectMap({"starts", "seed", "start_spread", "max_iterations", "residual_tolerance",
                  "duplicate_tolerance", "fit_offset", "ambiguity_ratio", "shape_significance"});
  o.starts = node.Int("starts", o.starts);
  o.seed = ReadSeed(node, o.seed);
  o.start_spread = node.PositiveDouble("start_spread", o.start_spread);
  o.max_iterations = node.Int("max_iterations", o.max_iterations);
  o.residual_tolerance = node.PositiveDouble("residual_tolerance", o.residual_tolerance);
  o.duplicate_tolerance = node.PositiveDouble("duplicate_tolerance", o.duplicate_tolerance);
  o.fit_offset = node.Bool("fit_offset", o.fit_offset);
  o.ambiguity_ratio = node.PositiveDouble("ambiguity_ratio", o.ambiguity_ratio);
  o.shape_significance = node.PositiveDouble("shape_significance", o.shape_significance);
  std::string why;
  if (!o.IsValid(&why)) node.Fail(why, "valid algebraic options (docs/scenarios.md)");
  return o;
}

GlobalSearchOptions ReadGlobalSearch(const YamlReader& node, GlobalSearchOptions o) {
  node.ExpectMap({"enabled", "design_starts", "seed", "screen_fraction", "screen_iterations",
                  "screen_relative_tolerance", "full_fits", "cluster_tolerance", "significance",
                  "threads", "pole_equivalent_starts"});
  o.pole_equivalent_starts = node.Bool("pole_equivalent_starts", o.pole_equivalent_starts);
  o.enabled = node.Bool("enabled", o.enabled);
  o.design_starts = node.Int("design_starts", o.design_starts);
  o.seed = ReadSeed(node, o.seed);
  o.screen_fraction = node.PositiveDouble("screen_fraction", o.screen_fraction);
  o.screen_iterations = node.Int("screen_iterations", o.screen_iterations);
  o.screen_relative_tolerance =
      node.PositiveDouble("screen_relative_tolerance", o.screen_relative_tolerance);
  o.full_fits = node.Int("full_fits", o.full_fits);
  o.cluster_tolerance = node.PositiveDouble("cluster_tolerance", o.cluster_tolerance);
  o.significance = node.PositiveDouble("significance", o.significance);
  const int threads = node.Int("threads", 0);
  if (threads < 0) node.FailAt("threads", "negative thread count", "0 (hardware) or more");
  o.threads = threads > 0 ? threads : DefaultSearchThreads();
  std::string why;
  if (!o.IsValid(&why)) node.Fail(why, "valid global search options (docs/scenarios.md)");
  return o;
}

ProfileOptions ReadProfile(const YamlReader& node, ProfileOptions o) {
  node.ExpectMap({"enabled", "sigmas", "max_fits_per_side", "max_iterations", "tolerance"});
  o.enabled = node.Bool("enabled", o.enabled);
  o.sigmas = node.PositiveDouble("sigmas", o.sigmas);
  o.max_fits_per_side = node.Int("max_fits_per_side", o.max_fits_per_side);
  o.max_iterations = node.Int("max_iterations", o.max_iterations);
  o.tolerance = node.PositiveDouble("tolerance", o.tolerance);
  std::string why;
  if (!o.IsValid(&why)) node.Fail(why, "valid profile options (docs/scenarios.md)");
  return o;
}

}  // namespace

UpdatingSettings MakeDefaultUpdatingSettings(const model::MechanicalModel& model,
                                             const simulation::IntegratorOptions& integrator) {
  UpdatingSettings settings;
  for (const std::string& name : ParameterNames(model)) {
    ParameterSetting setting;
    setting.name = name;
    settings.options.parameters.push_back(setting);
  }
  settings.options.integrator = integrator;
  settings.options.integrator.interpolate_outputs = true;
  settings.global_search.threads = DefaultSearchThreads();
  settings.profile.threads = settings.global_search.threads;
  return settings;
}

UpdatingSettings ReadUpdatingSettings(const YamlReader& node, const model::MechanicalModel& model,
                                      const simulation::IntegratorOptions& integrator) {
  UpdatingSettings settings = MakeDefaultUpdatingSettings(model, integrator);
  std::vector<std::string> keys{"parameters",
                                "start",
                                "bounds",
                                "log_scale",
                                "algebraic_start",
                                "jacobian",
                                "numeric_step",
                                "fit_payload_mass",
                                "fit_initial_deflection",
                                "fit_offsets",
                                "fit_drift",
                                "max_iterations",
                                "function_tolerance",
                                "gradient_tolerance",
                                "parameter_tolerance",
                                "undetermined_relative_std",
                                "rank_tolerance",
                                "max_chi_square_per_dof",
                                "whiteness_lags",
                                "threads",
                                "initial_trust_region_radius",
                                "speculative_jacobians",
                                "continuation_fractions",
                                "integrator",
                                "sensitivity",
                                "global_search",
                                "profile",
                                "algebraic"};
  // Residual weights in each channel's unit: noise_std_rad, noise_std_mps2, ...
  for (const std::string& key : simulation::UnitKeys("noise_std")) keys.push_back(key);
  node.ExpectMap(keys);
  UpdateOptions& options = settings.options;
  const std::vector<std::string> known = ParameterNames(model);
  if (node.Has("parameters")) {
    const std::vector<std::string> names = node.StringList("parameters");
    if (names.empty()) node.FailAt("parameters", "no parameter", "at least one parameter name");
    options.parameters.clear();
    for (const std::string& name : names) {
      if (std::find(known.begin(), known.end(), name) == known.end()) {
        node.FailAt("parameters", "unknown parameter '" + name + "'",
                    "parameters of the model (c_<joint>, d_<joint>); did you mean '" +
                        ClosestMatch(name, known) + "'?");
      }
      if (FindSetting(options, name) != nullptr) {
        node.FailAt("parameters", "'" + name + "' listed twice", "each parameter once");
      }
      ParameterSetting setting;
      setting.name = name;
      options.parameters.push_back(setting);
    }
  }
  const bool log_scale = node.Bool("log_scale", true);
  for (ParameterSetting& setting : options.parameters) setting.log_scale = log_scale;
  if (node.Has("start")) {
    const YamlReader start = node.Child("start");
    CheckParameterKeys(start, options);
    for (const std::string& name : start.Keys()) {
      const double value = log_scale ? start.PositiveDouble(name) : start.Double(name);
      FindSetting(options, name)->initial = value;
    }
  }
  if (node.Has("bounds")) {
    const YamlReader bounds = node.Child("bounds");
    CheckParameterKeys(bounds, options);
    for (const std::string& name : bounds.Keys()) {
      const YamlReader pair = bounds.Child(name);
      const std::string expected = "a list [lower, upper] with lower < upper";
      if (!pair.node().IsSequence() || pair.node().size() != 2) {
        pair.Fail("is not a list of two numbers", expected);
      }
      const double lower =
          YamlReader(pair.node()[0], pair.source(), pair.field() + "[0]").AsDouble();
      const double upper =
          YamlReader(pair.node()[1], pair.source(), pair.field() + "[1]").AsDouble();
      if (!(lower < upper) || (log_scale && !(lower > 0))) {
        pair.Fail("bounds [" + std::to_string(lower) + ", " + std::to_string(upper) + "]",
                  expected + (log_scale ? ", lower > 0 on the log scale" : ""));
      }
      ParameterSetting* setting = FindSetting(options, name);
      setting->lower = lower;
      setting->upper = upper;
      if (!std::isnan(setting->initial) &&
          !(lower <= setting->initial && setting->initial <= upper)) {
        pair.Fail("does not contain the start " + std::to_string(setting->initial),
                  "bounds around updating.start." + name);
      }
    }
  }
  settings.algebraic_start = node.Bool("algebraic_start", settings.algebraic_start);
  options.jacobian =
      node.Choice("jacobian", {"sensitivities", "numeric"}, "sensitivities") == "numeric"
          ? UpdateOptions::Jacobian::kNumeric
          : UpdateOptions::Jacobian::kSensitivities;
  options.numeric_step = node.PositiveDouble("numeric_step", options.numeric_step);
  std::vector<std::string> channels = model.output_names();
  channels.insert(channels.end(), model.coordinate_names().begin(), model.coordinate_names().end());
  for (const auto& [channel, value] :
       simulation::ReadPerUnitChannelValues(node, "noise_std", channels, model, true)) {
    if (!(value > 0)) {
      node.Fail("noise std of '" + channel + "' is 0", "a positive residual weight per channel");
    }
    settings.noise_std[channel] = value;
  }
  settings.fit_payload_mass = node.Bool("fit_payload_mass", false);
  settings.fit_initial_deflection = node.Bool("fit_initial_deflection", false);
  const std::string offsets = node.Choice("fit_offsets", {"auto", "true", "false"}, "auto");
  settings.fit_offsets = offsets == "auto"   ? UpdatingSettings::Offsets::kAuto
                         : offsets == "true" ? UpdatingSettings::Offsets::kAlways
                                             : UpdatingSettings::Offsets::kNever;
  settings.fit_drift = node.Bool("fit_drift", false);
  if (settings.fit_drift && settings.fit_offsets == UpdatingSettings::Offsets::kNever) {
    node.FailAt("fit_drift", "a drift with fit_offsets: false",
                "fit_offsets auto or true with fit_drift (a drift comes with an offset)");
  }
  options.max_iterations = node.Int("max_iterations", options.max_iterations);
  options.function_tolerance =
      node.PositiveDouble("function_tolerance", options.function_tolerance);
  options.gradient_tolerance =
      node.PositiveDouble("gradient_tolerance", options.gradient_tolerance);
  options.parameter_tolerance =
      node.PositiveDouble("parameter_tolerance", options.parameter_tolerance);
  options.undetermined_relative_std =
      node.PositiveDouble("undetermined_relative_std", options.undetermined_relative_std);
  options.rank_tolerance = node.PositiveDouble("rank_tolerance", options.rank_tolerance);
  options.max_chi_square_per_dof =
      node.PositiveDouble("max_chi_square_per_dof", options.max_chi_square_per_dof);
  options.whiteness_lags = node.Int("whiteness_lags", options.whiteness_lags);
  options.threads = node.Int("threads", options.threads);
  options.speculative_jacobians = node.Bool("speculative_jacobians", options.speculative_jacobians);
  options.initial_trust_region_radius =
      node.PositiveDouble("initial_trust_region_radius", options.initial_trust_region_radius);
  // A radius the file gives holds for every start, Route 1's too.
  if (node.Has("initial_trust_region_radius")) {
    settings.global_search.matched_trust_region_radius = options.initial_trust_region_radius;
  }
  if (node.Has("continuation_fractions")) {
    const YamlReader list = node.Child("continuation_fractions");
    if (!list.node().IsSequence()) {
      list.Fail("is not a list", "a list of ascending fractions in (0, 1), e.g. [0.25, 0.5]");
    }
    for (size_t i = 0; i < list.node().size(); ++i) {
      options.continuation_fractions.push_back(
          YamlReader(list.node()[i], list.source(), list.field() + "[" + std::to_string(i) + "]")
              .AsDouble());
    }
  }
  if (node.Has("integrator")) {
    options.integrator =
        simulation::ReadIntegratorOptions(node.Child("integrator"), options.integrator);
  }
  if (node.Has("sensitivity")) {
    options.sensitivity = ReadSensitivity(node.Child("sensitivity"), options.sensitivity);
  }
  if (node.Has("global_search")) {
    settings.global_search = ReadGlobalSearch(node.Child("global_search"), settings.global_search);
  }
  if (node.Has("profile")) settings.profile = ReadProfile(node.Child("profile"), settings.profile);
  // The profile's sides run on the search's workers (its bits do not depend on their count).
  settings.profile.threads = settings.global_search.threads;
  if (node.Has("algebraic")) {
    settings.algebraic = ReadAlgebraic(node.Child("algebraic"), settings.algebraic);
  }
  std::string why;
  if (!options.IsValid(&why)) node.Fail(why, "valid updating options (docs/scenarios.md)");
  return settings;
}

bool ApplyAlgebraicStart(const CharacteristicResult& algebraic, UpdateOptions& options,
                         std::string* why) {
  auto fail = [why](const std::string& reason) {
    if (why != nullptr) *why = reason;
    return false;
  };
  if (algebraic.status != CharacteristicResult::Status::kSolved || algebraic.chosen < 0) {
    return fail("Route 1 found no admissible set (" + algebraic.status_name() + ")");
  }
  const CharacteristicSolution& set = algebraic.solutions[static_cast<size_t>(algebraic.chosen)];
  UpdateOptions changed = options;
  int applied = 0;
  const auto reference = [](const Eigen::VectorXd& values, Eigen::Index k) {
    return k < values.size() ? values[k] : std::numeric_limits<double>::quiet_NaN();
  };
  for (size_t i = 0; i < algebraic.coordinates.size(); ++i) {
    const Eigen::Index k = static_cast<Eigen::Index>(i);
    for (const auto& [name, value, model_value] :
         {std::tuple<std::string, double, double>{"c_" + algebraic.coordinates[i], set.c[k],
                                                  reference(algebraic.c_reference, k)},
          std::tuple<std::string, double, double>{"d_" + algebraic.coordinates[i], set.d[k],
                                                  reference(algebraic.d_reference, k)}}) {
      ParameterSetting* setting = FindSetting(changed, name);
      if (setting == nullptr || !std::isnan(setting->initial)) continue;
      if ((!std::isnan(setting->lower) && value < setting->lower) ||
          (!std::isnan(setting->upper) && value > setting->upper) ||
          (setting->log_scale && !(value > 0))) {
        std::ostringstream reason;
        reason << "Route 1's " << name << " = " << value << " lies outside its bounds";
        return fail(reason.str());
      }
      setting->initial = value;
      // The default bounds (two decades either side of the start) hold the model's own value
      // too: poles that missed a stiff joint's mode gave c_tilt 2.8e5 for a scenario's 1.4e9
      // (truth 1e9), and the fit stopped at the bound, "does not explain the records".
      if (value > 0 && model_value > 0) {
        if (std::isnan(setting->lower)) setting->lower = std::min(value, model_value) / 100;
        if (std::isnan(setting->upper)) setting->upper = std::max(value, model_value) * 100;
      }
      ++applied;
    }
  }
  if (applied == 0) return fail("every tuned parameter has an explicit start");
  options = changed;
  return true;
}

std::string AlgebraicStartLabel(size_t index) { return "route1 set " + std::to_string(index); }

std::vector<SearchStart> MakeAlgebraicStarts(const CharacteristicResult& algebraic,
                                             bool skip_chosen) {
  std::vector<SearchStart> starts;
  for (size_t s = 0; s < algebraic.solutions.size(); ++s) {
    const CharacteristicSolution& set = algebraic.solutions[s];
    if (!set.admissible || (skip_chosen && static_cast<int>(s) == algebraic.chosen)) continue;
    SearchStart start;
    start.label = AlgebraicStartLabel(s);
    start.matches_poles = true;
    for (size_t i = 0; i < algebraic.coordinates.size(); ++i) {
      const Eigen::Index k = static_cast<Eigen::Index>(i);
      start.values["c_" + algebraic.coordinates[i]] = set.c[k];
      start.values["d_" + algebraic.coordinates[i]] = set.d[k];
    }
    starts.push_back(start);
  }
  return starts;
}

std::vector<std::string> MarkAlgebraicAmbiguity(const CharacteristicResult& algebraic,
                                                UpdateResult& result, double relative_difference,
                                                const std::vector<std::string>& judged_starts) {
  std::vector<std::string> names;
  if (!algebraic.ambiguous || algebraic.chosen < 0) return names;
  const CharacteristicSolution& chosen = algebraic.solutions[static_cast<size_t>(algebraic.chosen)];
  for (int rival : algebraic.rivals) {
    const std::string label = AlgebraicStartLabel(static_cast<size_t>(rival));
    if (std::find(judged_starts.begin(), judged_starts.end(), label) != judged_starts.end()) {
      continue;
    }
    const CharacteristicSolution& other = algebraic.solutions[static_cast<size_t>(rival)];
    for (size_t i = 0; i < algebraic.coordinates.size(); ++i) {
      const Eigen::Index k = static_cast<Eigen::Index>(i);
      if (std::abs(other.c[k] / chosen.c[k] - 1) > relative_difference) {
        names.push_back("c_" + algebraic.coordinates[i]);
      }
      if (std::abs(other.d[k] / chosen.d[k] - 1) > relative_difference) {
        names.push_back("d_" + algebraic.coordinates[i]);
      }
    }
  }
  std::sort(names.begin(), names.end());
  names.erase(std::unique(names.begin(), names.end()), names.end());
  std::string list;
  for (const std::string& name : names) {
    list += (list.empty() ? "" : ", ") + name;
    for (ParameterEstimate& estimate : result.parameters) {
      if (estimate.name != name) continue;
      estimate.determined = false;
      estimate.rival_differs = true;
      if (estimate.why_undetermined.empty()) {
        estimate.why_undetermined =
            "Route 1 found another set of joint parameters that reproduces the test's initial "
            "state about as well but differs in it: the record does not decide between them";
      }
    }
    if (std::find(result.undetermined.begin(), result.undetermined.end(), name) ==
        result.undetermined.end()) {
      result.undetermined.push_back(name);
    }
  }
  if (!names.empty()) {
    result.warnings.push_back(
        "Route 1 found sets that reproduce the test's initial state about "
        "as well as the chosen one but differ in " +
        list + ": the record does not decide between them");
  }
  return names;
}

TestRecord MakeTestRecord(const std::string& name, const Measurement& record,
                          const simulation::Excitation& excitation,
                          const UpdatingSettings& settings) {
  TestRecord test;
  test.name = name;
  test.record = record;
  test.excitation = excitation;
  for (const std::string& channel : record.channels) {
    const auto found = settings.noise_std.find(channel);
    if (found != settings.noise_std.end()) test.noise_std[channel] = found->second;
  }
  test.fit_payload_mass =
      settings.fit_payload_mass && excitation.get_if<simulation::LoadDrop>() != nullptr;
  test.fit_initial_deflection = settings.fit_initial_deflection &&
                                excitation.get_if<simulation::InitialDeflection>() != nullptr;
  switch (settings.fit_offsets) {
    case UpdatingSettings::Offsets::kAuto:
      // mbid's own records (simulated, or synthetic modes) have no zero error unless a sensor
      // bias was asked for.
      test.fit_offsets = !record.made_by_mbid();
      break;
    case UpdatingSettings::Offsets::kAlways:
      test.fit_offsets = true;
      break;
    case UpdatingSettings::Offsets::kNever:
      test.fit_offsets = false;
      break;
  }
  test.fit_drift = settings.fit_drift && test.fit_offsets;
  return test;
}

}  // namespace mbid::updating
