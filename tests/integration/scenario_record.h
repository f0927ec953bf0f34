// A scenario's model and its simulated record at a noise seed of the test's choosing: the
// cases of a campaign sweep, rebuilt one by one.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

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

}  // namespace mbid::testing
