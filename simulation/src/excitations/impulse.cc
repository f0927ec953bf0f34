#include "mbid/simulation/excitations/impulse.h"

#include <cmath>

#include "mbid/common/yaml_reader.h"

namespace mbid::simulation {

Impulse Impulse::Read(const YamlReader& node, const model::MechanicalModel& model) {
  node.ExpectMap({"type", "point", "force_N", "coordinate", "torque_Nm", "duration_s", "shape"});
  Impulse impulse;
  impulse.target = ForceTarget::Read(node, model);
  impulse.duration_s = node.PositiveDouble("duration_s");
  impulse.pulse_shape =
      node.Choice("shape", {"half_sine", "rectangular"}, "half_sine") == "rectangular"
          ? PulseShape::kRectangular
          : PulseShape::kHalfSine;
  return impulse;
}

Eigen::VectorXd Impulse::CalcInitialCoordinates(const model::MechanicalModel& model) const {
  return Eigen::VectorXd::Zero(model.coordinate_count());
}

double Impulse::CalcForcingFactor(double t) const {
  return pulse_shape == PulseShape::kRectangular ? 1.0 : std::sin(M_PI * t / duration_s);
}

}  // namespace mbid::simulation
