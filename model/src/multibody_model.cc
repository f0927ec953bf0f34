#include "mbid/model/multibody_model.h"

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <map>
#include <mutex>

#include "external_load_force.h"
#include "mbid/common/error.h"
#include "mbid/model/simbody.h"
#include "mbid/model/simbody_conversions.h"

namespace mbid::model {
namespace {

using SimTK::MobilizedBody;
using SimTK::Rotation;
using SimTK::Transform;
using SimTK::Vec3;

SimTK::Mat33 ToMat33(const Eigen::Matrix3d& m) {
  SimTK::Mat33 result;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) result(r, c) = m(r, c);
  }
  return result;
}

Eigen::Vector3d ToEigen3(const Vec3& v) { return Eigen::Vector3d(v[0], v[1], v[2]); }

Eigen::Matrix3d ToEigen33(const SimTK::Mat33& m) {
  Eigen::Matrix3d result;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) result(r, c) = m(r, c);
  }
  return result;
}

double WrapToPi(double angle_rad) { return std::remainder(angle_rad, 2.0 * M_PI); }

// The mobilizer's own axes turned onto the described ones: Pin turns about z, Slider slides
// along x, Universal turns about x then the new y. Both joint frames get the same turn, so the
// frames still coincide at q = 0.
Rotation CalcAlignment(const JointDescription& joint) {
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

SimTK::MassProperties CalcMassProperties(const BodyDescription& body, double point_mass_kg,
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
  // M, the geometric stiffness and H at q = 0 depend on the inertial data alone, not on c and d;
  // computed once and shared with clones (they cost about 30 right-hand sides).
  struct RestMatrices {
    std::once_flag once;
    Eigen::MatrixXd M, K_g, H;
  };

  Impl(MachineDescription description, std::string model_type)
      : machine(std::move(description)),
        type(std::move(model_type)),
        matter(system),
        forces(system) {
    machine.Validate();
    coordinates = machine.coordinates();
    const Eigen::Vector3d payload_at = machine.payload_point.empty()
                                           ? Eigen::Vector3d::Zero()
                                           : FindPoint(machine.payload_point).at_m;
    const std::string payload_body =
        machine.payload_point.empty() ? "" : FindPoint(machine.payload_point).body;

    SimTK::Force::UniformGravity(forces, matter, Vec3(0, 0, -machine.gravity_mps2));
    const std::vector<bool> merged = FindMergeableFrames();
    for (size_t b = 0; b < machine.bodies.size(); ++b) {
      const BodyDescription& body = machine.bodies[b];
      body_index[body.name] = static_cast<int>(b);
      parents.push_back(body.parent == "ground" ? -1 : body_index.at(body.parent));
      if (merged[b]) {
        // Its joint becomes the first axis of its child's universal joint.
        mobods.emplace_back();
        continue;
      }
      const int parent_index = parents.back();
      const bool universal_from_pair =
          parent_index >= 0 && merged[static_cast<size_t>(parent_index)];
      const BodyDescription* frame =
          universal_from_pair ? &machine.bodies[static_cast<size_t>(parent_index)] : nullptr;
      const int holder =
          universal_from_pair ? parents[static_cast<size_t>(parent_index)] : parent_index;
      MobilizedBody& parent = holder < 0 ? matter.updGround() : mobods[static_cast<size_t>(holder)];
      const JointDescription& joint = body.joint;
      const SimTK::Body::Rigid rigid(CalcMassProperties(
          body, body.name == payload_body ? machine.attached_payload_kg : 0.0, payload_at));
      if (universal_from_pair) {
        // R_PC = R_PF Rot(a1, q1) R_F2 Rot(a2, q2) R_CM^T = (R_PF R_F2) Rot(R_F2^T a1, q1)
        // Rot(a2, q2) R_CM^T: a universal joint with the frame's first axis turned into it.
        JointDescription combined;
        combined.type = JointType::kUniversal;
        combined.axes = {joint.in_parent_rotation.transpose() * frame->joint.axes[0].normalized(),
                         joint.axes[0].normalized()};
        const Rotation align = CalcAlignment(combined);
        const Transform X_PF(
            Rotation(ToMat33(frame->joint.in_parent_rotation * joint.in_parent_rotation), true) *
                align,
            ToVec3(frame->joint.in_parent_m));
        const Transform X_BM(Rotation(ToMat33(joint.in_body_rotation), true) * align,
                             ToVec3(joint.in_body_m));
        mobods.push_back(MobilizedBody::Universal(parent, X_PF, rigid, X_BM));
        AddCoordinate(*frame, 0, mobods.back(), 0);
        AddCoordinate(body, 0, mobods.back(), 1);
        continue;
      }
      const Rotation align = CalcAlignment(joint);
      const Transform X_PF(Rotation(ToMat33(joint.in_parent_rotation), true) * align,
                           ToVec3(joint.in_parent_m));
      const Transform X_BM(Rotation(ToMat33(joint.in_body_rotation), true) * align,
                           ToVec3(joint.in_body_m));
      switch (joint.type) {
        case JointType::kRevolute:
          mobods.push_back(MobilizedBody::Pin(parent, X_PF, rigid, X_BM));
          break;
        case JointType::kPrismatic:
          mobods.push_back(MobilizedBody::Slider(parent, X_PF, rigid, X_BM));
          break;
        case JointType::kUniversal:
          mobods.push_back(MobilizedBody::Universal(parent, X_PF, rigid, X_BM));
          break;
        case JointType::kWeld:
          mobods.push_back(MobilizedBody::Weld(parent, X_PF, rigid, X_BM));
          break;
      }
      for (size_t which = 0; which < joint.coordinates.size(); ++which) {
        AddCoordinate(body, which, mobods.back(), static_cast<int>(which));
      }
    }
    locate_point = [this](const std::string& point) {
      const PointDescription& p = FindPoint(point);
      return std::make_pair(
          mobods[static_cast<size_t>(body_index.at(p.body))].getMobilizedBodyIndex(),
          ToVec3(p.at_m));
    };
    SimTK::Force::Custom(forces, new ExternalLoadForce(matter, external_load, locate_point));
    system.realizeTopology();
    default_state = system.getDefaultState();
    system.realizeModel(default_state);
    const int n = static_cast<int>(coordinates.size());
    if (default_state.getNQ() != n || default_state.getNU() != n) {
      throw std::logic_error("MultibodyModel: q and u do not match the described coordinates");
    }
    for (const Coordinate& c : coordinate_data)
      coordinate_units.push_back(c.translational ? "m" : "rad");

    for (Coordinate& c : coordinate_data) {
      const MobilizedBody& mobod = matter.getMobilizedBody(c.mobod);
      c.q = mobod.getFirstQIndex(default_state) + c.mobility;
      c.u = mobod.getFirstUIndex(default_state) + c.mobility;
    }
    // Gravity's share of each mobilized body (the mass properties are fixed at Topology).
    for (SimTK::MobilizedBodyIndex b(1); b < matter.getNumBodies(); ++b) {
      const SimTK::MassProperties& mass =
          matter.getMobilizedBody(b).getBodyMassProperties(default_state);
      weights.push_back(
          {b, mass.getMass() * Vec3(0, 0, -machine.gravity_mps2), mass.getMassCenter()});
    }
    PrepareKinematics();
    ResolveOutputs();
    unloaded_gravity_force = CalcUnloadedGravityForce();
    CheckFreeCoordinates();
  }

  // A massless frame on a revolute joint whose only child turns on a revolute joint at the same
  // point about a perpendicular axis is a universal joint: Simbody gets one mobilizer for the
  // pair instead of a massless body (a tenth of a right-hand side on the crane). Frames that
  // carry points or body outputs stay bodies.
  std::vector<bool> FindMergeableFrames() const {
    const size_t count = machine.bodies.size();
    std::vector<bool> merged(count, false);
    std::map<std::string, int> index;
    for (size_t b = 0; b < count; ++b) index[machine.bodies[b].name] = static_cast<int>(b);
    for (size_t b = 0; b < count; ++b) {
      const BodyDescription& frame = machine.bodies[b];
      const JointDescription& joint = frame.joint;
      if (frame.mass_kg != 0 || joint.type != JointType::kRevolute ||
          !joint.in_body_m.isZero(0.0) || !joint.in_body_rotation.isIdentity(0.0)) {
        continue;
      }
      if (frame.parent != "ground" && merged[static_cast<size_t>(index.at(frame.parent))]) continue;
      // The child must follow at once, so that q keeps the description's order.
      if (b + 1 == count || machine.bodies[b + 1].parent != frame.name) continue;
      int children = 0;
      const BodyDescription* child = nullptr;
      for (const BodyDescription& other : machine.bodies) {
        if (other.parent == frame.name) {
          ++children;
          child = &other;
        }
      }
      if (children != 1 || child->joint.type != JointType::kRevolute ||
          !child->joint.in_parent_m.isZero(0.0)) {
        continue;
      }
      const Eigen::Vector3d first =
          child->joint.in_parent_rotation.transpose() * joint.axes[0].normalized();
      if (std::abs(first.dot(child->joint.axes[0].normalized())) > 1e-12) continue;
      bool referenced = false;
      for (const PointDescription& point : machine.points) referenced |= point.body == frame.name;
      for (const OutputDescription& output : machine.outputs)
        referenced |= output.body == frame.name;
      merged[b] = !referenced;
    }
    return merged;
  }

  // Coordinate `which` of `body` is mobility `mobility` of `mobod`, with its spring-damper.
  void AddCoordinate(const BodyDescription& body, size_t which, const MobilizedBody& mobod,
                     int mobility) {
    Coordinate coordinate;
    coordinate.translational = body.joint.type == JointType::kPrismatic;
    coordinate.mobod = mobod.getMobilizedBodyIndex();
    coordinate.mobility = mobility;
    const SpringDescription* spring = machine.FindSpring(body.joint.coordinates[which]);
    if (spring != nullptr) {
      coordinate.spring = static_cast<int>(springs.size());
      springs.push_back(SimTK::Force::MobilityLinearSpring(
          forces, mobod, SimTK::MobilizerUIndex(mobility), spring->stiffness, 0.0));
      dampers.push_back(SimTK::Force::MobilityLinearDamper(
          forces, mobod, SimTK::MobilizerUIndex(mobility), spring->damping));
    }
    coordinate_data.push_back(coordinate);
  }

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
    SimTK::State s = default_state;
    for (size_t k = 0; k < springs.size(); ++k) {
      springs[k].setStiffness(s, 0.0);
      dampers[k].setDamping(s, 0.0);
    }
    std::vector<PointLoad> lift;
    if (machine.attached_payload_kg > 0) {
      lift.push_back({machine.payload_point,
                      Eigen::Vector3d(0, 0, machine.attached_payload_kg * machine.gravity_mps2)});
    }
    return CalcStaticForceAt(
        s, Eigen::VectorXd::Zero(static_cast<Eigen::Index>(coordinates.size())), lift);
  }

  // A free coordinate has no spring to carry a dead weight: q = 0 is a rest position only if
  // gravity does not drive it there.
  void CheckFreeCoordinates() const {
    double scale = 0;  // N or N*m: weights times the machine's extent
    for (const BodyDescription& body : machine.bodies) {
      scale +=
          body.mass_kg * machine.gravity_mps2 *
          (1 + body.com_m.norm() + body.joint.in_parent_m.norm() + body.joint.in_body_m.norm());
    }
    for (size_t i = 0; i < coordinates.size(); ++i) {
      const double g = unloaded_gravity_force[static_cast<Eigen::Index>(i)];
      if (coordinate_data[i].spring < 0 && std::abs(g) > 1e-9 * std::max(scale, 1.0)) {
        throw InputError(
            "machine description", "springs",
            "coordinate '" + coordinates[i] + "' has no spring, but gravity drives it at q = 0 (" +
                std::to_string(g) + (coordinate_data[i].translational ? " N)" : " N*m)"),
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

void MultibodyModel::Impl::CalcRestMatrices(RestMatrices& result) const {
  const Eigen::Index n = static_cast<Eigen::Index>(coordinates.size());
  // One scratch state at q = 0 with springs and dampers off serves every evaluation (a Simbody
  // State copy costs about four right-hand sides); M and H do not depend on the forces.
  SimTK::State s = default_state;
  for (size_t k = 0; k < springs.size(); ++k) {
    springs[k].setStiffness(s, 0.0);
    dampers[k].setDamping(s, 0.0);
  }
  s.updQ() = 0;
  s.updU() = 0;
  system.realize(s, SimTK::Stage::Position);
  SimTK::Matrix M;
  matter.calcM(s, M);
  result.M = ToEigen(M);

  // Geometric stiffness K_g = -d(gravity force)/dq by central differences with one Richardson
  // step: error O(h^4) ~ 1e-12 relative on forces smooth on the scale of 1 rad or 1 m.
  auto gravity_force = [&](const Eigen::VectorXd& q) { return CalcStaticForceAt(s, q, {}); };
  auto central = [&](Eigen::Index j, double h) {
    Eigen::VectorXd dq = Eigen::VectorXd::Zero(n);
    dq[j] = h;
    return Eigen::VectorXd((gravity_force(dq) - gravity_force(-dq)) / (2 * h));
  };
  Eigen::MatrixXd K_g(n, n);
  const double h = 1e-3;
  for (Eigen::Index j = 0; j < n; ++j) K_g.col(j) = -(4 * central(j, h / 2) - central(j, h)) / 3;
  result.K_g = 0.5 * (K_g + K_g.transpose());  // a Hessian: symmetric up to roundoff

  // H exactly: with q' = e_j at q = 0 every output's rate is its derivative by q_j; velocity
  // and acceleration outputs are J q' and J q'' at rest, the same Jacobian rows.
  result.H = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(outputs.size()), n);
  s.updQ() = 0;
  for (Eigen::Index j = 0; j < n; ++j) {
    s.updU() = 0;
    s.updU()[static_cast<int>(j)] = 1;
    system.realize(s, SimTK::Stage::Velocity);
    for (size_t i = 0; i < outputs.size(); ++i) {
      const Output& output = outputs[i];
      double rate = 0;
      if (output.type == OutputType::kCoordinate) {
        rate = output.coordinate == j ? 1.0 : 0.0;
      } else {
        const MobilizedBody& body = mobods[static_cast<size_t>(output.body)];
        const Eigen::Matrix3d R_GB = ToEigen33(body.getBodyRotation(s).asMat33());
        const Eigen::Vector3d w = ToEigen3(body.getBodyAngularVelocity(s));
        const Eigen::Vector3d d = output.type == OutputType::kAzimuth ||
                                          output.type == OutputType::kElevation || output.body_frame
                                      ? Eigen::Vector3d(R_GB * output.direction)
                                      : output.direction;
        if (output.type == OutputType::kAzimuth || output.type == OutputType::kElevation) {
          const Eigen::Vector3d du = w.cross(d);
          const double rho2 = d[0] * d[0] + d[1] * d[1];
          const double rho = std::sqrt(rho2);
          rate =
              output.type == OutputType::kAzimuth
                  ? (d[0] * du[1] - d[1] * du[0]) / rho2
                  : (rho2 * du[2] - d[2] * (d[0] * du[0] + d[1] * du[1])) / (rho * d.squaredNorm());
        } else if (output.type == OutputType::kAngularVelocity) {
          rate = w.dot(d);
        } else {
          rate = ToEigen3(body.findStationVelocityInGround(s, output.station)).dot(d);
        }
      }
      result.H(static_cast<Eigen::Index>(i), j) = rate;
    }
  }
}

namespace {

// Simbody's multi-line exception text reduced to its one line of substance.
std::string SimbodyReason(const std::exception& error) {
  const std::string text = error.what();
  const size_t at = text.find("Error detected by Simbody method");
  std::string line = text.substr(at == std::string::npos ? 0 : at);
  line = line.substr(0, line.find('\n'));
  return line;
}

}  // namespace

MultibodyModel::MultibodyModel(MachineDescription machine, std::string type) {
  try {
    impl_ = std::make_unique<Impl>(std::move(machine), std::move(type));
  } catch (const SimTK::Exception::Base& error) {
    // Finite but absurd data (a mass of 1e308 kg overflows the inertia shift) reach Simbody.
    throw InputError("machine description", "bodies",
                     "Simbody cannot build this machine: " + SimbodyReason(error),
                     "masses, inertias and positions of a real machine");
  }
}

MultibodyModel::~MultibodyModel() = default;
// The Simbody system refers to the Impl by address; moving the pointer keeps it in place.
MultibodyModel::MultibodyModel(MultibodyModel&&) noexcept = default;
MultibodyModel& MultibodyModel::operator=(MultibodyModel&&) noexcept = default;

const MachineDescription& MultibodyModel::description() const { return impl_->machine; }
std::string MultibodyModel::type() const { return impl_->type; }
const std::vector<std::string>& MultibodyModel::coordinate_names() const {
  return impl_->coordinates;
}
const std::vector<std::string>& MultibodyModel::output_names() const { return impl_->output_names; }
const std::vector<std::string>& MultibodyModel::output_units() const { return impl_->output_units; }
std::vector<int> MultibodyModel::output_derivative_orders() const { return impl_->output_orders; }
std::vector<std::string> MultibodyModel::coordinate_units() const {
  return impl_->coordinate_units;
}

std::vector<std::string> MultibodyModel::load_points() const {
  std::vector<std::string> names;
  for (const PointDescription& point : impl_->machine.points) names.push_back(point.name);
  return names;
}

std::vector<PointLoad> MultibodyModel::CalcPayloadLoads(double mass_kg) const {
  if (impl_->machine.payload_point.empty()) {
    throw InputError("model", "payload_point", "this machine names no payload point",
                     "model.payload_point naming where a payload hangs");
  }
  return {{impl_->machine.payload_point,
           Eigen::Vector3d(0, 0, -mass_kg * impl_->machine.gravity_mps2)}};
}

std::vector<Parameter> MultibodyModel::parameters() const {
  std::vector<Parameter> result;
  const double inf = std::numeric_limits<double>::infinity();
  const MachineDescription& machine = impl_->machine;
  // Every stiffness, then every damping, in coordinate order.
  for (bool stiffness : {true, false}) {
    for (size_t i = 0; i < impl_->coordinates.size(); ++i) {
      const SpringDescription* spring = machine.FindSpring(impl_->coordinates[i]);
      if (spring == nullptr) continue;
      const bool translational = impl_->coordinate_data[i].translational;
      const std::string unit = translational ? "m" : "rad";
      const std::string units = stiffness ? StiffnessUnits(unit) : DampingUnits(unit);
      result.push_back({(stiffness ? "c_" : "d_") + impl_->coordinates[i], units,
                        stiffness ? spring->stiffness : spring->damping, 0.0, inf});
    }
  }
  return result;
}

namespace {

// The coordinate and coefficient `name` ("c_alpha", "d_theta") names; throws if none.
std::pair<int, bool> ParseSpringParameter(const std::vector<std::string>& coordinates,
                                          const MachineDescription& machine,
                                          const std::string& name, double value) {
  for (size_t i = 0; i < coordinates.size(); ++i) {
    const bool stiffness = name == "c_" + coordinates[i];
    if (!stiffness && name != "d_" + coordinates[i]) continue;
    if (machine.FindSpring(coordinates[i]) == nullptr) break;
    if (stiffness && !(std::isfinite(value) && value > 0)) {
      throw InputError("model", name, "stiffness " + std::to_string(value),
                       "a positive finite value");
    }
    if (!stiffness && !(std::isfinite(value) && value >= 0)) {
      throw InputError("model", name, "damping " + std::to_string(value),
                       "a non-negative finite value");
    }
    return {static_cast<int>(i), stiffness};
  }
  std::string known;
  for (const SpringDescription& spring : machine.springs) {
    known += (known.empty() ? "" : ", ") + spring.coordinate;
  }
  throw InputError("model", name, "unknown parameter",
                   "c_<coordinate> or d_<coordinate> of a sprung coordinate (" + known + ")");
}

}  // namespace

void MultibodyModel::SetParameter(const std::string& name, double value) {
  const auto [coordinate, stiffness] =
      ParseSpringParameter(impl_->coordinates, impl_->machine, name, value);
  for (SpringDescription& spring : impl_->machine.springs) {
    if (spring.coordinate != impl_->coordinates[static_cast<size_t>(coordinate)]) continue;
    (stiffness ? spring.stiffness : spring.damping) = value;
  }
}

void MultibodyModel::ApplyParameterToState(SimTK::State& state, const std::string& name,
                                           double value) const {
  const auto [coordinate, stiffness] =
      ParseSpringParameter(impl_->coordinates, impl_->machine, name, value);
  const int slot = impl_->coordinate_data[static_cast<size_t>(coordinate)].spring;
  if (stiffness) {
    impl_->springs[static_cast<size_t>(slot)].setStiffness(state, value);
    // The preload rule holds for every stiffness: the unloaded machine rests at q = 0.
    impl_->springs[static_cast<size_t>(slot)].setQZero(
        state, -impl_->unloaded_gravity_force[coordinate] / value);
  } else {
    impl_->dampers[static_cast<size_t>(slot)].setDamping(state, value);
  }
  // Simbody caches position-dependent forces (the spring's) at the Position stage, which a new
  // parameter alone does not invalidate: without this, a state realized before would keep the
  // old spring force (a caller that also sets q, as the integrator does, would not notice).
  state.invalidateAllCacheAtOrAbove(SimTK::Stage::Position);
}

MechanicalModel::ForceDerivative MultibodyModel::MakeParameterForceDerivative(
    const std::string& name) const {
  const auto [coordinate, stiffness] =
      ParseSpringParameter(impl_->coordinates, impl_->machine, name, GetParameter(name));
  const int n = coordinate_count();
  // Coordinate i is q_i and u_i of the state (tree order, q' = u). The spring's force
  // -c (q - q_n) with the preload's q_n = -g_0 / c is -c q - g_0.
  return [coordinate = coordinate, stiffness = stiffness, n](const SimTK::State& state,
                                                             Eigen::VectorXd& dforce) {
    dforce.setZero(n);
    dforce[coordinate] = stiffness ? -state.getQ()[coordinate] : -state.getU()[coordinate];
  };
}

MechanicalModel::StateDerivative MultibodyModel::MakeStateDerivative() const {
  struct Scratch {
    SimTK::Vector mobility_forces, residual, u_dot;
    SimTK::Vector_<SimTK::SpatialVec> body_forces;
  };
  auto scratch = std::make_shared<Scratch>();
  return [&m = *impl_, scratch](const SimTK::State& state, double* y_dot) {
    SimTK::Vector& mobility = scratch->mobility_forces;
    SimTK::Vector_<SimTK::SpatialVec>& body = scratch->body_forces;
    mobility.resize(state.getNU());
    mobility = 0;
    body.resize(m.matter.getNumBodies());
    body = SimTK::SpatialVec(Vec3(0), Vec3(0));
    // Force::UniformGravity: m g at the mass center, about the body origin, in Ground.
    for (const Impl::Weight& w : m.weights) {
      const Vec3 r = m.matter.getMobilizedBody(w.body).getBodyRotation(state) * w.mass_center_B;
      body[w.body] += SimTK::SpatialVec(r % w.force_G, w.force_G);
    }
    // Force::MobilityLinearSpring and MobilityLinearDamper: -c (q - q_0) - d u on the mobility.
    const SimTK::Vector& q = state.getQ();
    const SimTK::Vector& u = state.getU();
    for (const Impl::Coordinate& c : m.coordinate_data) {
      if (c.spring < 0) continue;
      const SimTK::Force::MobilityLinearSpring& spring = m.springs[static_cast<size_t>(c.spring)];
      mobility[c.u] += -spring.getStiffness(state) * (q[c.q] - spring.getQZero(state)) -
                       m.dampers[static_cast<size_t>(c.spring)].getDamping(state) * u[c.u];
    }
    AddExternalLoads(m.matter, m.external_load, m.locate_point, state, body, mobility);
    // u' = M^-1 (f_applied - f_inertial): Simbody's forward-dynamics operator needs the Dynamics
    // stage, its inverse dynamics (residual = f_inertial - f_applied at u' = 0) and M^-1 only
    // Velocity.
    m.matter.calcResidualForceIgnoringConstraints(state, mobility, body, SimTK::Vector(),
                                                  scratch->residual);
    scratch->residual *= -1;
    m.matter.multiplyByMInv(state, scratch->residual, scratch->u_dot);
    const SimTK::Vector& q_dot = state.getQDot();
    const int nq = q_dot.size();
    for (int i = 0; i < nq; ++i) y_dot[i] = q_dot[i];
    for (int i = 0; i < scratch->u_dot.size(); ++i) y_dot[nq + i] = scratch->u_dot[i];
  };
}

const SimTK::MultibodySystem& MultibodyModel::system() const { return impl_->system; }

SimTK::State MultibodyModel::MakeState(const Eigen::VectorXd& q, const Eigen::VectorXd& u) const {
  const Eigen::Index n = static_cast<Eigen::Index>(impl_->coordinates.size());
  if (q.size() != n || u.size() != n) {
    throw std::invalid_argument("MultibodyModel::MakeState: q and u need one entry per coordinate");
  }
  SimTK::State s = impl_->default_state;
  for (const SpringDescription& spring : impl_->machine.springs) {
    ApplyParameterToState(s, "c_" + spring.coordinate, spring.stiffness);
    ApplyParameterToState(s, "d_" + spring.coordinate, spring.damping);
  }
  s.setTime(0.0);
  s.updQ() = ToVector(q);
  s.updU() = ToVector(u);
  return s;
}

void MultibodyModel::SetExternalLoad(ExternalLoadFunction load) {
  impl_->external_load = std::move(load);
}

Eigen::VectorXd MultibodyModel::CalcOutputs(const SimTK::State& state) const {
  const Impl& m = *impl_;
  const SimTK::Vector& q_simtk = state.getQ();
  Eigen::VectorXd q(q_simtk.size());
  for (int i = 0; i < q_simtk.size(); ++i) q[i] = q_simtk[i];
  // Positions from the description's kinematics; rates from Simbody, realized as far as needed.
  const int highest_order = m.highest_output_order;
  const std::vector<Impl::Pose> poses = m.CalcPoses(q, m.pose_count);
  if (highest_order > 0) {
    m.system.realize(state,
                     highest_order == 1 ? SimTK::Stage::Velocity : SimTK::Stage::Acceleration);
  }
  Eigen::VectorXd y(static_cast<Eigen::Index>(m.outputs.size()));
  for (size_t i = 0; i < m.outputs.size(); ++i) {
    const Impl::Output& output = m.outputs[i];
    double value = 0;
    switch (output.type) {
      case OutputType::kCoordinate:
        value = output.coordinate >= 0 ? q[output.coordinate] : 0.0;
        break;
      case OutputType::kAzimuth:
      case OutputType::kElevation: {
        const Eigen::Vector3d u = poses[static_cast<size_t>(output.body)].R * output.direction;
        value = output.type == OutputType::kAzimuth
                    ? WrapToPi(std::atan2(u[1], u[0]) - output.rest_angle_rad)
                    : std::atan2(u[2], std::hypot(u[0], u[1])) - output.rest_angle_rad;
        break;
      }
      case OutputType::kDisplacement: {
        const Impl::Pose& pose = poses[static_cast<size_t>(output.body)];
        const Eigen::Vector3d p = pose.p + pose.R * ToEigen3(output.station);
        const Eigen::Vector3d d =
            output.body_frame ? Eigen::Vector3d(pose.R * output.direction) : output.direction;
        value = (p - output.rest_position).dot(d);
        break;
      }
      default: {
        const MobilizedBody& body = m.mobods[static_cast<size_t>(output.body)];
        const Eigen::Vector3d d =
            output.body_frame ? Eigen::Vector3d(ToEigen33(body.getBodyRotation(state).asMat33()) *
                                                output.direction)
                              : output.direction;
        const Vec3 v = output.type == OutputType::kVelocity
                           ? body.findStationVelocityInGround(state, output.station)
                       : output.type == OutputType::kAcceleration
                           ? body.findStationAccelerationInGround(state, output.station)
                           : body.getBodyAngularVelocity(state);
        value = ToEigen3(v).dot(d);
      }
    }
    y[static_cast<Eigen::Index>(i)] = value;
  }
  return y;
}

double MultibodyModel::CalcEnergy(const SimTK::State& state) const {
  impl_->system.realize(state, SimTK::Stage::Dynamics);
  return impl_->system.calcEnergy(state);
}

Eigen::VectorXd MultibodyModel::CalcStaticGeneralizedForce(
    const Eigen::VectorXd& q, const std::vector<PointLoad>& loads) const {
  SimTK::State s = MakeState(q, Eigen::VectorXd::Zero(q.size()));
  return impl_->CalcStaticForceAt(s, q, loads);
}

Eigen::VectorXd MultibodyModel::SolveStaticEquilibrium(const std::vector<PointLoad>& loads) const {
  // Newton's chord method on f(q) = 0: the tangent starts as the unloaded machine's -C at rest
  // (springs plus the cached geometric stiffness: no evaluations), kept while the steps shrink
  // fast and refreshed by central differences when they do not. The root's accuracy depends
  // only on f, so the iteration reaches machine precision.
  const Eigen::Index n = static_cast<Eigen::Index>(impl_->coordinates.size());
  SimTK::State s = MakeState(Eigen::VectorXd::Zero(n), Eigen::VectorXd::Zero(n));
  auto force = [&](const Eigen::VectorXd& q) { return impl_->CalcStaticForceAt(s, q, loads); };
  auto tangent = [&](const Eigen::VectorXd& q) {
    Eigen::MatrixXd jacobian(n, n);
    const double h = 1e-7;  // rad or m; smooth forces, curvature scale ~1
    for (Eigen::Index j = 0; j < n; ++j) {
      Eigen::VectorXd dq = Eigen::VectorXd::Zero(n);
      dq[j] = h;
      jacobian.col(j) = (force(q + dq) - force(q - dq)) / (2 * h);
    }
    return Eigen::FullPivLU<Eigen::MatrixXd>(jacobian);
  };
  Eigen::VectorXd q = Eigen::VectorXd::Zero(n);
  Eigen::VectorXd f = force(q);
  if (f.lpNorm<Eigen::Infinity>() == 0) return q;
  Eigen::MatrixXd rest_tangent = -impl_->rest_matrices().K_g;
  for (Eigen::Index i = 0; i < n; ++i) {
    const SpringDescription* spring =
        impl_->machine.FindSpring(impl_->coordinates[static_cast<size_t>(i)]);
    if (spring != nullptr) rest_tangent(i, i) -= spring->stiffness;
  }
  Eigen::FullPivLU<Eigen::MatrixXd> lu(rest_tangent);
  if (!lu.isInvertible()) {
    throw NumericalError("static equilibrium",
                         "the machine has no stiffness against a load on a free coordinate");
  }
  double last_step = std::numeric_limits<double>::infinity();
  for (int iteration = 0; iteration < 50; ++iteration) {
    const Eigen::VectorXd step = lu.solve(-f);
    q += step;
    f = force(q);
    const double step_norm = step.lpNorm<Eigen::Infinity>();
    if (!std::isfinite(step_norm)) break;
    // Converged when the step is at roundoff of q, or stops shrinking after being tiny.
    if (step_norm <= 4 * std::numeric_limits<double>::epsilon() * std::max(1.0, q.norm()) ||
        (step_norm < 1e-12 && step_norm >= last_step)) {
      return q;
    }
    if (step_norm > 0.1 * last_step) lu = tangent(q);  // slow contraction: refresh the tangent
    last_step = step_norm;
  }
  throw NumericalError("static equilibrium", "Newton did not converge in 50 iterations; residual " +
                                                 std::to_string(f.norm()));
}

LinearModel MultibodyModel::Linearize() const {
  const Impl::RestMatrices& rest = impl_->rest_matrices();
  const Eigen::Index n = static_cast<Eigen::Index>(impl_->coordinates.size());
  LinearModel linear;
  linear.coordinates = impl_->coordinates;
  linear.outputs = impl_->output_names;
  linear.output_orders = impl_->output_orders;
  linear.coordinate_units = impl_->coordinate_units;
  linear.output_units = impl_->output_units;
  linear.M = rest.M;
  linear.H = rest.H;
  linear.C = rest.K_g;
  linear.D = Eigen::MatrixXd::Zero(n, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const SpringDescription* spring =
        impl_->machine.FindSpring(impl_->coordinates[static_cast<size_t>(i)]);
    if (spring == nullptr) continue;
    linear.C(i, i) += spring->stiffness;
    // Dampers are the only velocity-dependent forces at rest; gyroscopic terms are quadratic in u.
    linear.D(i, i) = spring->damping;
  }
  return linear;
}

std::unique_ptr<MechanicalModel> MultibodyModel::Clone() const {
  auto clone = std::make_unique<MultibodyModel>(impl_->machine, impl_->type);
  clone->impl_->rest = impl_->rest;  // same inertial data: share M, K_g, H
  return clone;
}

Eigen::VectorXd MultibodyModel::neutral_positions() const {
  const Eigen::Index n = static_cast<Eigen::Index>(impl_->coordinates.size());
  Eigen::VectorXd q_n = Eigen::VectorXd::Zero(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const SpringDescription* spring =
        impl_->machine.FindSpring(impl_->coordinates[static_cast<size_t>(i)]);
    if (spring != nullptr) q_n[i] = -impl_->unloaded_gravity_force[i] / spring->stiffness;
  }
  return q_n;
}

void MultibodyModel::CalcBodyPose(const Eigen::VectorXd& q, const std::string& body,
                                  Eigen::Matrix3d* R_GB, Eigen::Vector3d* p_GB) const {
  const auto found = impl_->body_index.find(body);
  if (found == impl_->body_index.end()) throw std::invalid_argument("unknown body '" + body + "'");
  const Impl::Pose pose = impl_->CalcPoses(q)[static_cast<size_t>(found->second)];
  if (R_GB != nullptr) *R_GB = pose.R;
  if (p_GB != nullptr) *p_GB = pose.p;
}

}  // namespace mbid::model
