#pragma once

#include <memory>

#include "mbid/common/yaml_reader.h"
#include "mbid/model/mechanical_model.h"
#include "mbid/model/torsional_oscillator.h"
#include "mbid/model/truck_crane_parameters.h"

namespace mbid::model {

// The `model:` section of a scenario (docs/reference-crane.md, "Scenario keys"), read strictly.
TruckCraneParameters ReadTruckCraneParameters(const YamlReader& model);

// The `model:` section of a torsional oscillator: inertia_kgm2, joints.angle.{stiffness, damping}.
TorsionalOscillatorParameters ReadTorsionalOscillatorParameters(const YamlReader& model);

// The model named by `model.type`: `multibody` (docs/machine-description.md), `truck_crane`
// (a shorthand that expands to the crane's description) or `torsional_oscillator`; an unknown
// type is an InputError listing the known ones.
std::unique_ptr<MechanicalModel> MakeModel(const YamlReader& model);

}  // namespace mbid::model
