#include "mbid/model/rigid_coordinates.h"

#include <algorithm>
#include <set>

#include "mbid/common/error.h"

namespace mbid::model {

MachineDescription MakeCoordinatesRigid(const MachineDescription& machine,
                                        const std::vector<std::string>& rigid) {
  const std::vector<std::string> coordinates = machine.coordinates();
  std::set<std::string> wanted;
  for (const std::string& name : rigid) {
    if (std::find(coordinates.begin(), coordinates.end(), name) == coordinates.end()) {
      std::string known;
      for (const std::string& c : coordinates) known += (known.empty() ? "" : ", ") + c;
      throw InputError("machine description", "rigid", "unknown coordinate '" + name + "'",
                       "one of " + (known.empty() ? std::string("(none)") : known));
    }
    if (!wanted.insert(name).second) {
      throw InputError("machine description", "rigid", "coordinate '" + name + "' twice",
                       "each rigid coordinate once");
    }
  }

  MachineDescription result = machine;
  for (BodyDescription& body : result.bodies) {
    JointDescription& joint = body.joint;
    std::vector<std::string> kept_coordinates;
    std::vector<Eigen::Vector3d> kept_axes;
    for (size_t k = 0; k < joint.coordinates.size(); ++k) {
      const std::string& name = joint.coordinates[k];
      if (wanted.count(name)) {
        result.rigid_coordinates.push_back({name, joint.type == JointType::kPrismatic});
        continue;
      }
      kept_coordinates.push_back(name);
      kept_axes.push_back(joint.axes[k]);
    }
    if (kept_coordinates.size() == joint.coordinates.size()) continue;
    // A universal joint's second axis is given in the frame turned by the first; with the first
    // rigid at q1 = 0 that frame is the joint frame itself, so the axis carries over unchanged.
    joint.type = kept_coordinates.empty()              ? JointType::kWeld
                 : joint.type == JointType::kPrismatic ? JointType::kPrismatic
                                                       : JointType::kRevolute;
    joint.coordinates = kept_coordinates;
    joint.axes = kept_axes;
  }
  result.springs.erase(std::remove_if(result.springs.begin(), result.springs.end(),
                                      [&](const SpringDescription& spring) {
                                        return wanted.count(spring.coordinate) > 0;
                                      }),
                       result.springs.end());
  for (const std::string& name : rigid) {
    const bool named = std::any_of(result.outputs.begin(), result.outputs.end(),
                                   [&](const OutputDescription& o) { return o.name == name; });
    if (named) continue;
    OutputDescription output;
    output.name = name;
    output.type = OutputType::kCoordinate;
    output.coordinate = name;
    result.outputs.push_back(output);
  }
  return result;
}

MultibodyModel MakeCoordinatesRigid(const MultibodyModel& model,
                                    const std::vector<std::string>& rigid) {
  return MultibodyModel(MakeCoordinatesRigid(model.description(), rigid), model.type());
}

std::vector<std::string> CompliantCoordinates(const MachineDescription& machine) {
  std::vector<std::string> compliant;
  for (const std::string& name : machine.coordinates()) {
    if (machine.FindSpring(name) != nullptr) compliant.push_back(name);
  }
  return compliant;
}

}  // namespace mbid::model
