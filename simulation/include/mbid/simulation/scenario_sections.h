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
// Per-channel values whose keys say their unit: `<base>_rad`, `_m`, `_mps`, `_mps2`, `_radps`
// for channels in rad, m, m/s, m/s^2, rad/s (outputs and coordinates of `model`; an output
// wins over a coordinate of the same name). A number applies to every channel of that unit, a
// map names channels of it. `UnitKeys(base)` lists the keys for ExpectMap.
std::map<std::string, double> ReadPerUnitChannelValues(const YamlReader& node,
                                                       const std::string& base,
                                                       const std::vector<std::string>& channels,
                                                       const model::MechanicalModel& model,
                                                       bool non_negative);
std::vector<std::string> UnitKeys(const std::string& base);
// The unit of every name a channel may have: the model's outputs and coordinates (an output wins
// over a coordinate of the same name, as in the channel lookup).
std::map<std::string, std::string> ChannelUnits(const model::MechanicalModel& model);
SimulationOptions ReadSimulationOptions(const YamlReader& simulation);
// An `integrator:` block; keys it leaves out keep their values in `defaults`.
IntegratorOptions ReadIntegratorOptions(const YamlReader& integrator, IntegratorOptions defaults);
SensorOptions ReadSensorOptions(const YamlReader& sensors, const model::MechanicalModel& model);
// The channels of a scenario that lists none (or has no `sensors:`): the model's outputs, or its
// coordinates when it has no outputs.
std::vector<std::string> DefaultChannels(const model::MechanicalModel& model);

}  // namespace mbid::simulation
