#include "mbid/model/torsional_oscillator.h"

#include <cmath>
#include <limits>

#include "external_load_force.h"
#include "mbid/common/error.h"
#include "mbid/model/simbody.h"
#include "mbid/model/simbody_conversions.h"

namespace mbid::model {
namespace {

const std::vector<std::string> kCoordinates{"angle"};
const std::vector<std::string> kUnits{"rad"};
const SimTK::Vec3 kRim(1, 0, 0);  // m, in the body frame

void CheckParameter(const std::string& name, double value) {
  if (name == "c_angle" && !(std::isfinite(value) && value > 0)) {
    throw InputError("model", name, "stiffness " + std::to_string(value),
                     "a positive finite value in N*m/rad");
  }
  if (name == "d_angle" && !(std::isfinite(value) && value >= 0)) {
    throw InputError("model", name, "damping " + std::to_string(value),
                     "a non-negative finite value in N*m*s/rad");
  }
  if (name != "c_angle" && name != "d_angle") {
    throw InputError("model", name, "unknown parameter", "c_angle or d_angle");
  }
}

}  // namespace

void TorsionalOscillatorParameters::Validate() const {
  if (!(std::isfinite(inertia_kgm2) && inertia_kgm2 > 0)) {
    throw InputError("model parameters", "inertia_kgm2", "value " + std::to_string(inertia_kgm2),
                     "a positive finite inertia in kg*m^2");
  }
  CheckParameter("c_angle", stiffness_Nm_per_rad);
  CheckParameter("d_angle", damping_Nms_per_rad);
}

struct TorsionalOscillator::Impl {
  explicit Impl(const TorsionalOscillatorParameters& p)
      : parameters(p), matter(system), forces(system) {
    parameters.Validate();
    // A disc about its z axis with moment J; the other moments only keep the inertia valid.
    const double J = parameters.inertia_kgm2;
    body = SimTK::MobilizedBody::Pin(matter.Ground(), SimTK::Transform(),
                                     SimTK::Body::Rigid(SimTK::MassProperties(
                                         1.0, SimTK::Vec3(0), SimTK::Inertia(J / 2, J / 2, J))),
                                     SimTK::Transform());
    spring = SimTK::Force::MobilityLinearSpring(forces, body, SimTK::MobilizerQIndex(0),
                                                parameters.stiffness_Nm_per_rad, 0.0);
    damper = SimTK::Force::MobilityLinearDamper(forces, body, SimTK::MobilizerUIndex(0),
                                                parameters.damping_Nms_per_rad);
    SimTK::Force::Custom(forces,
                         new ExternalLoadForce(matter, external_load, [this](const std::string&) {
                           return std::make_pair(body.getMobilizedBodyIndex(), kRim);
                         }));
    system.realizeTopology();
    default_state = system.getDefaultState();
    system.realizeModel(default_state);
  }

  TorsionalOscillatorParameters parameters;
  SimTK::MultibodySystem system;
  SimTK::SimbodyMatterSubsystem matter;
  SimTK::GeneralForceSubsystem forces;
  SimTK::MobilizedBody::Pin body;
  SimTK::Force::MobilityLinearSpring spring;
  SimTK::Force::MobilityLinearDamper damper;
  MechanicalModel::ExternalLoadFunction external_load;
  SimTK::State default_state;
};

TorsionalOscillator::TorsionalOscillator(const TorsionalOscillatorParameters& parameters)
    : impl_(std::make_unique<Impl>(parameters)) {}
TorsionalOscillator::~TorsionalOscillator() = default;

const std::vector<std::string>& TorsionalOscillator::coordinate_names() const {
  return kCoordinates;
}
const std::vector<std::string>& TorsionalOscillator::output_names() const { return kCoordinates; }
const std::vector<std::string>& TorsionalOscillator::output_units() const { return kUnits; }
std::vector<std::string> TorsionalOscillator::load_points() const { return {"rim"}; }

std::vector<PointLoad> TorsionalOscillator::CalcPayloadLoads(double /*mass_kg*/) const {
  // No gravity: a payload has no static effect on a horizontal rotor.
  return {};
}

std::vector<Parameter> TorsionalOscillator::parameters() const {
  const double inf = std::numeric_limits<double>::infinity();
  return {{"c_angle", "N*m/rad", impl_->parameters.stiffness_Nm_per_rad, 0.0, inf},
          {"d_angle", "N*m*s/rad", impl_->parameters.damping_Nms_per_rad, 0.0, inf}};
}

void TorsionalOscillator::SetParameter(const std::string& name, double value) {
  CheckParameter(name, value);
  (name == "c_angle" ? impl_->parameters.stiffness_Nm_per_rad
                     : impl_->parameters.damping_Nms_per_rad) = value;
}

void TorsionalOscillator::ApplyParameterToState(SimTK::State& state, const std::string& name,
                                                double value) const {
  CheckParameter(name, value);
  if (name == "c_angle") {
    impl_->spring.setStiffness(state, value);
  } else {
    impl_->damper.setDamping(state, value);
  }
}

const SimTK::MultibodySystem& TorsionalOscillator::system() const { return impl_->system; }

SimTK::State TorsionalOscillator::MakeState(const Eigen::VectorXd& q,
                                            const Eigen::VectorXd& u) const {
  if (q.size() != 1 || u.size() != 1) {
    throw std::invalid_argument("TorsionalOscillator::MakeState: q and u need 1 entry");
  }
  SimTK::State s = impl_->default_state;
  ApplyParameterToState(s, "c_angle", impl_->parameters.stiffness_Nm_per_rad);
  ApplyParameterToState(s, "d_angle", impl_->parameters.damping_Nms_per_rad);
  s.setTime(0.0);
  s.updQ() = ToVector(q);
  s.updU() = ToVector(u);
  return s;
}

void TorsionalOscillator::SetExternalLoad(ExternalLoadFunction load) {
  impl_->external_load = std::move(load);
}

Eigen::VectorXd TorsionalOscillator::CalcOutputs(const SimTK::State& state) const {
  return Eigen::VectorXd::Constant(1, state.getQ()[0]);
}

double TorsionalOscillator::CalcEnergy(const SimTK::State& state) const {
  impl_->system.realize(state, SimTK::Stage::Dynamics);
  return impl_->system.calcEnergy(state);
}

Eigen::VectorXd TorsionalOscillator::SolveStaticEquilibrium(
    const std::vector<PointLoad>& loads) const {
  // c theta = torque of the rim loads, (R(theta) r) x F about z = F_y cos theta - F_x sin theta.
  // Newton from the linear guess; the residual is exact, so it converges to roundoff.
  Eigen::Vector3d force = Eigen::Vector3d::Zero();
  for (const PointLoad& load : loads) force += load.force_G;
  const double c = impl_->parameters.stiffness_Nm_per_rad;
  double theta = force[1] / c;
  for (int iteration = 0; iteration < 50; ++iteration) {
    const double residual = c * theta - (force[1] * std::cos(theta) - force[0] * std::sin(theta));
    const double slope = c + force[1] * std::sin(theta) + force[0] * std::cos(theta);
    const double step = -residual / slope;
    theta += step;
    if (std::abs(step) <=
        4 * std::numeric_limits<double>::epsilon() * std::max(1.0, std::abs(theta))) {
      return Eigen::VectorXd::Constant(1, theta);
    }
  }
  throw NumericalError("static equilibrium", "Newton did not converge for the rim load");
}

LinearModel TorsionalOscillator::Linearize() const {
  LinearModel linear;
  linear.coordinates = kCoordinates;
  linear.outputs = kCoordinates;
  SimTK::State s = MakeState(Eigen::VectorXd::Zero(1), Eigen::VectorXd::Zero(1));
  impl_->system.realize(s, SimTK::Stage::Position);
  SimTK::Matrix M;
  impl_->matter.calcM(s, M);
  linear.M = ToEigen(M);  // Simbody's, so that tests compare it with J
  linear.C = Eigen::MatrixXd::Constant(1, 1, impl_->parameters.stiffness_Nm_per_rad);
  linear.D = Eigen::MatrixXd::Constant(1, 1, impl_->parameters.damping_Nms_per_rad);
  linear.H = Eigen::MatrixXd::Identity(1, 1);
  return linear;
}

std::unique_ptr<MechanicalModel> TorsionalOscillator::Clone() const {
  return std::make_unique<TorsionalOscillator>(impl_->parameters);
}

}  // namespace mbid::model
