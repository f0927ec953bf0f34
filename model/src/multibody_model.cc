// Building the Simbody system from a description, its parameters and states.
#include "mbid/model/multibody_model.h"

#include <Eigen/Dense>
#include <cmath>
#include <string>
#include <vector>

#include "mbid/common/error.h"
#include "multibody_model_impl.h"

namespace mbid::model {

MultibodyModel::Impl::Impl(MachineDescription description, std::string model_type)
    : machine(std::move(description)), type(std::move(model_type)), matter(system), forces(system) {
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
    const bool universal_from_pair = parent_index >= 0 && merged[static_cast<size_t>(parent_index)];
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
        mobods[static_cast<size_t>(body_index.at(p.body))].getMobilizedBodyIndex(), ToVec3(p.at_m));
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
  CheckMassMatrix();
  unloaded_gravity_force = CalcUnloadedGravityForce();
  CheckFreeCoordinates();
}

void MultibodyModel::Impl::CheckMassMatrix() const {
  // A coordinate that moves no mass (a massless frame turning about the axis its only child
  // turns about) makes M singular: no dynamics, no modes.
  SimTK::State s = default_state;
  system.realize(s, SimTK::Stage::Position);
  SimTK::Matrix M;
  matter.calcM(s, M);
  const Eigen::MatrixXd m = ToEigen(M);
  const Eigen::LLT<Eigen::MatrixXd> cholesky(m);
  const Eigen::VectorXd diagonal = m.diagonal();
  if (m.allFinite() && cholesky.info() == Eigen::Success &&
      (cholesky.matrixL().toDenseMatrix().diagonal().array().square() >
       1e-12 * diagonal.cwiseAbs().maxCoeff())
          .all()) {
    return;
  }
  // The motion that moves no mass: M's eigenvector of least eigenvalue (a massless link turning
  // with its child about one axis is qc and qd together, not a zero on the diagonal).
  std::string moving;
  if (m.allFinite()) {
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(m);
    const Eigen::VectorXd v = eigen.eigenvectors().col(0);
    for (Eigen::Index i = 0; i < v.size(); ++i) {
      if (std::abs(v[i]) < 0.1 * v.cwiseAbs().maxCoeff()) continue;
      moving += (moving.empty() ? "'" : ", '") + coordinates[static_cast<size_t>(i)] + "'";
    }
  }
  throw InputError("machine description", "bodies",
                   "the mass matrix is singular at q = 0 (coordinates " + moving +
                       "): some motion of the joints moves no mass",
                   "every coordinate moving some mass or inertia (a massless frame may not turn "
                   "about or slide along the axis of its only child's joint)");
}

std::vector<bool> MultibodyModel::Impl::FindMergeableFrames() const {
  const size_t count = machine.bodies.size();
  std::vector<bool> merged(count, false);
  std::map<std::string, int> index;
  for (size_t b = 0; b < count; ++b) index[machine.bodies[b].name] = static_cast<int>(b);
  for (size_t b = 0; b < count; ++b) {
    const BodyDescription& frame = machine.bodies[b];
    const JointDescription& joint = frame.joint;
    if (frame.mass_kg != 0 || joint.type != JointType::kRevolute || !joint.in_body_m.isZero(0.0) ||
        !joint.in_body_rotation.isIdentity(0.0)) {
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
    for (const OutputDescription& output : machine.outputs) referenced |= output.body == frame.name;
    merged[b] = !referenced;
  }
  return merged;
}

void MultibodyModel::Impl::AddCoordinate(const BodyDescription& body, size_t which,
                                         const MobilizedBody& mobod, int mobility) {
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
  // Compared in place: the sensitivities' input hook applies a parameter per quotient.
  const bool prefixed = name.size() > 2 && name[1] == '_' && (name[0] == 'c' || name[0] == 'd');
  for (size_t i = 0; prefixed && i < coordinates.size(); ++i) {
    if (name.compare(2, std::string::npos, coordinates[i]) != 0) continue;
    const bool stiffness = name[0] == 'c';
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
  // The rest an attached payload deflects the machine to moves with the stiffness.
  if (stiffness && impl_->machine.attached_payload_kg > 0) {
    impl_->rest = std::make_shared<Impl::RestMatrices>();
  }
}

SimTK::State MultibodyModel::Impl::MakeSpringState() const {
  SimTK::State s = default_state;
  for (const SpringDescription& spring : machine.springs) {
    const auto found = std::find(coordinates.begin(), coordinates.end(), spring.coordinate);
    const int coordinate = static_cast<int>(found - coordinates.begin());
    const int slot = coordinate_data[static_cast<size_t>(coordinate)].spring;
    ApplyStiffness(s, slot, coordinate, spring.stiffness);
    dampers[static_cast<size_t>(slot)].setDamping(s, spring.damping);
  }
  s.invalidateAllCacheAtOrAbove(SimTK::Stage::Position);
  return s;
}

void MultibodyModel::Impl::ApplyStiffness(SimTK::State& state, int slot, int coordinate,
                                          double stiffness) const {
  springs[static_cast<size_t>(slot)].setStiffness(state, stiffness);
  // The preload rule holds for every stiffness: the unloaded machine rests at q = 0.
  springs[static_cast<size_t>(slot)].setQZero(state,
                                              -unloaded_gravity_force[coordinate] / stiffness);
}

void MultibodyModel::ApplyParameterToState(SimTK::State& state, const std::string& name,
                                           double value) const {
  const auto [coordinate, stiffness] =
      ParseSpringParameter(impl_->coordinates, impl_->machine, name, value);
  const int slot = impl_->coordinate_data[static_cast<size_t>(coordinate)].spring;
  if (stiffness) {
    impl_->ApplyStiffness(state, slot, coordinate, value);
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

const SimTK::MultibodySystem& MultibodyModel::system() const { return impl_->system; }

SimTK::State MultibodyModel::MakeState(const Eigen::VectorXd& q, const Eigen::VectorXd& u) const {
  const Eigen::Index n = static_cast<Eigen::Index>(impl_->coordinates.size());
  if (q.size() != n || u.size() != n) {
    throw std::invalid_argument("MultibodyModel::MakeState: q and u need one entry per coordinate");
  }
  SimTK::State s = impl_->MakeSpringState();
  s.setTime(0.0);
  s.updQ() = ToVector(q);
  s.updU() = ToVector(u);
  return s;
}

void MultibodyModel::SetExternalLoad(ExternalLoadFunction load) {
  impl_->external_load = std::move(load);
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
