#include "mbid/simulation/excitations/force_target.h"

#include <array>

#include "mbid/common/yaml_reader.h"

namespace mbid::simulation {

ForceTarget ForceTarget::Read(const YamlReader& node, const model::MechanicalModel& model) {
  ForceTarget target;
  const bool has_point = node.Has("point") || node.Has("force_N");
  const bool has_torque = node.Has("coordinate") || node.Has("torque_Nm");
  if (has_point == has_torque) {
    node.Fail("needs exactly one target",
              "either point + force_N (a force in N, ground frame) or coordinate + torque_Nm");
  }
  if (has_point) {
    target.point = node.Choice("point", model.load_points(), model.load_points().front());
    const std::array<double, 3> f = node.Vector3("force_N");
    target.force_N = Eigen::Vector3d(f[0], f[1], f[2]);
    if (target.force_N.isZero(0.0)) node.FailAt("force_N", "zero force", "a non-zero force");
  } else {
    target.coordinate = node.Choice("coordinate", model.coordinate_names(), "");
    target.torque_Nm = node.Double("torque_Nm");
    if (target.torque_Nm == 0) node.FailAt("torque_Nm", "zero torque", "a non-zero torque");
  }
  return target;
}

}  // namespace mbid::simulation
