#pragma once

// MultibodyModel's state (private to model/): the Simbody system built from a machine description,
// the described kinematics and the outputs resolved to indices. Shared by multibody_model.cc
// (building, parameters, states), multibody_dynamics.cc (forces, statics, linearization) and
// multibody_outputs.cc (sensor outputs).
#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <map>
#include <mutex>

#include "external_load_force.h"
#include "mbid/common/error.h"
#include "mbid/model/multibody_model.h"
#include "mbid/model/simbody.h"
#include "mbid/model/simbody_conversions.h"

namespace mbid::model {
// Names and helpers of the three files.
namespace {

using SimTK::MobilizedBody;
using SimTK::Rotation;
using SimTK::Transform;
using SimTK::Vec3;

inline SimTK::Mat33 ToMat33(const Eigen::Matrix3d& m) {
  SimTK::Mat33 result;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) result(r, c) = m(r, c);
  }
  return result;
}

inline Eigen::Vector3d ToEigen3(const Vec3& v) { return Eigen::Vector3d(v[0], v[1], v[2]); }

inline Eigen::Matrix3d ToEigen33(const SimTK::Mat33& m) {
  Eigen::Matrix3d result;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) result(r, c) = m(r, c);
  }
  return result;
}

inline double WrapToPi(double angle_rad) { return std::remainder(angle_rad, 2.0 * M_PI); }

// The mobilizer's own axes turned onto the described ones: Pin turns about z, Slider slides
// along x, Universal turns about x then the new y. Both joint frames get the same turn, so the
// frames still coincide at q = 0.
inline Rotation CalcAlignment(const JointDescription& joint) {
  switch (joint.type) {
    case JointType::kRevolute:
      return Rotation(SimTK::UnitVec3(ToVec3(joint.axes[0])), SimTK::ZAxis);
    case JointType::kPrismatic:
      return Rotation(SimTK::UnitVec3(ToVec3(joint.axes[0])), SimTK::XAxis);
    case JointType::kUniversal:
      return Rotation(SimTK::UnitVec3(ToVec3(joint.axes[0])), SimTK::XAxis, ToVec3(joint.axes[1]),
                      SimTK::YAxis);
    case JointType::kWeld:
      break;
  }
  return Rotation();
}

inline SimTK::MassProperties CalcMassProperties(const BodyDescription& body, double point_mass_kg,
                                                const Eigen::Vector3d& point_m) {
  if (body.mass_kg == 0 && point_mass_kg == 0) {
    return SimTK::MassProperties(0, Vec3(0), SimTK::Inertia(0));
  }
  const Eigen::Matrix3d& I = body.inertia_kgm2;
  const Vec3 com = ToVec3(body.com_m);
  SimTK::Inertia inertia = SimTK::Inertia(I(0, 0), I(1, 1), I(2, 2), I(0, 1), I(0, 2), I(1, 2))
                               .shiftFromMassCenter(com, body.mass_kg);
  const double mass = body.mass_kg + point_mass_kg;
  Vec3 center = com;
  if (point_mass_kg > 0) {
    const Vec3 p = ToVec3(point_m);
    inertia += SimTK::Inertia::pointMassAt(p, point_mass_kg);
    center = (body.mass_kg * com + point_mass_kg * p) / mass;
  }
  return SimTK::MassProperties(mass, center, inertia);
}

}  // namespace

struct MultibodyModel::Impl {
  // What a coordinate carries: its spring slot, and whether it slides (m) or turns (rad).
  struct Coordinate {
    int spring = -1;  // index into springs/dampers, -1 for a free coordinate
    bool translational = false;
    SimTK::MobilizedBodyIndex mobod;  // its mobilizer and the mobility in it
    int mobility = 0;
    int q = 0, u = 0;  // its entries of the state's q and u
  };
  struct Weight {
    SimTK::MobilizedBodyIndex body;
    Vec3 force_G;        // m g
    Vec3 mass_center_B;  // where it acts
  };
  // Output data resolved to indices, directions unit.
  struct Output {
    OutputType type;
    int coordinate = -1;
    int body = -1;
    Vec3 station{0};
    Eigen::Vector3d direction;
    bool body_frame = false;
    double rest_angle_rad = 0.0;                              // azimuth or elevation at q = 0
    Eigen::Vector3d rest_position = Eigen::Vector3d::Zero();  // the point at q = 0
  };
  // M, the geometric stiffness and H at the linearization point: q = 0, where they depend on the
  // inertial data alone, or the rest an attached payload deflects the machine to, which moves
  // with the stiffness (SetParameter starts a new set). Computed once and shared with clones
  // (they cost about 30 right-hand sides).
  struct RestMatrices {
    std::once_flag once;
    Eigen::VectorXd q;  // the rest
    Eigen::MatrixXd M, K_g, H;
  };

  Impl(MachineDescription description, std::string model_type);

  // A massless frame on a revolute joint whose only child turns on a revolute joint at the same
  // point about a perpendicular axis is a universal joint: Simbody gets one mobilizer for the
  // pair instead of a massless body (a tenth of a right-hand side on the crane). Frames that
  // carry points or body outputs stay bodies.
  std::vector<bool> FindMergeableFrames() const;

  // Coordinate `which` of `body` is mobility `mobility` of `mobod`, with its spring-damper.
  void AddCoordinate(const BodyDescription& body, size_t which, const MobilizedBody& mobod,
                     int mobility);

  const PointDescription& FindPoint(const std::string& name) const {
    for (const PointDescription& point : machine.points) {
      if (point.name == name) return point;
    }
    std::string known;
    for (const PointDescription& point : machine.points)
      known += (known.empty() ? "" : ", ") + point.name;
    throw InputError("model", "load point", "unknown point '" + name + "'",
                     "one of " + (known.empty() ? std::string("(no points)") : known));
  }

  void ResolveOutputs() {
    const Eigen::VectorXd zero =
        Eigen::VectorXd::Zero(static_cast<Eigen::Index>(coordinates.size()));
    for (const OutputDescription& description : machine.outputs) {
      Output output;
      output.type = description.type;
      output.body_frame = description.body_frame;
      output.direction = description.direction.normalized();
      if (description.type == OutputType::kCoordinate) {
        // A rigid coordinate (MachineDescription::rigid_coordinates) stays -1: it reads 0.
        const auto found =
            std::find(coordinates.begin(), coordinates.end(), description.coordinate);
        if (found != coordinates.end()) {
          output.coordinate = static_cast<int>(found - coordinates.begin());
        }
      } else if (!description.body.empty()) {
        output.body = body_index.at(description.body);
      } else {
        const PointDescription& point = FindPoint(description.point);
        output.body = body_index.at(point.body);
        output.station = ToVec3(point.at_m);
      }
      output_names.push_back(description.name);
      output_units.push_back(OutputUnits(machine, description));
      output_orders.push_back(OutputDerivativeOrder(description.type));
      highest_output_order = std::max(highest_output_order, output_orders.back());
      if (output.body >= 0 && OutputDerivativeOrder(output.type) == 0) {
        pose_count = std::max(pose_count, static_cast<size_t>(output.body) + 1);
      }
      outputs.push_back(output);
    }
    // Reference values at q = 0: outputs are deviations from them.
    std::vector<Pose> poses = CalcPoses(zero);
    for (size_t i = 0; i < outputs.size(); ++i) {
      Output& output = outputs[i];
      if (output.type == OutputType::kAzimuth || output.type == OutputType::kElevation) {
        const Eigen::Vector3d u = poses[static_cast<size_t>(output.body)].R * output.direction;
        if (std::hypot(u[0], u[1]) < 1e-6) {
          throw InputError("machine description", "outputs." + output_names[i] + ".direction",
                           "vertical at q = 0, where azimuth and elevation are undefined",
                           "a direction off the vertical");
        }
        output.rest_angle_rad = output.type == OutputType::kAzimuth
                                    ? std::atan2(u[1], u[0])
                                    : std::atan2(u[2], std::hypot(u[0], u[1]));
      }
      if (output.type == OutputType::kDisplacement) {
        const Pose& pose = poses[static_cast<size_t>(output.body)];
        output.rest_position = pose.p + pose.R * ToEigen3(output.station);
      }
    }
  }

  // Gravity's generalized force at q = 0 on the machine without the attached payload: the dead
  // weight the springs carry (the preload rule).
  Eigen::VectorXd CalcUnloadedGravityForce() const {
    SimTK::State s = MakeStaticState();
    std::vector<PointLoad> lift;
    if (machine.attached_payload_kg > 0) {
      lift.push_back({machine.payload_point,
                      Eigen::Vector3d(0, 0, machine.attached_payload_kg * machine.gravity_mps2)});
    }
    return CalcStaticForceAt(
        s, Eigen::VectorXd::Zero(static_cast<Eigen::Index>(coordinates.size())), lift);
  }

  // InputError when M at q = 0 is singular or not finite.
  void CheckMassMatrix() const;

  // A free coordinate has no spring to carry a dead weight: q = 0 is a rest position only if
  // gravity does not drive it there.
  void CheckFreeCoordinates() const {
    double scale = 0;  // N or N*m: weights times the machine's extent
    for (const BodyDescription& body : machine.bodies) {
      scale +=
          body.mass_kg * machine.gravity_mps2 *
          (1 + body.com_m.norm() + body.joint.in_parent_m.norm() + body.joint.in_body_m.norm());
    }
    // An attached payload's weight deflects the sprung coordinates to a rest of their own; a free
    // one it would drive away.
    Eigen::VectorXd gravity = unloaded_gravity_force;
    if (machine.attached_payload_kg > 0) {
      SimTK::State s = MakeStaticState();
      gravity = CalcStaticForceAt(
          s, Eigen::VectorXd::Zero(static_cast<Eigen::Index>(coordinates.size())), {});
    }
    for (size_t i = 0; i < coordinates.size(); ++i) {
      const double g = gravity[static_cast<Eigen::Index>(i)];
      if (coordinate_data[i].spring < 0 && std::abs(g) > 1e-9 * std::max(scale, 1.0)) {
        throw InputError(
            "machine description", "springs",
            "coordinate '" + coordinates[i] + "' has no spring, but gravity drives it at q = 0 (" +
                std::to_string(g) + (coordinate_data[i].translational ? " N" : " N*m") +
                (machine.attached_payload_kg > 0 ? ", with the attached payload)" : ")"),
            "a spring on '" + coordinates[i] + "' (the unloaded machine rests at q = 0)");
      }
    }
  }

  // M(q) u' at rest at q (velocity terms vanish) on `scratch`, a state carrying the parameters:
  // springs, gravity and the point loads.
  Eigen::VectorXd CalcStaticForceAt(SimTK::State& scratch, const Eigen::VectorXd& q,
                                    const std::vector<PointLoad>& loads) const {
    scratch.updQ() = ToVector(q);
    scratch.updU() = 0;
    system.realize(scratch, SimTK::Stage::Acceleration);
    SimTK::Vector m_udot;
    matter.multiplyByM(scratch, scratch.getUDot(), m_udot);
    Eigen::VectorXd force = ToEigen(m_udot);
    for (const PointLoad& load : loads) {
      if (load.force_G.isZero(0.0)) continue;
      const PointDescription& point = FindPoint(load.point);
      SimTK::Vector f;
      matter.multiplyByStationJacobianTranspose(
          scratch, mobods[static_cast<size_t>(body_index.at(point.body))], ToVec3(point.at_m),
          ToVec3(load.force_G), f);
      force += ToEigen(f);
    }
    return force;
  }

  // Body poses in ground from the description's kinematics, cheaper than a Position
  // realization (outputs are read at every sample); equal to Simbody's to roundoff (tests).
  struct Pose {
    Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
    Eigen::Vector3d p = Eigen::Vector3d::Zero();
  };
  // Per body, what the pose needs of its joint: the turns' cross-product matrices K and K^2
  // (Rodrigues: Rot(a, t) = I + sin t K + (1 - cos t) K^2) and which frame terms are trivial.
  struct JointKinematics {
    Eigen::Matrix3d K[2], K2[2];
    Eigen::Vector3d slide = Eigen::Vector3d::Zero();
    bool parent_turned = false, body_turned = false, body_offset = false;
  };
  void PrepareKinematics() {
    for (const BodyDescription& body : machine.bodies) {
      const JointDescription& joint = body.joint;
      JointKinematics k;
      for (size_t i = 0; i < joint.axes.size(); ++i) {
        const Eigen::Vector3d a = joint.axes[i].normalized();
        k.K[i] << 0, -a[2], a[1], a[2], 0, -a[0], -a[1], a[0], 0;
        k.K2[i] = k.K[i] * k.K[i];
        if (joint.type == JointType::kPrismatic) k.slide = a;
      }
      k.parent_turned = !joint.in_parent_rotation.isIdentity(0.0);
      k.body_turned = !joint.in_body_rotation.isIdentity(0.0);
      k.body_offset = !joint.in_body_m.isZero(0.0);
      kinematics.push_back(k);
    }
  }
  static Eigen::Matrix3d Turn(const JointKinematics& k, int i, double angle) {
    return Eigen::Matrix3d::Identity() + std::sin(angle) * k.K[i] + (1 - std::cos(angle)) * k.K2[i];
  }
  // Poses of the first `count` bodies (all by default).
  std::vector<Pose> CalcPoses(const Eigen::VectorXd& q, size_t count = SIZE_MAX) const {
    count = std::min(count, machine.bodies.size());
    std::vector<Pose> poses(count);
    Eigen::Index next = 0;
    for (size_t b = 0; b < count; ++b) {
      const JointDescription& joint = machine.bodies[b].joint;
      const JointKinematics& k = kinematics[b];
      Eigen::Matrix3d R_FM = Eigen::Matrix3d::Identity();
      Eigen::Vector3d p_FM = Eigen::Vector3d::Zero();
      switch (joint.type) {
        case JointType::kRevolute:
          R_FM = Turn(k, 0, q[next++]);
          break;
        case JointType::kPrismatic:
          p_FM = q[next++] * k.slide;
          break;
        case JointType::kUniversal:
          R_FM = Turn(k, 0, q[next]) * Turn(k, 1, q[next + 1]);
          next += 2;
          break;
        case JointType::kWeld:
          break;
      }
      // X_GB = X_GP X_PF X_FM X_MB with X_MB the inverse of X_BM.
      Eigen::Matrix3d R_PB =
          k.parent_turned ? Eigen::Matrix3d(joint.in_parent_rotation * R_FM) : R_FM;
      if (k.body_turned) R_PB = R_PB * joint.in_body_rotation.transpose();
      Eigen::Vector3d p_PB =
          joint.in_parent_m +
          (k.parent_turned ? Eigen::Vector3d(joint.in_parent_rotation * p_FM) : p_FM);
      if (k.body_offset) p_PB -= R_PB * joint.in_body_m;
      if (parents[b] < 0) {
        poses[b].R = R_PB;
        poses[b].p = p_PB;
      } else {
        const Pose& parent = poses[static_cast<size_t>(parents[b])];
        poses[b].R = parent.R * R_PB;
        poses[b].p = parent.p + parent.R * p_PB;
      }
    }
    return poses;
  }

  const RestMatrices& rest_matrices() const {
    std::call_once(rest->once, [this] { CalcRestMatrices(*rest); });
    return *rest;
  }
  void CalcRestMatrices(RestMatrices& result) const;
  // M, K_g and H at result.q.
  void CalcMatricesAt(RestMatrices& result) const;
  // The default state with springs and dampers off: gravity and loads alone.
  SimTK::State MakeStaticState() const;
  // The default state carrying the description's springs and dampers (with the preload rule's
  // neutral positions): what MakeState starts from.
  SimTK::State MakeSpringState() const;
  // Sets spring `slot`'s stiffness (and its preload's neutral position) in `state`.
  void ApplyStiffness(SimTK::State& state, int slot, int coordinate, double stiffness) const;
  // df/dq of the static generalized force at rest: -(springs + K_g).
  Eigen::MatrixXd CalcRestTangent(const Eigen::MatrixXd& K_g) const;

  MachineDescription machine;
  std::string type;
  SimTK::MultibodySystem system;
  SimTK::SimbodyMatterSubsystem matter;
  SimTK::GeneralForceSubsystem forces;
  std::vector<MobilizedBody> mobods;
  std::vector<int> parents;
  std::map<std::string, int> body_index;
  std::vector<std::string> coordinates;
  std::vector<std::string> coordinate_units;
  std::vector<Coordinate> coordinate_data;
  std::vector<SimTK::Force::MobilityLinearSpring> springs;
  std::vector<SimTK::Force::MobilityLinearDamper> dampers;
  std::vector<JointKinematics> kinematics;
  size_t pose_count = 0;         // bodies up to the last one a position output needs
  int highest_output_order = 0;  // how far CalcOutputs realizes: 1 Velocity, 2 Acceleration
  std::vector<Output> outputs;
  std::vector<std::string> output_names;
  std::vector<std::string> output_units;
  std::vector<int> output_orders;
  MechanicalModel::ExternalLoadFunction external_load;
  LoadPointLocator locate_point;
  std::vector<Weight> weights;
  SimTK::State default_state;
  Eigen::VectorXd unloaded_gravity_force;
  std::shared_ptr<RestMatrices> rest = std::make_shared<RestMatrices>();
};

}  // namespace mbid::model
