// The model's dynamics: the state derivative without the Dynamics stage, the rest matrices, static
// equilibrium and the linearization.
#include <fmt/format.h>

#include <Eigen/Dense>
#include <cmath>
#include <functional>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "mbid/common/error.h"
#include "mbid/model/multibody_model.h"
#include "multibody_model_impl.h"

namespace mbid::model {
namespace {

using Force = std::function<Eigen::VectorXd(const Eigen::VectorXd&)>;
// The generalized force at q under the fraction s in [0, 1] of the load.
using LoadedForce = std::function<Eigen::VectorXd(const Eigen::VectorXd&, double)>;

// The tangent df/dq at q by central differences.
Eigen::MatrixXd Tangent(const Force& force, const Eigen::VectorXd& q) {
  const Eigen::Index n = q.size();
  Eigen::MatrixXd jacobian(n, n);
  const double h = 1e-7;  // rad or m; smooth forces, curvature scale ~1
  for (Eigen::Index j = 0; j < n; ++j) {
    Eigen::VectorXd dq = Eigen::VectorXd::Zero(n);
    dq[j] = h;
    jacobian.col(j) = (force(q + dq) - force(q - dq)) / (2 * h);
  }
  return jacobian;
}

// Converged when the step is at roundoff of q, or stops shrinking after being tiny.
bool StepConverged(double step_norm, double last_step, const Eigen::VectorXd& q) {
  return step_norm <= 4 * std::numeric_limits<double>::epsilon() * std::max(1.0, q.norm()) ||
         (step_norm < 1e-12 && step_norm >= last_step);
}

// Newton's chord method on f(q) = 0 from q = 0 with the tangent at rest (-C: no evaluations).
// Taken only where it contracts fast from the first step on (each step at most half the one
// before, the tangent never refreshed): then the root is the one nearest the unloaded rest. A
// payload that deflects the machine far (a luffed arm sagging 1.3 rad) made the chord overshoot
// into another root: flipped over the top, at an unstable one, or at none (50 iterations).
std::optional<Eigen::VectorXd> SolveByChord(const Force& force, const Eigen::MatrixXd& rest_tangent,
                                            const Eigen::VectorXd& f0) {
  const Eigen::FullPivLU<Eigen::MatrixXd> lu(rest_tangent);
  Eigen::VectorXd q = Eigen::VectorXd::Zero(rest_tangent.rows());
  Eigen::VectorXd f = f0;
  double last_step = std::numeric_limits<double>::infinity();
  for (int iteration = 0; iteration < 50; ++iteration) {
    const Eigen::VectorXd step = lu.solve(-f);
    const double step_norm = step.lpNorm<Eigen::Infinity>();
    if (!std::isfinite(step_norm) || step_norm > 0.5 * last_step + 1e-12) return std::nullopt;
    q += step;
    f = force(q);
    if (StepConverged(step_norm, last_step, q)) return q;
    last_step = step_norm;
  }
  return std::nullopt;
}

// The rest reached by applying the load gradually: the roots of loaded(q, s), the machine under
// the fraction s of its load (the rest of the payload's weight held by a hook, point loads
// scaled), followed from q = 0 at s = 0 to s = 1 by Newton with fresh tangents, each step of s
// halved until Newton converges without q moving more than 0.2 (rad or m) from the last root.
// Where the step must shrink below 1e-6, the load has no rest on this path (a fold: the machine
// snaps through).
Eigen::VectorXd SolveByContinuation(const LoadedForce& loaded, Eigen::Index n) {
  Eigen::VectorXd q = Eigen::VectorXd::Zero(n);
  double s = 0, ds = 0.125;
  while (s < 1) {
    const double next = std::min(1.0, s + ds);
    const Force force = [&](const Eigen::VectorXd& x) { return loaded(x, next); };
    const double scale = 1 + force(q).norm();
    Eigen::VectorXd x = q;
    bool converged = false;
    double last_step = std::numeric_limits<double>::infinity();
    for (int iteration = 0; iteration < 30 && !converged; ++iteration) {
      const Eigen::FullPivLU<Eigen::MatrixXd> lu(Tangent(force, x));
      if (!lu.isInvertible()) break;
      const Eigen::VectorXd step = lu.solve(-force(x));
      const double step_norm = step.lpNorm<Eigen::Infinity>();
      if (!std::isfinite(step_norm) || step_norm > 0.2) break;
      x += step;
      converged = StepConverged(step_norm, last_step, x) ||
                  (step_norm < 1e-10 && force(x).norm() <= 1e-9 * scale);
      last_step = step_norm;
    }
    if (converged && (x - q).lpNorm<Eigen::Infinity>() <= 0.2) {
      q = x;
      s = next;
      ds = std::min(0.25, 2 * ds);
    } else if ((ds *= 0.5) < 1e-6) {
      throw NumericalError(
          "static equilibrium",
          fmt::format("the load has no rest reached by applying it gradually: at {:.4g} % of it "
                      "the machine snaps through (a spring too weak for the load's overturning "
                      "moment)",
                      100 * s));
    }
  }
  return q;
}

// The static equilibrium loaded(q, 1) = 0 that loading the machine gradually from its unloaded
// rest q = 0 reaches; `rest_tangent` is d loaded / dq at q = 0 under the whole load.
Eigen::VectorXd SolveEquilibrium(const LoadedForce& loaded, const Eigen::MatrixXd& rest_tangent) {
  const Eigen::Index n = rest_tangent.rows();
  const Force force = [&](const Eigen::VectorXd& q) { return loaded(q, 1.0); };
  const Eigen::VectorXd f0 = force(Eigen::VectorXd::Zero(n));
  if (f0.lpNorm<Eigen::Infinity>() == 0) return Eigen::VectorXd::Zero(n);
  if (!Eigen::FullPivLU<Eigen::MatrixXd>(rest_tangent).isInvertible()) {
    throw NumericalError("static equilibrium",
                         "the machine has no stiffness against a load on a free coordinate");
  }
  // The chord's root stands where the machine is stable there (-K negative definite) and was at
  // q = 0: from a tangent that is not (a link raised 70 degrees under its payload) its first step
  // went the wrong way, to an unstable balance with the link tipped back (a re-audit's arm).
  const auto stable = [&](const Eigen::MatrixXd& tangent) {
    const Eigen::MatrixXd symmetric = 0.5 * (tangent + tangent.transpose());
    return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(symmetric).eigenvalues().maxCoeff() < 0;
  };
  if (stable(rest_tangent)) {
    if (std::optional<Eigen::VectorXd> q = SolveByChord(force, rest_tangent, f0)) {
      if (stable(Tangent(force, *q))) return *q;
    }
  }
  return SolveByContinuation(loaded, n);
}

}  // namespace

Eigen::MatrixXd MultibodyModel::Impl::CalcRestTangent(const Eigen::MatrixXd& K_g) const {
  Eigen::MatrixXd tangent = -K_g;
  for (Eigen::Index i = 0; i < tangent.rows(); ++i) {
    const SpringDescription* spring = machine.FindSpring(coordinates[static_cast<size_t>(i)]);
    if (spring != nullptr) tangent(i, i) -= spring->stiffness;
  }
  return tangent;
}

void MultibodyModel::Impl::CalcRestMatrices(RestMatrices& result) const {
  const Eigen::Index n = static_cast<Eigen::Index>(coordinates.size());
  result.q = Eigen::VectorXd::Zero(n);
  CalcMatricesAt(result);
  if (machine.attached_payload_kg == 0) return;
  // The springs carry the unloaded machine at q = 0; an attached payload's weight deflects it to
  // a rest of its own, where it vibrates: the matrices belong there.
  SimTK::State s = MakeSpringState();  // the preload carries the unloaded machine
  // Under a fraction of the payload, a hook holds the rest of its weight at its point.
  const Eigen::Vector3d weight(0, 0, -machine.attached_payload_kg * machine.gravity_mps2);
  result.q = SolveEquilibrium(
      [&](const Eigen::VectorXd& q, double fraction) {
        return CalcStaticForceAt(s, q, {{machine.payload_point, -(1 - fraction) * weight}});
      },
      CalcRestTangent(result.K_g));
  if (result.q.lpNorm<Eigen::Infinity>() > 0) CalcMatricesAt(result);
}

SimTK::State MultibodyModel::Impl::MakeStaticState() const {
  SimTK::State s = default_state;
  for (size_t k = 0; k < springs.size(); ++k) {
    springs[k].setStiffness(s, 0.0);
    dampers[k].setDamping(s, 0.0);
  }
  return s;
}

void MultibodyModel::Impl::CalcMatricesAt(RestMatrices& result) const {
  const Eigen::Index n = static_cast<Eigen::Index>(coordinates.size());
  const Eigen::VectorXd& q0 = result.q;
  // One scratch state with springs and dampers off serves every evaluation (a Simbody State
  // copy costs about four right-hand sides); M and H do not depend on the forces.
  SimTK::State s = MakeStaticState();
  for (Eigen::Index i = 0; i < n; ++i) s.updQ()[static_cast<int>(i)] = q0[i];
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
    return Eigen::VectorXd((gravity_force(q0 + dq) - gravity_force(q0 - dq)) / (2 * h));
  };
  Eigen::MatrixXd K_g(n, n);
  const double h = 1e-3;
  for (Eigen::Index j = 0; j < n; ++j) K_g.col(j) = -(4 * central(j, h / 2) - central(j, h)) / 3;
  result.K_g = 0.5 * (K_g + K_g.transpose());  // a Hessian: symmetric up to roundoff

  // H exactly: with q' = e_j at q = 0 every output's rate is its derivative by q_j; velocity
  // and acceleration outputs are J q' and J q'' at rest, the same Jacobian rows.
  result.H = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(outputs.size()), n);
  for (Eigen::Index i = 0; i < n; ++i) s.updQ()[static_cast<int>(i)] = q0[i];
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

// A Simbody vector's elements as an array (SimTK's element access is an out-of-line call in
// Debian's build); nullptr when empty.
template <typename V>
auto Elements(V& v) -> decltype(&v[0]) {
  if (v.size() == 0) return nullptr;
  if (!v.hasContiguousData()) throw std::logic_error("Simbody vector without contiguous data");
  return &v[0];
}

}  // namespace

namespace {

// The applied forces as Simbody's force elements sum them, for a state realized to Position
// (gravity) and Velocity (dampers).
struct AppliedForces {
  SimTK::Vector mobility;
  SimTK::Vector_<SimTK::SpatialVec> body;

  // M: MultibodyModel::Impl (private to the model, hence deduced).
  template <typename M>
  void Sum(const M& m, const SimTK::State& state) {
    mobility.resize(state.getNU());
    mobility = 0;
    body.resize(m.matter.getNumBodies());
    body = SimTK::SpatialVec(Vec3(0), Vec3(0));
    // Force::UniformGravity: m g at the mass center, about the body origin, in Ground.
    for (const auto& w : m.weights) {
      const Vec3 r = m.matter.getMobilizedBody(w.body).getBodyRotation(state) * w.mass_center_B;
      body[w.body] += SimTK::SpatialVec(r % w.force_G, w.force_G);
    }
    // Force::MobilityLinearSpring and MobilityLinearDamper: -c (q - q_0) - d u on the mobility.
    const double* q = Elements(state.getQ());
    const double* u = Elements(state.getU());
    double* f = Elements(mobility);
    for (const auto& c : m.coordinate_data) {
      if (c.spring < 0) continue;
      const SimTK::Force::MobilityLinearSpring& spring = m.springs[static_cast<size_t>(c.spring)];
      f[c.u] += -spring.getStiffness(state) * (q[c.q] - spring.getQZero(state)) -
                m.dampers[static_cast<size_t>(c.spring)].getDamping(state) * u[c.u];
    }
    AddExternalLoads(m.matter, m.external_load, m.locate_point, state, body, mobility);
  }
};

}  // namespace

MechanicalModel::StateDerivative MultibodyModel::MakeStateDerivative() const {
  struct Scratch {
    AppliedForces applied;
    SimTK::Vector residual, u_dot;
    const SimTK::Vector no_accelerations;  // u' = 0 for the inverse dynamics, made once
  };
  auto scratch = std::make_shared<Scratch>();
  return [&m = *impl_, scratch](const SimTK::State& state, double* y_dot) {
    scratch->applied.Sum(m, state);
    // u' = M^-1 (f_applied - f_inertial): Simbody's forward-dynamics operator needs the Dynamics
    // stage, its inverse dynamics (residual = f_inertial - f_applied at u' = 0) and M^-1 only
    // Velocity. u' = -(M^-1 residual): M^-1's arithmetic is odd in its argument, bit for bit.
    m.matter.calcResidualForceIgnoringConstraints(state, scratch->applied.mobility,
                                                  scratch->applied.body, scratch->no_accelerations,
                                                  scratch->residual);
    m.matter.multiplyByMInv(state, scratch->residual, scratch->u_dot);
    const SimTK::Vector& q_dot = state.getQDot();
    const int nq = q_dot.size();
    const double* q_dot_data = Elements(q_dot);
    for (int i = 0; i < nq; ++i) y_dot[i] = q_dot_data[i];
    const double* u_dot = Elements(scratch->u_dot);
    for (int i = 0; i < scratch->u_dot.size(); ++i) y_dot[nq + i] = -u_dot[i];
  };
}

MechanicalModel::Residual MultibodyModel::MakeResidual() const {
  struct Scratch {
    AppliedForces applied;
    SimTK::Vector u_dot, residual;
  };
  auto scratch = std::make_shared<Scratch>();
  return [&m = *impl_, scratch](const SimTK::State& state, const double* u_dot, double* residual) {
    scratch->applied.Sum(m, state);
    const int nu = state.getNU();
    scratch->u_dot.resize(nu);
    double* u_dot_data = Elements(scratch->u_dot);
    for (int i = 0; i < nu; ++i) u_dot_data[i] = u_dot[i];
    m.matter.calcResidualForceIgnoringConstraints(
        state, scratch->applied.mobility, scratch->applied.body, scratch->u_dot, scratch->residual);
    const double* r = Elements(scratch->residual);
    for (int i = 0; i < nu; ++i) residual[i] = r[i];
  };
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
  const Eigen::Index n = static_cast<Eigen::Index>(impl_->coordinates.size());
  SimTK::State s = MakeState(Eigen::VectorXd::Zero(n), Eigen::VectorXd::Zero(n));
  return SolveEquilibrium(
      [&](const Eigen::VectorXd& q, double fraction) {
        std::vector<PointLoad> part = loads;
        for (PointLoad& load : part) load.force_G *= fraction;
        if (impl_->machine.attached_payload_kg > 0) {  // a hook holds the rest of its weight
          part.push_back({impl_->machine.payload_point,
                          Eigen::Vector3d(0, 0,
                                          (1 - fraction) * impl_->machine.attached_payload_kg *
                                              impl_->machine.gravity_mps2)});
        }
        return impl_->CalcStaticForceAt(s, q, part);
      },
      impl_->CalcRestTangent(impl_->rest_matrices().K_g));
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

}  // namespace mbid::model
