#pragma once

#include <map>
#include <string>
#include <vector>

#include "mbid/common/yaml_reader.h"
#include "mbid/model/mechanical_model.h"
#include "mbid/simulation/excitation.h"
#include "mbid/simulation/sensor.h"
#include "mbid/simulation/simulate.h"

namespace mbid::simulation {

// The scenario sections the simulation layer owns (docs/scenarios.md), read strictly; names of
// coordinates, load points and channels are checked against `model`.
Excitation ReadExcitation(const YamlReader& excitation, const model::MechanicalModel& model);
// `key` of `node` as one number for every channel or a map channel -> value (channels checked);
// absent: empty. With `non_negative`, a negative value is an error.
std::map<std::string, double> ReadChannelValues(const YamlReader& node, const std::string& key,
                                                const std::vector<std::string>& channels,
                                                bool non_negative);
SimulationOptions ReadSimulationOptions(const YamlReader& simulation);
// An `integrator:` block; keys it leaves out keep their values in `defaults`.
IntegratorOptions ReadIntegratorOptions(const YamlReader& integrator, IntegratorOptions defaults);
SensorOptions ReadSensorOptions(const YamlReader& sensors, const model::MechanicalModel& model);

}  // namespace mbid::simulation
