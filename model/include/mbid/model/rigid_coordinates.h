#pragma once

#include <string>
#include <vector>

#include "mbid/model/machine_description.h"
#include "mbid/model/multibody_model.h"

namespace mbid::model {

// A machine with some of its coordinates made rigid: the structural hypothesis "this joint does
// not move" (the paper's sub-problem 4, which degrees of freedom the machine really has).
//
// Each rigid coordinate's degree of freedom leaves its joint, at the joint's rest pose (q = 0):
// a revolute or prismatic joint becomes a weld with the same frames; a universal joint keeps its
// other axis as a revolute joint (the second axis, when the first is rigid, seen in the joint
// frame at q1 = 0), and becomes a weld when both are. The coordinate's spring and damper go with
// it (its c_ and d_ parameters are no longer the model's), the other springs keep their values
// and the preload rule holds the unloaded machine at q = 0 as before. Outputs keep their meaning:
// an output of type coordinate naming a rigid coordinate reads 0; the rigid model also gets an
// output of that type under the coordinate's own name (unless an output has the name), so a
// record channel that measured the joint directly stays comparable.
//
// Throws InputError (source "machine description") for a name that is not a coordinate of
// `machine` or is given twice.
MachineDescription MakeCoordinatesRigid(const MachineDescription& machine,
                                        const std::vector<std::string>& rigid);

// The same for a built model: its description (for `type: truck_crane`, the crane's description,
// truck_crane_description.h) with the coordinates made rigid and the model's current spring
// values, built again under the same type().
MultibodyModel MakeCoordinatesRigid(const MultibodyModel& model,
                                    const std::vector<std::string>& rigid);

// The coordinates with a spring (the compliant ones), in the order of q.
std::vector<std::string> CompliantCoordinates(const MachineDescription& machine);

}  // namespace mbid::model
