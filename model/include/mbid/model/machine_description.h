#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "mbid/common/yaml_reader.h"

namespace mbid::model {

// A machine as docs/machine-description.md describes it: a tree of rigid bodies, each joined to
// its parent by a joint whose coordinates may carry linear spring-dampers, named points and
// outputs. All values evaluated (no expressions left), SI units, rotations as matrices.

enum class JointType { kRevolute, kPrismatic, kUniversal, kWeld };

struct JointDescription {
  JointType type = JointType::kWeld;
  std::vector<std::string> coordinates;  // one per degree of freedom
  // Unit axes in the joint frame: one (revolute, prismatic) or two (universal: the second in the
  // frame turned by the first, perpendicular to the first); none for a weld.
  std::vector<Eigen::Vector3d> axes;
  Eigen::Vector3d in_parent_m = Eigen::Vector3d::Zero();
  Eigen::Matrix3d in_parent_rotation = Eigen::Matrix3d::Identity();  // R_PF
  Eigen::Vector3d in_body_m = Eigen::Vector3d::Zero();
  Eigen::Matrix3d in_body_rotation = Eigen::Matrix3d::Identity();  // R_BM
};

// The largest body mass accepted: far past any machine (the largest weigh ~1e7 kg), it keeps
// masses, inertias and their products finite (1e308 kg would overflow to inf in the model).
constexpr double kMaxBodyMass_kg = 1e9;

struct BodyDescription {
  std::string name;
  std::string parent;  // "ground" or a body listed before this one
  JointDescription joint;
  double mass_kg = 0.0;
  Eigen::Vector3d com_m = Eigen::Vector3d::Zero();
  Eigen::Matrix3d inertia_kgm2 = Eigen::Matrix3d::Zero();  // about the CoM, body axes
};

// -c (q - q_n) - d q' on one coordinate; q_n follows from the preload rule.
struct SpringDescription {
  std::string coordinate;
  double stiffness = 0.0;  // N*m/rad or N/m
  double damping = 0.0;    // N*m*s/rad or N*s/m
};

struct PointDescription {
  std::string name;
  std::string body;
  Eigen::Vector3d at_m = Eigen::Vector3d::Zero();
};

enum class OutputType {
  kCoordinate,
  kAzimuth,
  kElevation,
  kDisplacement,
  kVelocity,
  kAcceleration,
  kAngularVelocity
};

struct OutputDescription {
  std::string name;
  OutputType type = OutputType::kCoordinate;
  std::string coordinate;                                // kCoordinate
  std::string body;                                      // kAzimuth, kElevation, kAngularVelocity
  std::string point;                                     // kDisplacement, kVelocity, kAcceleration
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();  // unit; the axis of kAngularVelocity
  bool body_frame = false;  // direction fixed in the body (true) or in ground (false)
};

// A name of the description (body, coordinate, point): letters, digits and '_', starting with a
// letter.
bool IsIdentifier(const std::string& name);

struct MachineDescription {
  double gravity_mps2 = 9.81;  // along -z of ground
  std::vector<BodyDescription> bodies;
  std::vector<SpringDescription> springs;
  std::vector<PointDescription> points;
  std::string payload_point;  // may be empty: the machine then takes no payload
  // A point mass that stays attached at the payload point; it does not move the unloaded
  // equilibrium (the springs' preload is that of the machine without it).
  double attached_payload_kg = 0.0;
  std::vector<OutputDescription> outputs;
  // Coordinates made rigid in code (rigid_coordinates.h), not a description key: their joints
  // are welds now, so they are not among coordinates(), but an output of type coordinate may
  // still name one and reads 0 (a sensor on a joint that does not move).
  struct RigidCoordinate {
    std::string name;
    bool translational = false;  // m (a prismatic joint's) or rad
  };
  std::vector<RigidCoordinate> rigid_coordinates;

  // Coordinate names in tree order (the order of q).
  std::vector<std::string> coordinates() const;
  // True for coordinates of prismatic joints (m), false for angles (rad); rigid coordinates too.
  bool IsTranslational(const std::string& coordinate) const;
  const SpringDescription* FindSpring(const std::string& coordinate) const;
  const RigidCoordinate* FindRigid(const std::string& coordinate) const;

  // Throws InputError (source "machine description", the key path as field) on the contract's
  // load checks, for descriptions built in code.
  void Validate() const;
};

// The unit of an output: "rad", "m", "m/s", "m/s^2", "rad/s".
std::string OutputUnits(const MachineDescription& machine, const OutputDescription& output);
// How many times q is differentiated in an output's linearization: 0 (y = H q), 1 (y = H q'),
// 2 (y = H q'').
int OutputDerivativeOrder(OutputType type);

// `model:` of `type: multibody`, read strictly with expressions of `model.parameters`
// evaluated; every error is an InputError naming the file and key path.
MachineDescription ReadMachineDescription(const YamlReader& model);

// The intrinsic turns of a rotation list (`[{z: -30}, {y: 16}]`, degrees) as a matrix.
Eigen::Matrix3d RotationFromTurns(const std::vector<std::pair<char, double>>& turns_deg);

}  // namespace mbid::model
