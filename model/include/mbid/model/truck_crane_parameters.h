#pragma once

#include <Eigen/Core>
#include <array>

namespace mbid::model {

// Joint spring-damper: generalized force -c (q - q0) - d q'.
struct JointSpringDamper {
  double stiffness_Nm_per_rad = 0.0;
  double damping_Nms_per_rad = 0.0;
};

// All data of the truck crane of docs/reference-crane.md, SI units, angles in radians.
// Frames: G ground (x forward, y left, z up); B base, S slewing mechanism, K boom.
struct TruckCraneParameters {
  double gravity_mps2 = 9.81;
  double boom_elevation_rad = 0.0;  // phi0
  double slew_rad = 0.0;            // psi0

  Eigen::Vector3d p_GOa_m = Eigen::Vector3d::Zero();  // base pitch pivot O_a, in G
  double base_mass_kg = 0.0;
  Eigen::Vector3d p_GBcm_m = Eigen::Vector3d::Zero();           // base CoM in G at alpha = 0
  Eigen::Vector3d base_inertia_kgm2 = Eigen::Vector3d::Zero();  // principal, about CoM, G axes

  Eigen::Vector3d p_GOs_m = Eigen::Vector3d::Zero();  // slewing bearing O_s in G at alpha = 0
  double slewing_mass_kg = 0.0;
  Eigen::Vector3d p_OsScm_S_m = Eigen::Vector3d::Zero();           // CoM from O_s, S axes
  Eigen::Vector3d slewing_inertia_kgm2 = Eigen::Vector3d::Zero();  // principal, CoM, S axes

  Eigen::Vector3d p_OsF_S_m = Eigen::Vector3d::Zero();  // boom foot F from O_s, S axes
  double boom_mass_kg = 0.0;
  double boom_length_m = 0.0;
  double boom_axial_inertia_kgm2 = 0.0;

  // A payload that stays attached: a point mass at the boom tip. It does not move the
  // unloaded equilibrium (the preload rule keeps the unloaded crane at q = 0).
  double attached_payload_kg = 0.0;

  // In coordinate order alpha, gamma, eta, theta.
  std::array<JointSpringDamper, 4> joints{};

  // Throws InputError (source "model parameters", field named) unless every mass, length,
  // stiffness and principal inertia is positive and finite, dampings and the payload are
  // non-negative and finite, inertias satisfy the triangle inequality and the boom elevation
  // is in (-90, 90) degrees.
  void Validate() const;
};

}  // namespace mbid::model
