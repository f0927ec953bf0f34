#include "mbid/model/truck_crane_description.h"

#include <cmath>

namespace mbid::model {

MachineDescription DescribeTruckCrane(const TruckCraneParameters& p) {
  p.Validate();
  MachineDescription machine;
  machine.gravity_mps2 = p.gravity_mps2;
  auto revolute = [](const char* coordinate, const Eigen::Vector3d& axis,
                     const Eigen::Vector3d& in_parent_m) {
    JointDescription joint;
    joint.type = JointType::kRevolute;
    joint.coordinates = {coordinate};
    joint.axes = {axis};
    joint.in_parent_m = in_parent_m;
    return joint;
  };
  // The crane's data are given in G at alpha = 0 with the base frame at G's origin; the base
  // body frame here sits at the pitch pivot O_a, so base data shift by O_a.
  BodyDescription base;
  base.name = "base";
  base.parent = "ground";
  base.joint = revolute("alpha", Eigen::Vector3d::UnitY(), p.p_GOa_m);
  base.mass_kg = p.base_mass_kg;
  base.com_m = p.p_GBcm_m - p.p_GOa_m;
  base.inertia_kgm2 = p.base_inertia_kgm2.asDiagonal();

  BodyDescription slewing;
  slewing.name = "slewing";
  slewing.parent = "base";
  slewing.joint = revolute("gamma", Eigen::Vector3d::UnitZ(), p.p_GOs_m - p.p_GOa_m);
  slewing.joint.in_parent_rotation = RotationFromTurns({{'z', p.slew_rad * 180.0 / M_PI}});
  slewing.mass_kg = p.slewing_mass_kg;
  slewing.com_m = p.p_OsScm_S_m;
  slewing.inertia_kgm2 = p.slewing_inertia_kgm2.asDiagonal();

  // The boom's universal joint at the foot F as a massless yaw frame and a luffing pin.
  BodyDescription yaw;
  yaw.name = "yaw";
  yaw.parent = "slewing";
  yaw.joint = revolute("eta", Eigen::Vector3d::UnitZ(), p.p_OsF_S_m);

  BodyDescription boom;
  boom.name = "boom";
  boom.parent = "yaw";
  boom.joint = revolute("theta", -Eigen::Vector3d::UnitY(), Eigen::Vector3d::Zero());
  boom.joint.in_parent_rotation = RotationFromTurns({{'y', -p.boom_elevation_rad * 180.0 / M_PI}});
  const double L = p.boom_length_m;
  const double m = p.boom_mass_kg;
  boom.mass_kg = m;
  boom.com_m = Eigen::Vector3d(L / 2, 0, 0);
  boom.inertia_kgm2 =
      Eigen::Vector3d(p.boom_axial_inertia_kgm2, m * L * L / 12, m * L * L / 12).asDiagonal();
  machine.bodies = {base, slewing, yaw, boom};

  const char* coordinates[] = {"alpha", "gamma", "eta", "theta"};
  for (int i = 0; i < 4; ++i) {
    machine.springs.push_back({coordinates[i],
                               p.joints[static_cast<size_t>(i)].stiffness_Nm_per_rad,
                               p.joints[static_cast<size_t>(i)].damping_Nms_per_rad});
  }
  machine.points.push_back({"boom_tip", "boom", Eigen::Vector3d(L, 0, 0)});
  machine.payload_point = "boom_tip";
  machine.attached_payload_kg = p.attached_payload_kg;
  OutputDescription psi;
  psi.name = "psi";
  psi.type = OutputType::kAzimuth;
  psi.body = "boom";
  psi.body_frame = true;
  OutputDescription phi = psi;
  phi.name = "phi";
  phi.type = OutputType::kElevation;
  machine.outputs = {psi, phi};
  return machine;
}

MultibodyModel MakeTruckCrane(const TruckCraneParameters& parameters) {
  return MultibodyModel(DescribeTruckCrane(parameters), "truck_crane");
}

}  // namespace mbid::model
