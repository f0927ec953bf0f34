#pragma once

#include <Eigen/Core>
#include <string>

#include "mbid/model/mechanical_model.h"

namespace mbid {
class YamlReader;
}  // namespace mbid

namespace mbid::simulation {

// Where a forcing excitation (impulse, burst) acts: either a force at a load point (N, ground
// frame) or a torque on a coordinate (N*m); the other half stays empty.
struct ForceTarget {
  std::string point;
  Eigen::Vector3d force_N = Eigen::Vector3d::Zero();
  std::string coordinate;
  double torque_Nm = 0.0;

  // `point` + `force_N` or `coordinate` + `torque_Nm` of an excitation's map, names checked
  // against `model`.
  static ForceTarget Read(const YamlReader& node, const model::MechanicalModel& model);
};

}  // namespace mbid::simulation
