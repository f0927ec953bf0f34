#include "mbid/model/torsional_oscillator.h"

#include <cmath>
#include <string>

#include "mbid/common/error.h"

namespace mbid::model {

void TorsionalOscillatorParameters::Validate() const {
  if (!(std::isfinite(inertia_kgm2) && inertia_kgm2 > 0)) {
    throw InputError("model parameters", "inertia_kgm2", "value " + std::to_string(inertia_kgm2),
                     "a positive finite inertia in kg*m^2");
  }
  if (!(std::isfinite(stiffness_Nm_per_rad) && stiffness_Nm_per_rad > 0)) {
    throw InputError("model", "c_angle", "stiffness " + std::to_string(stiffness_Nm_per_rad),
                     "a positive finite value in N*m/rad");
  }
  if (!(std::isfinite(damping_Nms_per_rad) && damping_Nms_per_rad >= 0)) {
    throw InputError("model", "d_angle", "damping " + std::to_string(damping_Nms_per_rad),
                     "a non-negative finite value in N*m*s/rad");
  }
}

MachineDescription DescribeTorsionalOscillator(const TorsionalOscillatorParameters& p) {
  p.Validate();
  MachineDescription machine;
  machine.gravity_mps2 = 0.0;
  BodyDescription disc;
  disc.name = "disc";
  disc.parent = "ground";
  disc.joint.type = JointType::kRevolute;
  disc.joint.coordinates = {"angle"};
  disc.joint.axes = {Eigen::Vector3d::UnitZ()};
  // Moment J about the axis; the other two only keep the inertia a rigid body's (J/2 + J/2).
  disc.mass_kg = 1.0;
  const double J = p.inertia_kgm2;
  disc.inertia_kgm2 = Eigen::Vector3d(J / 2, J / 2, J).asDiagonal();
  machine.bodies = {disc};
  machine.springs = {{"angle", p.stiffness_Nm_per_rad, p.damping_Nms_per_rad}};
  machine.points = {{"rim", "disc", Eigen::Vector3d(1, 0, 0)}};
  machine.payload_point = "rim";  // without gravity a payload has no static effect
  OutputDescription angle;
  angle.name = "angle";
  angle.type = OutputType::kCoordinate;
  angle.coordinate = "angle";
  machine.outputs = {angle};
  return machine;
}

MultibodyModel MakeTorsionalOscillator(const TorsionalOscillatorParameters& parameters) {
  return MultibodyModel(DescribeTorsionalOscillator(parameters), "torsional_oscillator");
}

}  // namespace mbid::model
