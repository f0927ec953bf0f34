#include "fit_unknowns.h"

#include <algorithm>
#include <map>
#include <sstream>

#include "mbid/common/error.h"
#include "mbid/common/yaml_reader.h"

namespace mbid::updating::internal {

std::vector<Unknown> ResolveUnknowns(const model::MechanicalModel& model,
                                     const std::vector<TestRecord>& tests,
                                     const UpdateOptions& options) {
  const std::vector<model::Parameter> available = model.parameters();
  std::vector<ParameterSetting> settings = options.parameters;
  if (settings.empty()) {
    for (const model::Parameter& parameter : available) settings.push_back({parameter.name});
  }
  std::vector<std::string> names;
  for (const model::Parameter& parameter : available) names.push_back(parameter.name);
  std::vector<Unknown> unknowns;
  for (const ParameterSetting& setting : settings) {
    const auto found = std::find_if(
        available.begin(), available.end(),
        [&](const model::Parameter& parameter) { return parameter.name == setting.name; });
    if (found == available.end()) {
      throw InputError(
          "updating", "parameters", "unknown parameter '" + setting.name + "'",
          "a parameter of the model; did you mean '" + ClosestMatch(setting.name, names) + "'?");
    }
    for (const Unknown& known : unknowns) {
      if (known.name == setting.name) {
        throw InputError("updating", "parameters", "'" + setting.name + "' listed twice",
                         "each parameter once");
      }
    }
    Unknown unknown;
    unknown.name = setting.name;
    unknown.units = found->units;
    unknown.log_scale = setting.log_scale;
    unknown.initial = std::isnan(setting.initial) ? found->value : setting.initial;
    unknown.lower =
        std::isnan(setting.lower) ? std::max(unknown.initial / 100, found->lower) : setting.lower;
    unknown.upper =
        std::isnan(setting.upper) ? std::min(unknown.initial * 100, found->upper) : setting.upper;
    unknowns.push_back(unknown);
  }
  for (size_t t = 0; t < tests.size(); ++t) {
    const TestRecord& test = tests[t];
    if (test.fit_payload_mass) {
      const auto* drop = test.excitation.get_if<simulation::LoadDrop>();
      if (drop == nullptr) {
        throw InputError(test.name, "fit_payload_mass", "the test is not a load drop",
                         "payload mass as a nuisance parameter of load-drop tests only");
      }
      Unknown unknown;
      unknown.kind = Unknown::Kind::kPayloadMass;
      unknown.name = test.name + ":payload_mass_kg";
      unknown.units = "kg";
      unknown.test = static_cast<int>(t);
      unknown.initial = drop->payload_mass_kg;
      unknown.lower = unknown.initial / 100;
      unknown.upper = unknown.initial * 100;
      unknowns.push_back(unknown);
    }
    if (test.fit_initial_deflection) {
      const auto* deflection = test.excitation.get_if<simulation::InitialDeflection>();
      if (deflection == nullptr) {
        throw InputError(test.name, "fit_initial_deflection",
                         "the test is not an initial deflection",
                         "initial deflections as nuisance parameters of initial_deflection "
                         "tests only");
      }
      // The test's largest deflection of each unit (rad, m): the scale of each.
      std::map<std::string, double> largest;
      for (const auto& [coordinate, value] : deflection->deflection_rad) {
        const std::string unit = model.coordinate_unit(coordinate);
        double& at = largest[unit];
        at = std::max(at, std::abs(value));
      }
      for (const auto& [coordinate, value] : deflection->deflection_rad) {
        Unknown unknown;
        unknown.kind = Unknown::Kind::kDeflection;
        unknown.scale = largest[model.coordinate_unit(coordinate)];
        unknown.name = test.name + ":deflection_" + coordinate;
        // A prismatic coordinate's deflection is a length (excitation.deflection_m).
        const std::string unit = model.coordinate_unit(coordinate);
        unknown.units = unit.empty() ? "rad" : unit;
        unknown.test = static_cast<int>(t);
        unknown.coordinate = coordinate;
        unknown.log_scale = false;
        unknown.initial = value;
        const double span = std::max(10 * std::abs(value), 0.01);
        unknown.lower = value - span;
        unknown.upper = value + span;
        unknowns.push_back(unknown);
      }
    }
  }
  for (const Unknown& unknown : unknowns) {
    const bool positive = !unknown.log_scale || (unknown.lower > 0 && unknown.initial > 0);
    if (!(unknown.lower <= unknown.initial && unknown.initial <= unknown.upper) ||
        !(unknown.lower < unknown.upper) || !positive || !std::isfinite(unknown.lower) ||
        !std::isfinite(unknown.upper)) {
      throw InputError("updating", unknown.name,
                       "start " + FormatValue(unknown.initial) + " with bounds [" +
                           FormatValue(unknown.lower) + ", " + FormatValue(unknown.upper) + "]",
                       std::string("finite bounds lower < upper around the start") +
                           (unknown.log_scale ? ", all > 0 (log scale)" : ""));
    }
  }
  return unknowns;
}

void StartNuisanceAt(const UpdateResult& result, std::vector<TestRecord>& tests) {
  for (const ParameterEstimate& estimate : result.parameters) {
    if (estimate.test.empty()) continue;
    for (TestRecord& test : tests) {
      if (test.name != estimate.test) continue;
      const std::string prefix = test.name + ":deflection_";
      if (estimate.name == test.name + ":payload_mass_kg") {
        test.excitation.get<simulation::LoadDrop>().payload_mass_kg = estimate.value;
      } else if (estimate.name.compare(0, prefix.size(), prefix) == 0) {
        test.excitation.get<simulation::InitialDeflection>()
            .deflection_rad[estimate.name.substr(prefix.size())] = estimate.value;
      }
    }
  }
}

void WeighAs(const UpdateResult& result, std::vector<TestRecord>& tests) {
  for (size_t t = 0; t < tests.size() && t < result.tests.size(); ++t) {
    const TestFit& fit = result.tests[t];
    for (size_t c = 0; c < fit.channels.size(); ++c) {
      tests[t].noise_std.emplace(fit.channels[c], fit.noise_std[static_cast<Eigen::Index>(c)]);
    }
  }
}

}  // namespace mbid::updating::internal
