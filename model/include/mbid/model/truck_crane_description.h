#pragma once

#include "mbid/model/machine_description.h"
#include "mbid/model/multibody_model.h"
#include "mbid/model/truck_crane_parameters.h"

namespace mbid::model {

// The truck crane of docs/reference-crane.md written as a machine description
// (docs/machine-description.md): base pitching about y at its pivot (alpha), slewing part
// yawing at the bearing (gamma), a massless frame yawing at the boom foot (eta), the boom
// luffing about -y (theta); outputs psi and phi, the boom axis' azimuth and elevation; the
// payload point at the boom tip. `type: truck_crane` expands to this.
MachineDescription DescribeTruckCrane(const TruckCraneParameters& parameters);

// The crane as a model: its description built, type() "truck_crane".
MultibodyModel MakeTruckCrane(const TruckCraneParameters& parameters);

}  // namespace mbid::model
