// A scenario's model and its simulated record at a noise seed of the test's choosing: the
// cases of a campaign sweep, rebuilt one by one.
#pragma once

#include <cstdint>
#include <fstream>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "mbid/common/yaml_reader.h"
#include "mbid/model/model_factory.h"
#include "mbid/simulation/scenario_sections.h"
#include "mbid/simulation/simulate.h"

namespace mbid::testing {

struct ScenarioRecord {
  std::unique_ptr<model::MechanicalModel> model;
  simulation::SimulationResult record;
};

inline ScenarioRecord SimulateScenario(const YamlReader& root, std::uint64_t seed) {
  ScenarioRecord out;
  out.model = model::MakeModel(root.Child("model"));
  simulation::SensorOptions sensors =
      simulation::ReadSensorOptions(root.Child("sensors"), *out.model);
  sensors.seed = seed;
  out.record =
      Simulate(*out.model, simulation::ReadExcitation(root.Child("excitation"), *out.model),
               simulation::ReadSimulationOptions(root.Child("simulation")), sensors);
  return out;
}

// The text of scenarios/<name> with `from` replaced by `to` (empty `from`: as shipped); throws
// if `from` is not in it, so that a changed scenario fails the test rather than passing it.
inline std::string ShippedScenarioText(const std::string& name, const std::string& from = "",
                                       const std::string& to = "") {
  std::ifstream file(std::string(MBID_SOURCE_DIR) + "/scenarios/" + name);
  std::stringstream text;
  text << file.rdbuf();
  std::string scenario = text.str();
  if (from.empty()) return scenario;
  const size_t at = scenario.find(from);
  if (at == std::string::npos) throw std::runtime_error(name + " has no '" + from + "'");
  return scenario.replace(at, from.size(), to);
}

// Whether one of `lines` (warnings, reasons) contains `what`.
inline bool Mentions(const std::vector<std::string>& lines, const std::string& what) {
  for (const std::string& line : lines) {
    if (line.find(what) != std::string::npos) return true;
  }
  return false;
}

}  // namespace mbid::testing
