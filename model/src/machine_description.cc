#include "mbid/model/machine_description.h"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "degrees.h"
#include "mbid/common/error.h"
#include "mbid/common/measurement.h"

namespace mbid::model {
namespace {

using internal::kDegToRad;

[[noreturn]] void Fail(const std::string& field, const std::string& problem,
                       const std::string& expected) {
  throw InputError("machine description", field, problem, expected);
}

std::string JoinNames(const std::vector<std::string>& names) {
  std::string text;
  for (const std::string& name : names) text += (text.empty() ? "" : ", ") + name;
  return text.empty() ? "(none)" : text;
}

void CheckInertia(const BodyDescription& body, const std::string& field) {
  const Eigen::Matrix3d& I = body.inertia_kgm2;
  if (!I.allFinite()) Fail(field, "non-finite inertia", "finite values in kg*m^2");
  if (!I.isApprox(I.transpose(), 1e-12) && !(I - I.transpose()).isZero(0.0)) {
    Fail(field, "inertia matrix not symmetric", "a symmetric matrix");
  }
  if (body.mass_kg == 0) {
    if (!I.isZero(0.0)) Fail(field, "a massless body with inertia", "all zero for a massless body");
    return;
  }
  const Eigen::Vector3d moments = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(I).eigenvalues();
  if (!(moments.minCoeff() > 0)) {
    Fail(field,
         "inertia not positive definite (principal moments " + std::to_string(moments[0]) + ", " +
             std::to_string(moments[1]) + ", " + std::to_string(moments[2]) + ")",
         "positive principal moments in kg*m^2 (a point mass or a slender rod has a zero one: "
         "give each a small positive value, e.g. 1e-6 m L^2)");
  }
  // A rigid body's principal moments obey I_max <= I_a + I_b (a tolerance for rounded data).
  if (moments[2] > (moments[0] + moments[1]) * (1 + 1e-9)) {
    Fail(field, "principal moments violate the triangle inequality",
         "each principal moment at most the sum of the other two");
  }
}

}  // namespace

bool IsIdentifier(const std::string& name) {
  return !name.empty() && std::isalpha(static_cast<unsigned char>(name[0])) &&
         name.find_first_not_of(
             "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_") ==
             std::string::npos;
}

std::vector<std::string> MachineDescription::coordinates() const {
  std::vector<std::string> names;
  for (const BodyDescription& body : bodies) {
    names.insert(names.end(), body.joint.coordinates.begin(), body.joint.coordinates.end());
  }
  return names;
}

bool MachineDescription::IsTranslational(const std::string& coordinate) const {
  for (const BodyDescription& body : bodies) {
    const auto& names = body.joint.coordinates;
    if (std::find(names.begin(), names.end(), coordinate) != names.end()) {
      return body.joint.type == JointType::kPrismatic;
    }
  }
  const RigidCoordinate* rigid = FindRigid(coordinate);
  return rigid != nullptr && rigid->translational;
}

const MachineDescription::RigidCoordinate* MachineDescription::FindRigid(
    const std::string& coordinate) const {
  for (const RigidCoordinate& rigid : rigid_coordinates) {
    if (rigid.name == coordinate) return &rigid;
  }
  return nullptr;
}

const SpringDescription* MachineDescription::FindSpring(const std::string& coordinate) const {
  for (const SpringDescription& spring : springs) {
    if (spring.coordinate == coordinate) return &spring;
  }
  return nullptr;
}

int OutputDerivativeOrder(OutputType type) {
  switch (type) {
    case OutputType::kVelocity:
    case OutputType::kAngularVelocity:
      return 1;
    case OutputType::kAcceleration:
      return 2;
    default:
      return 0;
  }
}

std::string OutputUnits(const MachineDescription& machine, const OutputDescription& output) {
  switch (output.type) {
    case OutputType::kCoordinate:
      return machine.IsTranslational(output.coordinate) ? "m" : "rad";
    case OutputType::kAzimuth:
    case OutputType::kElevation:
      return "rad";
    case OutputType::kDisplacement:
      return "m";
    case OutputType::kVelocity:
      return "m/s";
    case OutputType::kAcceleration:
      return "m/s^2";
    case OutputType::kAngularVelocity:
      return "rad/s";
  }
  return "";
}

Eigen::Matrix3d RotationFromTurns(const std::vector<std::pair<char, double>>& turns_deg) {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  for (const auto& [axis, angle_deg] : turns_deg) {
    const Eigen::Vector3d unit = axis == 'x'   ? Eigen::Vector3d::UnitX()
                                 : axis == 'y' ? Eigen::Vector3d::UnitY()
                                               : Eigen::Vector3d::UnitZ();
    R = R * Eigen::AngleAxisd(angle_deg * kDegToRad, unit).toRotationMatrix();
  }
  return R;
}

void MachineDescription::Validate() const {
  if (!(std::isfinite(gravity_mps2) && gravity_mps2 >= 0)) {
    Fail("gravity_mps2", "gravity " + std::to_string(gravity_mps2), "a finite value >= 0 in m/s^2");
  }
  if (bodies.empty()) Fail("bodies", "no bodies", "at least one body");
  std::set<std::string> body_names{"ground"};
  std::set<std::string> coordinate_names;
  std::set<std::string> parents;
  for (const BodyDescription& body : bodies) {
    const std::string field = "bodies." + body.name;
    if (!IsIdentifier(body.name) || body.name == "ground") {
      Fail(field, "body name '" + body.name + "'",
           "a name of letters, digits and '_' other than 'ground'");
    }
    if (body_names.count(body.name))
      Fail(field, "body '" + body.name + "' twice", "each body once");
    if (!body_names.count(body.parent)) {
      Fail(field + ".parent", "parent '" + body.parent + "' is not defined above",
           "ground or a body listed before '" + body.name + "'");
    }
    parents.insert(body.parent);
    body_names.insert(body.name);

    const JointDescription& joint = body.joint;
    const size_t dofs = joint.type == JointType::kWeld        ? 0
                        : joint.type == JointType::kUniversal ? 2
                                                              : 1;
    if (joint.coordinates.size() != dofs) {
      Fail(field + ".joint.coordinates", std::to_string(joint.coordinates.size()) + " coordinates",
           std::to_string(dofs) + " for this joint type");
    }
    for (const std::string& coordinate : joint.coordinates) {
      if (!IsIdentifier(coordinate)) {
        Fail(field + ".joint.coordinates", "coordinate name '" + coordinate + "'",
             "letters, digits and '_', starting with a letter");
      }
      if (!coordinate_names.insert(coordinate).second) {
        Fail(field + ".joint.coordinates", "coordinate '" + coordinate + "' named twice",
             "each coordinate name once in the machine");
      }
    }
    const size_t axes = joint.type == JointType::kWeld ? 0 : dofs;
    if (joint.axes.size() != axes) {
      Fail(field + ".joint." + (joint.type == JointType::kUniversal ? "axes" : "axis"),
           std::to_string(joint.axes.size()) + " axes", std::to_string(axes));
    }
    for (const Eigen::Vector3d& axis : joint.axes) {
      if (!axis.allFinite() || !(axis.norm() > 0)) {
        Fail(field + ".joint." + (joint.type == JointType::kUniversal ? "axes" : "axis"),
             "zero axis", "a non-zero direction");
      }
    }
    // Simbody builds the joint frame on the first axis and the second made perpendicular to
    // it: axes typed to 6 digits (1e-6 in the cosine, 0.06 mdeg) are perpendicular enough.
    if (joint.type == JointType::kUniversal &&
        std::abs(joint.axes[0].normalized().dot(joint.axes[1].normalized())) > 1e-6) {
      Fail(field + ".joint.axes",
           fmt::format("axes at {:.7g} deg to each other",
                       std::acos(std::clamp(
                           joint.axes[0].normalized().dot(joint.axes[1].normalized()), -1.0, 1.0)) *
                           180 / M_PI),
           "two perpendicular axes (to 1e-6 in the cosine of their angle)");
    }
    for (const auto& [matrix, key] :
         {std::pair{&joint.in_parent_rotation, "in_parent_rotation_deg"},
          std::pair{&joint.in_body_rotation, "in_body_rotation_deg"}}) {
      if (!matrix->allFinite() ||
          !(*matrix * matrix->transpose()).isApprox(Eigen::Matrix3d::Identity(), 1e-12)) {
        Fail(field + ".joint." + key, "not a rotation", "turns in degrees");
      }
    }
    if (!joint.in_parent_m.allFinite() || !joint.in_body_m.allFinite()) {
      Fail(field + ".joint", "non-finite joint position", "finite positions in m");
    }
    if (!(std::isfinite(body.mass_kg) && body.mass_kg >= 0 && body.mass_kg <= kMaxBodyMass_kg)) {
      Fail(field + ".mass_kg", fmt::format("mass {:g} kg", body.mass_kg),
           "a mass from 0 to 1e9 kg");
    }
    if (!body.com_m.allFinite()) Fail(field + ".com_m", "non-finite position", "finite, in m");
    CheckInertia(body, field + ".inertia_kgm2");
  }
  if (coordinate_names.empty()) {
    Fail("bodies", "no joint coordinate: every joint is a weld",
         "at least one revolute, prismatic or universal joint (a machine that cannot move has no "
         "modes)");
  }
  for (const BodyDescription& body : bodies) {
    if (body.mass_kg == 0 && !parents.count(body.name)) {
      Fail("bodies." + body.name + ".mass_kg", "a massless body without children",
           "a positive mass (massless link frames need a child body)");
    }
  }

  for (const RigidCoordinate& rigid : rigid_coordinates) {
    if (coordinate_names.count(rigid.name)) {
      Fail("bodies", "coordinate '" + rigid.name + "' both moves and is rigid",
           "a rigid coordinate that no joint has");
    }
  }
  const std::vector<std::string> all_coordinates = coordinates();
  std::set<std::string> sprung;
  for (const SpringDescription& spring : springs) {
    const std::string field = "springs." + spring.coordinate;
    if (!coordinate_names.count(spring.coordinate)) {
      Fail(field, "unknown coordinate '" + spring.coordinate + "'",
           "one of " + JoinNames(all_coordinates));
    }
    if (!sprung.insert(spring.coordinate).second) Fail(field, "two springs", "one per coordinate");
    if (!(std::isfinite(spring.stiffness) && spring.stiffness > 0)) {
      Fail(field, "stiffness " + std::to_string(spring.stiffness), "a positive finite stiffness");
    }
    if (!(std::isfinite(spring.damping) && spring.damping >= 0)) {
      Fail(field, "damping " + std::to_string(spring.damping), "a finite damping >= 0");
    }
  }

  std::vector<std::string> body_list;
  for (const BodyDescription& body : bodies) body_list.push_back(body.name);
  std::set<std::string> point_names;
  for (const PointDescription& point : points) {
    const std::string field = "points." + point.name;
    if (!IsIdentifier(point.name)) Fail(field, "point name '" + point.name + "'", "an identifier");
    if (!point_names.insert(point.name).second) Fail(field, "point named twice", "each point once");
    if (!body_names.count(point.body) || point.body == "ground") {
      Fail(field + ".body", "unknown body '" + point.body + "'", "one of " + JoinNames(body_list));
    }
    if (!point.at_m.allFinite()) Fail(field + ".at_m", "non-finite position", "finite, in m");
  }
  std::vector<std::string> point_list(point_names.begin(), point_names.end());
  if (!payload_point.empty() && !point_names.count(payload_point)) {
    Fail("payload_point", "unknown point '" + payload_point + "'",
         "one of " + JoinNames(point_list));
  }
  if (!(std::isfinite(attached_payload_kg) && attached_payload_kg >= 0)) {
    Fail("payload_mass_kg", "mass " + std::to_string(attached_payload_kg), "a finite mass >= 0");
  }
  if (attached_payload_kg > 0 && payload_point.empty()) {
    Fail("payload_mass_kg", "an attached payload without a payload_point",
         "payload_point naming where it hangs");
  }

  if (outputs.empty())
    Fail("outputs", "no outputs", "at least one output (what a sensor measures)");
  std::set<std::string> output_names;
  for (const OutputDescription& output : outputs) {
    const std::string field = "outputs." + output.name;
    if (!output_names.insert(output.name).second) Fail(field, "output named twice", "each once");
    // Its name is a channel of the measurement files: found here, not after a simulation.
    if (const std::string problem = ProblemWithChannelName(output.name); !problem.empty()) {
      Fail(field, problem + " for an output", kChannelNameRule);
    }
    // A channel is an output or a coordinate by its name: one name, one quantity.
    const bool coordinate_name = std::find(all_coordinates.begin(), all_coordinates.end(),
                                           output.name) != all_coordinates.end();
    const auto fail_name = [&] {
      Fail(field, "output named like the coordinate '" + output.name + "'",
           "a name of its own (or a coordinate output of that coordinate)");
    };
    if (coordinate_name && output.type != OutputType::kCoordinate) fail_name();
    switch (output.type) {
      case OutputType::kCoordinate:
        if (!coordinate_names.count(output.coordinate) && !FindRigid(output.coordinate)) {
          Fail(field + ".coordinate", "unknown coordinate '" + output.coordinate + "'",
               "one of " + JoinNames(all_coordinates));
        }
        if (coordinate_name && output.coordinate != output.name) fail_name();
        continue;
      case OutputType::kAzimuth:
      case OutputType::kElevation:
      case OutputType::kAngularVelocity:
        if (!body_names.count(output.body) || output.body == "ground") {
          Fail(field + ".body", "unknown body '" + output.body + "'",
               "one of " + JoinNames(body_list));
        }
        break;
      default:
        if (!point_names.count(output.point)) {
          Fail(field + ".point", "unknown point '" + output.point + "'",
               "one of " + JoinNames(point_list));
        }
    }
    if (!output.direction.allFinite() || !(output.direction.norm() > 0)) {
      Fail(field + (output.type == OutputType::kAngularVelocity ? ".axis" : ".direction"),
           "zero direction", "a non-zero direction");
    }
  }
}

}  // namespace mbid::model
