#include "mbid/validation/plan_candidates.h"

#include <fmt/format.h>

#include <cmath>
#include <set>

#include "mbid/common/error.h"
#include "mbid/common/json_io.h"
#include "mbid/common/yaml_reader.h"
#include "mbid/model/model_factory.h"
#include "mbid/simulation/scenario_sections.h"
#include "sample_count.h"

namespace mbid::validation {
namespace {

bool IsSensorEffectKey(const std::string& key) {
  for (const char* base : {"noise_std", "bias", "quantization_step"}) {
    for (const std::string& known : simulation::UnitKeys(base)) {
      if (key == known) return true;
    }
  }
  return false;
}

// The scenario's section `key` (or an empty map) with the candidate's over it.
YAML::Node MergedSection(const Scenario& scenario, const YamlReader& candidate,
                         const std::string& key, bool drop_sensor_effects) {
  YAML::Node base(YAML::NodeType::Map);
  if (scenario.root.Has(key)) base = YAML::Clone(scenario.root.Child(key).node());
  if (drop_sensor_effects && base.IsMap()) {
    YAML::Node kept(YAML::NodeType::Map);
    for (const auto& item : base) {
      const std::string name = item.first.as<std::string>();
      if (!IsSensorEffectKey(name)) kept[name] = item.second;
    }
    base = kept;
  }
  return MergeYaml(base, candidate.Child(key).node());
}

}  // namespace

YAML::Node MergeYaml(const YAML::Node& base, const YAML::Node& override) {
  if (!base.IsMap() || !override.IsMap()) return YAML::Clone(override);
  YAML::Node merged = YAML::Clone(base);
  for (const auto& item : override) {
    const std::string key = item.first.as<std::string>();
    const YAML::Node& mine = merged;  // const lookup does not insert
    merged[key] =
        mine[key].IsDefined() ? MergeYaml(mine[key], item.second) : YAML::Clone(item.second);
  }
  return merged;
}

CandidateFile ReadCandidateFile(const std::string& path, const Scenario& scenario,
                                const model::MechanicalModel& model) {
  const YamlReader root = YamlReader::FromFile(path);
  root.ExpectMap({"candidates"});
  const YamlReader list = root.Child("candidates");
  if (!list.node().IsSequence() || list.node().size() == 0) {
    list.Fail("not a non-empty list", "a list of candidate tests [{name, excitation, ...}]");
  }
  CandidateFile file;
  file.path = path;
  std::set<std::string> names;
  for (size_t i = 0; i < list.node().size(); ++i) {
    const YamlReader entry(list.node()[i], path, fmt::format("candidates[{}]", i));
    if (!entry.IsMap()) entry.Fail("not a map", "a map {name, excitation, ...}");
    entry.ExpectMap({"name", "excitation", "simulation", "sensors", "model"});
    updating::PlanCandidate candidate;
    candidate.name = entry.String("name");
    if (candidate.name.empty()) entry.FailAt("name", "''", "a non-empty name");
    if (!names.insert(candidate.name).second) {
      entry.FailAt("name", "'" + candidate.name + "' given twice", "unique candidate names");
    }
    const model::MechanicalModel* own = &model;
    if (entry.Has("model")) {
      // model.parameters is a free map: a misspelt name would be one more parameter nothing
      // uses, and the candidate the recorded test again (scored as such, without a word).
      const YamlReader overrides = entry.Child("model");
      if (overrides.IsMap() && overrides.Has("parameters") &&
          overrides.Child("parameters").IsMap()) {
        const YamlReader parameters = overrides.Child("parameters");
        for (const std::string& name : parameters.Keys()) {
          const std::string expected =
              ExpectDeclaredParameter(scenario.root.node(), name, "scenario");
          if (!expected.empty()) {
            parameters.FailAt(name, "'" + name + "' is not a parameter of the scenario's model",
                              expected);
          }
        }
      }
      const YamlReader merged(MergedSection(scenario, entry, "model", false), path,
                              entry.field() + ".model");
      candidate.model = model::MakeModel(merged);
      own = candidate.model.get();
    }
    candidate.test.name = candidate.name;
    candidate.test.excitation = simulation::ReadExcitation(entry.Child("excitation"), *own);
    candidate.test.simulation = scenario.simulation;
    if (entry.Has("simulation")) {
      candidate.test.simulation = simulation::ReadSimulationOptions(
          YamlReader(MergedSection(scenario, entry, "simulation", false), path,
                     entry.field() + ".simulation"));
    }
    std::vector<std::string> own_noise;
    if (entry.Has("sensors")) {
      candidate.test.sensors =
          simulation::ReadSensorOptions(YamlReader(MergedSection(scenario, entry, "sensors", true),
                                                   path, entry.field() + ".sensors"),
                                        *own);
      for (const auto& [channel, value] : candidate.test.sensors.noise_std) {
        // A noiseless sensor would tell everything exactly; 0 is no level to plan with.
        if (!(value > 0)) {
          throw InputError(path, entry.field() + ".sensors",
                           fmt::format("a noise level of {} for '{}'", value, channel),
                           "a positive noise standard deviation (or none: the recorded tests' "
                           "or the scenario's)");
        }
        own_noise.push_back(channel);
      }
    } else {
      candidate.test.sensors = scenario.sensors;
    }
    // Only the candidate's own noise until FillCandidateNoise; no sensor effects otherwise.
    std::map<std::string, double> noise;
    for (const std::string& channel : own_noise) {
      noise[channel] = candidate.test.sensors.noise_std.at(channel);
    }
    candidate.test.sensors.noise_std = noise;
    candidate.test.sensors.bias.clear();
    candidate.test.sensors.quantization_step.clear();
    internal::CheckSampleCount(
        path, entry.field() + ".simulation.duration_s, sensors.sample_rate_hz",
        candidate.test.simulation.duration_s, candidate.test.sensors.sample_rate_hz);
    file.candidates.push_back(std::move(candidate));
    file.own_noise.push_back(own_noise);
  }
  return file;
}

void FillCandidateNoise(CandidateFile& file, const std::map<std::string, double>& recorded,
                        const std::map<std::string, double>& scenario_noise) {
  for (size_t i = 0; i < file.candidates.size(); ++i) {
    updating::TestDesign& test = file.candidates[i].test;
    for (const std::string& channel : test.sensors.channels) {
      if (test.sensors.noise_std.count(channel) > 0) continue;
      const auto from_records = recorded.find(channel);
      const auto from_scenario = scenario_noise.find(channel);
      if (from_records != recorded.end() && from_records->second > 0) {
        test.sensors.noise_std[channel] = from_records->second;
      } else if (from_scenario != scenario_noise.end() && from_scenario->second > 0) {
        test.sensors.noise_std[channel] = from_scenario->second;
      } else {
        throw InputError(file.path, fmt::format("candidates[{}].sensors", i),
                         "no noise level for channel '" + channel +
                             "' (not in the recorded tests, none in the scenario's sensors)",
                         "sensors.noise_std_rad (or the channel unit's key) for the channel");
      }
    }
  }
}

nlohmann::json PerParameterJson(const std::vector<std::string>& names,
                                const Eigen::VectorXd& values) {
  nlohmann::json out = nlohmann::json::object();
  for (size_t k = 0; k < names.size(); ++k) {
    out[names[k]] = NumberOrNull(values[static_cast<Eigen::Index>(k)]);
  }
  return out;
}

nlohmann::json CandidateScoresToJson(
    const updating::TestPlan& plan, const CandidateFile& file,
    const updating::AlternativesPlan& at_alternatives,
    const std::vector<updating::AlternativeMinimumValues>& alternatives) {
  nlohmann::json candidates = nlohmann::json::array();
  for (const updating::CandidateScore& candidate : plan.candidates) {
    nlohmann::json item;
    item["name"] = candidate.name;
    item["score"] = NumberOrNull(candidate.score);
    item["gain"] = NumberOrNull(candidate.gain);
    item["expected_relative_std"] = PerParameterJson(plan.parameters, candidate.relative_std);
    nlohmann::json determined = nlohmann::json::object();
    for (size_t k = 0; k < plan.parameters.size(); ++k) {
      determined[plan.parameters[k]] = static_cast<bool>(candidate.determined[k]);
    }
    item["determined"] = determined;
    item["unseen"] = candidate.unseen;  // its channels do not see their modes
    item["moves_nothing"] = candidate.moves_nothing;
    item["rank"] = candidate.rank;
    item["ridge"] = NumberOrNull(candidate.ridge);
    for (size_t i = 0; i < file.candidates.size(); ++i) {
      if (file.candidates[i].name != candidate.name) continue;
      nlohmann::json noise = nlohmann::json::object();
      for (const auto& [channel, value] : file.candidates[i].test.sensors.noise_std) {
        noise[channel] = value;
      }
      item["noise_std"] = noise;
    }
    for (const updating::CandidateAtAlternatives& entry : at_alternatives.candidates) {
      if (entry.name != candidate.name) continue;
      item["worst_score"] = NumberOrNull(entry.worst_score);
      nlohmann::json list = nlohmann::json::array();
      for (size_t a = 0; a < alternatives.size(); ++a) {
        list.push_back({{"alternative", alternatives[a].label},
                        {"score", NumberOrNull(entry.scores[a])},
                        {"separation_chi_square", NumberOrNull(entry.separation[a])},
                        {"cannot_separate", static_cast<bool>(entry.cannot_separate[a])}});
      }
      item["at_alternatives"] = list;
    }
    candidates.push_back(item);
  }
  return candidates;
}

}  // namespace mbid::validation
