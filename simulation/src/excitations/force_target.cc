#include "mbid/simulation/excitations/force_target.h"

#include <array>
#include <string>

#include "mbid/common/yaml_reader.h"

namespace mbid::simulation {

ForceTarget ForceTarget::Read(const YamlReader& node, const model::MechanicalModel& model) {
  ForceTarget target;
  const bool has_coordinate = node.Has("coordinate") || node.Has("torque_Nm");
  const bool has_point = node.Has("point") || (node.Has("force_N") && !node.Has("coordinate"));
  if (has_point == has_coordinate) {
    node.Fail("needs exactly one target",
              "either point + force_N (a force in N, ground frame) or coordinate + torque_Nm "
              "(force_N for a prismatic coordinate)");
  }
  if (has_point) {
    target.point = node.Choice("point", model.load_points(), model.load_points().front());
    const std::array<double, 3> f = node.Vector3("force_N");
    target.force_N = Eigen::Vector3d(f[0], f[1], f[2]);
    if (target.force_N.isZero(0.0)) node.FailAt("force_N", "zero force", "a non-zero force");
  } else {
    target.coordinate = node.Choice("coordinate", model.coordinate_names(), "");
    // The generalized force has the coordinate's unit: a torque on a turning one, a force on a
    // sliding one.
    const bool slides = model.coordinate_unit(target.coordinate) == "m";
    const std::string key = slides ? "force_N" : "torque_Nm";
    const std::string other = slides ? "torque_Nm" : "force_N";
    if (node.Has(other)) {
      node.FailAt(other, "coordinate '" + target.coordinate + (slides ? "' slides" : "' turns"),
                  key + (slides ? " (its force in N)" : " (its torque in N*m)"));
    }
    target.torque_Nm = node.Double(key);
    if (target.torque_Nm == 0) node.FailAt(key, "zero " + key, "a non-zero generalized force");
  }
  return target;
}

}  // namespace mbid::simulation
