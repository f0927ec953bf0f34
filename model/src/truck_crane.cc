#include "mbid/model/truck_crane.h"

#include <Eigen/Dense>
#include <cmath>
#include <limits>
#include <mutex>
#include <optional>

#include "external_load_force.h"
#include "mbid/common/error.h"
#include "mbid/model/simbody.h"
#include "mbid/model/simbody_conversions.h"

namespace mbid::model {
namespace {

using SimTK::Inertia;
using SimTK::MassProperties;
using SimTK::MobilizedBody;
using SimTK::Rotation;
using SimTK::Transform;
using SimTK::Vec3;

const std::vector<std::string> kCoordinates{"alpha", "gamma", "eta", "theta"};
const std::vector<std::string> kOutputs{"psi", "phi"};
const std::vector<std::string> kOutputUnits{"rad", "rad"};
constexpr int kDofs = 4;

// Maps the Universal mobilizer's (x, then new y) axes onto the boom joint axes: F's x along S's
// z (eta) and F's y along -y (theta > 0 lifts the tip). Columns: P e_x = e_z, P e_y = -e_y.
Rotation CalcUniversalAxes() {
  SimTK::Mat33 p(0, 0, 1,   //
                 0, -1, 0,  //
                 1, 0, 0);
  return Rotation(p, true);
}

double WrapToPi(double angle_rad) { return std::remainder(angle_rad, 2.0 * M_PI); }

}  // namespace

struct TruckCrane::Impl {
  explicit Impl(const TruckCraneParameters& p) : parameters(p), matter(system), forces(system) {
    parameters.Validate();
    const Vec3 gravity_G(0, 0, -parameters.gravity_mps2);
    SimTK::Force::UniformGravity(forces, matter, gravity_G);

    // B: body frame coincides with G at alpha = 0, so data given "in G at alpha = 0" are body
    // coordinates. The pin turns about its frames' z axis, rotated onto G's y.
    const Rotation R_GF_pitch(-M_PI / 2, SimTK::XAxis);
    const Vec3 p_GOa = ToVec3(parameters.p_GOa_m);
    const MassProperties base_mass(
        parameters.base_mass_kg, ToVec3(parameters.p_GBcm_m),
        Inertia(ToVec3(parameters.base_inertia_kgm2))
            .shiftFromMassCenter(ToVec3(parameters.p_GBcm_m), parameters.base_mass_kg));
    base = MobilizedBody::Pin(matter.Ground(), Transform(R_GF_pitch, p_GOa),
                              SimTK::Body::Rigid(base_mass), Transform(R_GF_pitch, p_GOa));

    // S: origin at O_s, x axis along the boom's horizontal direction (slew psi0 + gamma).
    const Vec3 p_OsScm = ToVec3(parameters.p_OsScm_S_m);
    const MassProperties slewing_mass(
        parameters.slewing_mass_kg, p_OsScm,
        Inertia(ToVec3(parameters.slewing_inertia_kgm2))
            .shiftFromMassCenter(p_OsScm, parameters.slewing_mass_kg));
    slewing = MobilizedBody::Pin(
        base, Transform(Rotation(parameters.slew_rad, SimTK::ZAxis), ToVec3(parameters.p_GOs_m)),
        SimTK::Body::Rigid(slewing_mass), Transform());

    // K: origin at the foot F, x along the boom. R_K = R_S Rz(eta) Ry(-(phi0 + theta)).
    const double L = parameters.boom_length_m;
    const double m = parameters.boom_mass_kg;
    const Vec3 p_FKcm(L / 2, 0, 0);
    Inertia boom_inertia =
        Inertia(Vec3(parameters.boom_axial_inertia_kgm2, m * L * L / 12, m * L * L / 12))
            .shiftFromMassCenter(p_FKcm, m);
    MassProperties boom_mass(m, p_FKcm, boom_inertia);
    if (parameters.attached_payload_kg > 0) {
      const double mp = parameters.attached_payload_kg;
      const Vec3 p_FTip(L, 0, 0);
      boom_mass = MassProperties(m + mp, (m * p_FKcm + mp * p_FTip) / (m + mp),
                                 boom_inertia + Inertia::pointMassAt(p_FTip, mp));
    }
    const Rotation P = CalcUniversalAxes();
    boom = MobilizedBody::Universal(
        slewing, Transform(P, ToVec3(parameters.p_OsF_S_m)), SimTK::Body::Rigid(boom_mass),
        Transform(Rotation(parameters.boom_elevation_rad, SimTK::YAxis) * P, Vec3(0)));

    const std::array<std::pair<MobilizedBody*, int>, kDofs> joint_mobilities{
        {{&base, 0}, {&slewing, 0}, {&boom, 0}, {&boom, 1}}};
    for (int i = 0; i < kDofs; ++i) {
      auto [mobod, which] = joint_mobilities[i];
      springs[i] =
          SimTK::Force::MobilityLinearSpring(forces, *mobod, SimTK::MobilizerUIndex(which),
                                             parameters.joints[i].stiffness_Nm_per_rad, 0.0);
      dampers[i] = SimTK::Force::MobilityLinearDamper(forces, *mobod, SimTK::MobilizerUIndex(which),
                                                      parameters.joints[i].damping_Nms_per_rad);
    }
    SimTK::Force::Custom(
        forces, new ExternalLoadForce(matter, external_load, [this](const std::string& point) {
          return std::make_pair(FindLoadBody(point).getMobilizedBodyIndex(),
                                FindLoadStation(point));
        }));

    system.realizeTopology();
    default_state = system.getDefaultState();
    system.realizeModel(default_state);
    if (default_state.getNQ() != kDofs || default_state.getNU() != kDofs) {
      throw std::logic_error("TruckCrane: expected 4 coordinates and speeds");
    }
    unloaded_gravity_force = CalcUnloadedGravityForce();
  }

  // Gravity's generalized force at q = 0 on the crane without the attached payload: the dead
  // weight the springs carry (the preload rule).
  Eigen::Vector4d CalcUnloadedGravityForce() const {
    SimTK::State s = default_state;
    for (int i = 0; i < kDofs; ++i) {
      springs[i].setStiffness(s, 0.0);
      dampers[i].setDamping(s, 0.0);
    }
    // Everything at rest minus the attached payload's weight.
    const double payload_weight_N = parameters.attached_payload_kg * parameters.gravity_mps2;
    return CalcStaticForceAt(s, Eigen::VectorXd::Zero(kDofs),
                             {{"boom_tip", Eigen::Vector3d(0, 0, payload_weight_N)}});
  }

  // The generalized force at rest at q, M(q) u' with u = 0 (velocity terms vanish), computed on
  // `scratch` (a state carrying the parameters; its q and u are overwritten): springs, gravity
  // and the point loads.
  Eigen::VectorXd CalcStaticForceAt(SimTK::State& scratch, const Eigen::VectorXd& q,
                                    const std::vector<PointLoad>& loads) const {
    scratch.updQ() = ToVector(q);
    scratch.updU() = 0;
    system.realize(scratch, SimTK::Stage::Acceleration);
    SimTK::Vector m_udot;
    matter.multiplyByM(scratch, scratch.getUDot(), m_udot);
    Eigen::VectorXd force = ToEigen(m_udot);
    for (const PointLoad& load : loads) force += CalcPointLoadForce(scratch, load);
    return force;
  }

  Eigen::VectorXd CalcPointLoadForce(const SimTK::State& s, const PointLoad& load) const {
    if (load.force_G.isZero(0.0)) return Eigen::VectorXd::Zero(kDofs);
    system.realize(s, SimTK::Stage::Position);
    SimTK::Vector f;
    matter.multiplyByStationJacobianTranspose(s, FindLoadBody(load.point),
                                              FindLoadStation(load.point), ToVec3(load.force_G), f);
    return ToEigen(f);
  }

  const MobilizedBody& FindLoadBody(const std::string& point) const {
    if (point == "boom_tip") return boom;
    throw InputError("model", "load point", "unknown point '" + point + "'", "boom_tip");
  }
  Vec3 FindLoadStation(const std::string& point) const {
    FindLoadBody(point);
    return Vec3(parameters.boom_length_m, 0, 0);
  }

  TruckCraneParameters parameters;
  SimTK::MultibodySystem system;
  SimTK::SimbodyMatterSubsystem matter;
  SimTK::GeneralForceSubsystem forces;
  MobilizedBody::Pin base;
  MobilizedBody::Pin slewing;
  MobilizedBody::Universal boom;
  std::array<SimTK::Force::MobilityLinearSpring, kDofs> springs;
  std::array<SimTK::Force::MobilityLinearDamper, kDofs> dampers;
  MechanicalModel::ExternalLoadFunction external_load;
  SimTK::State default_state;
  Eigen::Vector4d unloaded_gravity_force;

  // M, the geometric stiffness K_g and H at q = 0 depend on the inertial data and the
  // configuration, not on c and d: computed once (Linearize serves every simulation, sensitivity
  // run and mode table; they cost about 30 right-hand sides), thread-safe for const use.
  struct RestMatrices {
    Eigen::MatrixXd M, K_g, H;
  };
  const RestMatrices& rest_matrices() const {
    std::call_once(rest_once, [this] { rest = CalcRestMatrices(); });
    return rest;
  }
  RestMatrices CalcRestMatrices() const;
  mutable std::once_flag rest_once;
  mutable RestMatrices rest;
};

TruckCrane::TruckCrane(const TruckCraneParameters& parameters)
    : impl_(std::make_unique<Impl>(parameters)) {}

TruckCrane::~TruckCrane() = default;

const TruckCraneParameters& TruckCrane::crane_parameters() const { return impl_->parameters; }
const std::vector<std::string>& TruckCrane::coordinate_names() const { return kCoordinates; }
const std::vector<std::string>& TruckCrane::output_names() const { return kOutputs; }
const std::vector<std::string>& TruckCrane::output_units() const { return kOutputUnits; }
std::vector<std::string> TruckCrane::load_points() const { return {"boom_tip"}; }

std::vector<PointLoad> TruckCrane::CalcPayloadLoads(double mass_kg) const {
  return {{"boom_tip", Eigen::Vector3d(0, 0, -mass_kg * impl_->parameters.gravity_mps2)}};
}

std::vector<Parameter> TruckCrane::parameters() const {
  std::vector<Parameter> result;
  const double inf = std::numeric_limits<double>::infinity();
  for (int i = 0; i < kDofs; ++i) {
    result.push_back({"c_" + kCoordinates[i], "N*m/rad",
                      impl_->parameters.joints[i].stiffness_Nm_per_rad, 0.0, inf});
  }
  for (int i = 0; i < kDofs; ++i) {
    result.push_back({"d_" + kCoordinates[i], "N*m*s/rad",
                      impl_->parameters.joints[i].damping_Nms_per_rad, 0.0, inf});
  }
  return result;
}

namespace {

// Which joint and which coefficient `name` ("c_alpha", "d_theta") names; throws if none.
std::pair<int, bool> ParseJointParameter(const std::string& name, double value) {
  for (int i = 0; i < kDofs; ++i) {
    const bool stiffness = name == "c_" + kCoordinates[i];
    if (!stiffness && name != "d_" + kCoordinates[i]) continue;
    if (stiffness && !(std::isfinite(value) && value > 0)) {
      throw InputError("model", name, "stiffness " + std::to_string(value),
                       "a positive finite value in N*m/rad");
    }
    if (!stiffness && !(std::isfinite(value) && value >= 0)) {
      throw InputError("model", name, "damping " + std::to_string(value),
                       "a non-negative finite value in N*m*s/rad");
    }
    return {i, stiffness};
  }
  throw InputError("model", name, "unknown parameter",
                   "c_<joint> or d_<joint> with joint in alpha, gamma, eta, theta");
}

}  // namespace

void TruckCrane::SetParameter(const std::string& name, double value) {
  const auto [joint, stiffness] = ParseJointParameter(name, value);
  if (stiffness) {
    impl_->parameters.joints[joint].stiffness_Nm_per_rad = value;
  } else {
    impl_->parameters.joints[joint].damping_Nms_per_rad = value;
  }
}

void TruckCrane::ApplyParameterToState(SimTK::State& state, const std::string& name,
                                       double value) const {
  const auto [joint, stiffness] = ParseJointParameter(name, value);
  if (stiffness) {
    impl_->springs[joint].setStiffness(state, value);
    // The preload rule holds for every stiffness: the unloaded crane rests at q = 0.
    impl_->springs[joint].setQZero(state, -impl_->unloaded_gravity_force[joint] / value);
  } else {
    impl_->dampers[joint].setDamping(state, value);
  }
}

const SimTK::MultibodySystem& TruckCrane::system() const { return impl_->system; }

SimTK::State TruckCrane::MakeState(const Eigen::VectorXd& q, const Eigen::VectorXd& u) const {
  if (q.size() != kDofs || u.size() != kDofs) {
    throw std::invalid_argument("TruckCrane::MakeState: q and u need 4 entries");
  }
  SimTK::State s = impl_->default_state;
  for (int i = 0; i < kDofs; ++i) {
    ApplyParameterToState(s, "c_" + kCoordinates[i],
                          impl_->parameters.joints[i].stiffness_Nm_per_rad);
    ApplyParameterToState(s, "d_" + kCoordinates[i],
                          impl_->parameters.joints[i].damping_Nms_per_rad);
  }
  s.setTime(0.0);
  s.updQ() = ToVector(q);
  s.updU() = ToVector(u);
  return s;
}

void TruckCrane::SetExternalLoad(ExternalLoadFunction load) {
  impl_->external_load = std::move(load);
}

Eigen::VectorXd TruckCrane::CalcOutputs(const SimTK::State& state) const {
  // The boom axis u = R_K e_x in closed form from reference-crane.md's kinematics,
  // R_K = Ry(alpha) Rz(psi0 + gamma + eta) Ry(-(phi0 + theta)), rather than from Simbody's
  // realized body rotation (equal to roundoff, tests/model/truck_crane_test.cc): outputs are
  // read at every sample and in every output-Jacobian quotient, and a Position realization
  // costs a third of a right-hand side.
  const TruckCraneParameters& p = impl_->parameters;
  const SimTK::Vector& q = state.getQ();
  const double azimuth_rad = p.slew_rad + q[1] + q[2];
  const double elevation_rad = p.boom_elevation_rad + q[3];
  const Vec3 u_S(std::cos(elevation_rad) * std::cos(azimuth_rad),
                 std::cos(elevation_rad) * std::sin(azimuth_rad), std::sin(elevation_rad));
  const double c_alpha = std::cos(q[0]), s_alpha = std::sin(q[0]);
  const Vec3 u_G(c_alpha * u_S[0] + s_alpha * u_S[2], u_S[1], -s_alpha * u_S[0] + c_alpha * u_S[2]);
  Eigen::VectorXd y(2);
  y[0] = WrapToPi(std::atan2(u_G[1], u_G[0]) - p.slew_rad);
  y[1] = std::atan2(u_G[2], std::hypot(u_G[0], u_G[1])) - p.boom_elevation_rad;
  return y;
}

double TruckCrane::CalcEnergy(const SimTK::State& state) const {
  impl_->system.realize(state, SimTK::Stage::Dynamics);
  return impl_->system.calcEnergy(state);
}

Eigen::VectorXd TruckCrane::CalcStaticGeneralizedForce(const Eigen::VectorXd& q,
                                                       const std::vector<PointLoad>& loads) const {
  SimTK::State s = MakeState(q, Eigen::VectorXd::Zero(kDofs));
  return impl_->CalcStaticForceAt(s, q, loads);
}

Eigen::VectorXd TruckCrane::SolveStaticEquilibrium(const std::vector<PointLoad>& loads) const {
  // Newton's chord method on f(q) = 0: the tangent df/dq starts as the unloaded crane's -C at
  // rest (springs plus the cached geometric stiffness: no evaluations), kept while the steps
  // shrink fast (the loads are small against the springs, so the tangent hardly changes) and
  // refreshed by central differences when they do not. The root's accuracy depends only on f,
  // so the iteration reaches machine precision. One scratch state serves every evaluation.
  SimTK::State s = MakeState(Eigen::VectorXd::Zero(kDofs), Eigen::VectorXd::Zero(kDofs));
  auto force = [&](const Eigen::VectorXd& q) { return impl_->CalcStaticForceAt(s, q, loads); };
  auto tangent = [&](const Eigen::VectorXd& q) {
    Eigen::Matrix4d jacobian;
    const double h = 1e-7;  // rad; smooth forces, curvature scale ~1 rad
    for (int j = 0; j < kDofs; ++j) {
      Eigen::VectorXd dq = Eigen::VectorXd::Zero(kDofs);
      dq[j] = h;
      jacobian.col(j) = (force(q + dq) - force(q - dq)) / (2 * h);
    }
    return Eigen::PartialPivLU<Eigen::Matrix4d>(jacobian);
  };
  Eigen::VectorXd q = Eigen::VectorXd::Zero(kDofs);
  Eigen::VectorXd f = force(q);
  Eigen::Matrix4d rest_tangent = -impl_->rest_matrices().K_g;
  for (int i = 0; i < kDofs; ++i) {
    rest_tangent(i, i) -= impl_->parameters.joints[i].stiffness_Nm_per_rad;
  }
  Eigen::PartialPivLU<Eigen::Matrix4d> lu(rest_tangent);
  double last_step = std::numeric_limits<double>::infinity();
  for (int iteration = 0; iteration < 50; ++iteration) {
    const Eigen::VectorXd step = lu.solve(-f);
    q += step;
    f = force(q);
    const double step_norm = step.lpNorm<Eigen::Infinity>();
    // Converged when the step is at roundoff of q, or stops shrinking after being tiny.
    if (step_norm <= 4 * std::numeric_limits<double>::epsilon() * std::max(1.0, q.norm()) ||
        (step_norm < 1e-12 && step_norm >= last_step)) {
      return q;
    }
    if (step_norm > 0.1 * last_step) lu = tangent(q);  // slow contraction: refresh the tangent
    last_step = step_norm;
  }
  throw NumericalError("static equilibrium", "Newton did not converge in 50 iterations; residual " +
                                                 std::to_string(f.norm()) + " N*m");
}

TruckCrane::Impl::RestMatrices TruckCrane::Impl::CalcRestMatrices() const {
  RestMatrices result;
  // One scratch state at q = 0 with springs and dampers off serves every evaluation (a Simbody
  // State copy costs about four right-hand sides); M and H do not depend on the forces.
  SimTK::State s = default_state;
  for (int i = 0; i < kDofs; ++i) {
    springs[i].setStiffness(s, 0.0);
    dampers[i].setDamping(s, 0.0);
  }
  s.updQ() = 0;
  s.updU() = 0;
  system.realize(s, SimTK::Stage::Position);
  SimTK::Matrix M;
  matter.calcM(s, M);
  result.M = ToEigen(M);
  const Vec3 u = boom.getBodyRotation(s).x();  // the boom axis at rest, for H below

  // Geometric stiffness K_g = -d(gravity force)/dq by central differences with one Richardson
  // step: error O(h^4) ~ 1e-16 of the gravity torque.
  auto gravity_force = [&](const Eigen::VectorXd& q) { return CalcStaticForceAt(s, q, {}); };
  auto central = [&](int j, double h) {
    Eigen::VectorXd dq = Eigen::VectorXd::Zero(kDofs);
    dq[j] = h;
    return Eigen::VectorXd((gravity_force(dq) - gravity_force(-dq)) / (2 * h));
  };
  Eigen::MatrixXd K_g(kDofs, kDofs);
  const double h = 1e-3;  // rad; Richardson removes the h^2 term, h^4 ~ 1e-12 relative
  for (int j = 0; j < kDofs; ++j) {
    K_g.col(j) = -(4 * central(j, h / 2) - central(j, h)) / 3;
  }
  result.K_g = 0.5 * (K_g + K_g.transpose());  // a Hessian: symmetric up to roundoff

  // H exactly: a unit speed of coordinate j turns the boom axis u at w_GK, du = w x u, and
  // psi = atan2(u_y, u_x), phi = atan2(u_z, |u_xy|) differentiate in closed form.
  result.H.resize(2, kDofs);
  const double rho2 = u[0] * u[0] + u[1] * u[1];
  const double rho = std::sqrt(rho2);
  s.updQ() = 0;
  for (int j = 0; j < kDofs; ++j) {
    s.updU() = 0;
    s.updU()[j] = 1;
    system.realize(s, SimTK::Stage::Velocity);
    const Vec3 du = boom.getBodyAngularVelocity(s) % u;
    result.H(0, j) = (u[0] * du[1] - u[1] * du[0]) / rho2;
    result.H(1, j) = (rho2 * du[2] - u[2] * (u[0] * du[0] + u[1] * du[1])) / rho;
  }
  return result;
}

LinearModel TruckCrane::Linearize() const {
  const Impl::RestMatrices& rest = impl_->rest_matrices();
  LinearModel linear;
  linear.coordinates = kCoordinates;
  linear.outputs = kOutputs;
  linear.M = rest.M;
  linear.H = rest.H;
  linear.C = rest.K_g;
  linear.D = Eigen::MatrixXd::Zero(kDofs, kDofs);
  for (int i = 0; i < kDofs; ++i) {
    linear.C(i, i) += impl_->parameters.joints[i].stiffness_Nm_per_rad;
    // Dampers are the only velocity-dependent forces; gyroscopic terms are quadratic in u.
    linear.D(i, i) = impl_->parameters.joints[i].damping_Nms_per_rad;
  }
  return linear;
}

std::unique_ptr<MechanicalModel> TruckCrane::Clone() const {
  return std::make_unique<TruckCrane>(impl_->parameters);
}

Eigen::Vector4d TruckCrane::neutral_angles() const {
  Eigen::Vector4d q0;
  for (int i = 0; i < kDofs; ++i) {
    q0[i] = -impl_->unloaded_gravity_force[i] / impl_->parameters.joints[i].stiffness_Nm_per_rad;
  }
  return q0;
}

}  // namespace mbid::model
