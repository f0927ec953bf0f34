#include "mbid/simulation/excitations/burst.h"

#include <cmath>

#include "mbid/common/yaml_reader.h"

namespace mbid::simulation {

Burst Burst::Read(const YamlReader& node, const model::MechanicalModel& model) {
  node.ExpectMap({"type", "point", "force_N", "coordinate", "torque_Nm", "frequency_hz", "cycles"});
  Burst burst;
  burst.target = ForceTarget::Read(node, model);
  burst.frequency_hz = node.PositiveDouble("frequency_hz");
  burst.cycles = node.Int("cycles");
  if (burst.cycles < 1) node.FailAt("cycles", "fewer than one cycle", "an integer >= 1");
  return burst;
}

Eigen::VectorXd Burst::CalcInitialCoordinates(const model::MechanicalModel& model) const {
  return Eigen::VectorXd::Zero(model.coordinate_count());
}

double Burst::CalcForcingFactor(double t) const { return std::sin(2 * M_PI * frequency_hz * t); }

}  // namespace mbid::simulation
