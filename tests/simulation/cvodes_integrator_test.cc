#include "mbid/simulation/cvodes_integrator.h"

#include <Simbody.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include "mbid/common/error.h"

namespace mbid::simulation {
namespace {

using Method = IntegratorOptions::Method;

// Two 1 kg point-like bobs on 1 m massless-looking links (Pin joints about z, gravity -y),
// optionally with a torsional spring and damper in the upper joint.
struct DoublePendulum {
  static constexpr double kLength = 1.0;

  explicit DoublePendulum(bool with_spring_damper) {
    SimTK::Force::Gravity(forces, matter, -SimTK::YAxis, 9.81);
    const SimTK::Body::Rigid bob(
        SimTK::MassProperties(1.0, SimTK::Vec3(0), SimTK::Inertia(0.01, 0.01, 0.01)));
    const SimTK::Transform X_BM(SimTK::Vec3(0, kLength, 0));
    upper = SimTK::MobilizedBody::Pin(matter.Ground(), SimTK::Transform(), bob, X_BM);
    lower = SimTK::MobilizedBody::Pin(upper, SimTK::Transform(), bob, X_BM);
    if (with_spring_damper) {
      SimTK::Force::MobilityLinearSpring(forces, upper, SimTK::MobilizerQIndex(0), 20.0, 0.0);
      SimTK::Force::MobilityLinearDamper(forces, upper, SimTK::MobilizerUIndex(0), 0.5);
    }
    system.realizeTopology();
  }

  SimTK::State MakeState() const {
    SimTK::State state = system.getDefaultState();
    upper.setOneQ(state, SimTK::MobilizerQIndex(0), 0.3);
    lower.setOneQ(state, SimTK::MobilizerQIndex(0), -0.2);
    upper.setOneU(state, SimTK::MobilizerUIndex(0), 0.2);
    return state;
  }

  SimTK::MultibodySystem system;
  SimTK::SimbodyMatterSubsystem matter{system};
  SimTK::GeneralForceSubsystem forces{system};
  SimTK::MobilizedBody::Pin upper;
  SimTK::MobilizedBody::Pin lower;
};

// A rigid body on one Pin joint (axis z, no gravity) with a torsional spring c and damper d:
//   I theta'' + d theta' + c theta = T,  T from a DiscreteForces element (0 by default).
struct TorsionalPendulum {
  TorsionalPendulum(double inertia_zz, double stiffness_c, double damping_d)
      : inertia(inertia_zz), stiffness(stiffness_c), damping(damping_d) {
    const SimTK::Body::Rigid body(
        SimTK::MassProperties(3.0, SimTK::Vec3(0), SimTK::Inertia(1.0, 1.0, inertia)));
    pin = SimTK::MobilizedBody::Pin(matter.Ground(), SimTK::Transform(), body, SimTK::Transform());
    SimTK::Force::MobilityLinearSpring(forces, pin, SimTK::MobilizerQIndex(0), stiffness, 0.0);
    SimTK::Force::MobilityLinearDamper(forces, pin, SimTK::MobilizerUIndex(0), damping);
    discrete = SimTK::Force::DiscreteForces(forces, matter);
    system.realizeTopology();
  }

  SimTK::State MakeState(double theta0, double omega0) const {
    SimTK::State state = system.getDefaultState();
    pin.setOneQ(state, SimTK::MobilizerQIndex(0), theta0);
    pin.setOneU(state, SimTK::MobilizerUIndex(0), omega0);
    return state;
  }

  // The underdamped free response (zeta < 1) from theta0, omega0.
  double ExactTheta(double t, double theta0, double omega0) const {
    const double omega_n = std::sqrt(stiffness / inertia);
    const double zeta = damping / (2.0 * std::sqrt(stiffness * inertia));
    const double omega_d = omega_n * std::sqrt(1.0 - zeta * zeta);
    const double sigma = zeta * omega_n;
    return std::exp(-sigma * t) * (theta0 * std::cos(omega_d * t) +
                                   (omega0 + sigma * theta0) / omega_d * std::sin(omega_d * t));
  }

  double inertia, stiffness, damping;
  SimTK::MultibodySystem system;
  SimTK::SimbodyMatterSubsystem matter{system};
  SimTK::GeneralForceSubsystem forces{system};
  SimTK::MobilizedBody::Pin pin;
  SimTK::Force::DiscreteForces discrete;
};

IntegratorOptions Options(Method method, double rtol, double atol) {
  IntegratorOptions options;
  options.method = method;
  options.relative_tolerance = rtol;
  options.absolute_tolerance = atol;
  return options;
}

std::vector<double> SampleTimes(double t_end, int count) {
  std::vector<double> times;
  for (int i = 1; i <= count; ++i) times.push_back(t_end * i / count);
  return times;
}

using Trajectory = std::vector<SimTK::Vector>;  // Y at each sample time

Trajectory RunCvodes(const SimTK::System& system, const SimTK::State& initial,
                     const IntegratorOptions& options, const std::vector<double>& times) {
  CvodesIntegrator integrator(system, options);
  integrator.Initialize(initial);
  Trajectory trajectory;
  for (double t : times) trajectory.push_back(integrator.AdvanceTo(t).getY());
  return trajectory;
}

Trajectory RunSimbody(const SimTK::System& system, SimTK::Integrator& integrator,
                      const SimTK::State& initial, const std::vector<double>& times) {
  integrator.setAccuracy(1e-10);
  SimTK::TimeStepper stepper(system, integrator);
  stepper.initialize(initial);
  Trajectory trajectory;
  for (double t : times) {
    stepper.stepTo(t);
    EXPECT_DOUBLE_EQ(integrator.getState().getTime(), t);
    trajectory.push_back(integrator.getState().getY());
  }
  return trajectory;
}

double MaxDifference(const Trajectory& a, const Trajectory& b) {
  double max_difference = 0.0;
  for (size_t i = 0; i < a.size(); ++i) {
    max_difference = std::max(max_difference, SimTK::max(SimTK::abs(a[i] - b[i])));
  }
  return max_difference;
}

// The toolchain trap (docs/toolchain.md, trap 1): CVODES and Simbody's CPodes carry
// same-named N_V* symbols. Both must run correctly in this one binary.
TEST(CvodesIntegratorTest, AgreesWithSimbodyIntegratorsInOneBinary) {
  DoublePendulum pendulum(/*with_spring_damper=*/true);
  const SimTK::State initial = pendulum.MakeState();
  const std::vector<double> times = SampleTimes(5.0, 50);

  std::vector<std::pair<std::string, Trajectory>> runs;
  runs.emplace_back("CVODES BDF", RunCvodes(pendulum.system, initial,
                                            Options(Method::kBdf, 1e-10, 1e-12), times));
  runs.emplace_back("CVODES Adams", RunCvodes(pendulum.system, initial,
                                              Options(Method::kAdams, 1e-10, 1e-12), times));
  SimTK::CPodesIntegrator cpodes(pendulum.system, SimTK::CPodes::BDF);
  runs.emplace_back("CPodes", RunSimbody(pendulum.system, cpodes, initial, times));
  SimTK::RungeKuttaMersonIntegrator merson(pendulum.system);
  runs.emplace_back("RK-Merson", RunSimbody(pendulum.system, merson, initial, times));

  // Each run is within 2e-8 of a rtol 1e-13 reference here (the global error of a 1e-10
  // local tolerance after 5 s of motion up to 3.5 rad/s); 1e-7 leaves a factor 5 for other
  // compilers while a solver corrupted by the symbol clash is off by O(1).
  const Trajectory reference =
      RunCvodes(pendulum.system, initial, Options(Method::kAdams, 1e-13, 1e-15), times);
  for (const auto& [name, trajectory] : runs) {
    const double error = MaxDifference(trajectory, reference);
    std::printf("max |Y - reference| %s: %.3g\n", name.c_str(), error);
    EXPECT_LT(error, 1e-7) << name;
  }
  for (size_t a = 0; a < runs.size(); ++a) {
    for (size_t b = a + 1; b < runs.size(); ++b) {
      const double difference = MaxDifference(runs[a].second, runs[b].second);
      std::printf("max |Y| difference %s vs %s: %.3g\n", runs[a].first.c_str(),
                  runs[b].first.c_str(), difference);
      EXPECT_LT(difference, 1e-7) << runs[a].first << " vs " << runs[b].first;
    }
  }
  // The pendulum moved: agreement is not trivial.
  EXPECT_GT(SimTK::max(SimTK::abs(runs[0].second.back() - initial.getY())), 0.1);
}

TEST(CvodesIntegratorTest, ForwardDynamicsOperatorIsRealizeAccelerationWithoutBookkeeping) {
  // Given as a MultibodySystem, the right-hand side is realize(Dynamics) plus Simbody's
  // forward-dynamics operator; given as a System, realize(Acceleration). Both compute the same
  // articulated-body recursion on the same forces: on the double pendulum (gravity, a spring and
  // damper, velocity-dependent Coriolis terms, 0.3 rad swings) the trajectories agree to
  // roundoff, far below the 1e-10 tolerance, with the same steps.
  const DoublePendulum pendulum(true);
  const SimTK::State initial = pendulum.MakeState();
  const std::vector<double> times = SampleTimes(3.0, 30);
  for (Method method : {Method::kBdf, Method::kAdams}) {
    const IntegratorOptions options = Options(method, 1e-10, 1e-12);
    CvodesIntegrator with_operator(pendulum.system, options);
    CvodesIntegrator with_realize(static_cast<const SimTK::System&>(pendulum.system), options);
    with_operator.Initialize(initial);
    with_realize.Initialize(initial);
    double max_difference = 0.0;
    for (double t : times) {
      const SimTK::Vector a = with_operator.AdvanceTo(t).getY();
      const SimTK::Vector b = with_realize.AdvanceTo(t).getY();
      max_difference = std::max(max_difference, SimTK::max(SimTK::abs(a - b)));
    }
    // Measured: 0, bit for bit (Simbody 3.7); the bound leaves room for another build's order of
    // operations.
    EXPECT_LT(max_difference, 1e-13) << MethodName(method);
    EXPECT_EQ(with_operator.statistics().steps, with_realize.statistics().steps);
  }
}

TEST(CvodesIntegratorTest, MatchesDampedOscillatorClosedForm) {
  const TorsionalPendulum pendulum(/*inertia=*/2.0, /*stiffness=*/50.0, /*damping=*/1.0);
  const double theta0 = 0.1, omega0 = 0.3;
  for (Method method : {Method::kBdf, Method::kAdams}) {
    for (bool interpolate : {false, true}) {
      IntegratorOptions options = Options(method, 1e-10, 1e-12);
      options.interpolate_outputs = interpolate;
      CvodesIntegrator integrator(pendulum.system, options);
      integrator.Initialize(pendulum.MakeState(theta0, omega0));
      double max_error = 0.0;
      for (double t : SampleTimes(5.0, 50)) {
        const SimTK::State& state = integrator.AdvanceTo(t);
        ASSERT_EQ(state.getTime(), t);
        ASSERT_GE(state.getSystemStage(), SimTK::Stage::Acceleration);
        const double theta = pendulum.pin.getOneQ(state, SimTK::MobilizerQIndex(0));
        max_error = std::max(max_error, std::abs(theta - pendulum.ExactTheta(t, theta0, omega0)));
      }
      std::printf("%s%s: max |theta - exact| = %.3g rad\n",
                  method == Method::kBdf ? "BDF" : "Adams", interpolate ? " interpolated" : "",
                  max_error);
      // Amplitude 0.1 rad, local tolerance 1e-10 relative: the global error after ~4 periods
      // is a few 1e-10 (docs/toolchain.md), interpolation adds an error of the same order;
      // 1e-8 bounds both with margin, and the closed form is exact to roundoff.
      EXPECT_LT(max_error, 1e-8);
    }
  }
}

TEST(CvodesIntegratorTest, GivenJacobianReplacesDifferenceQuotients) {
  const TorsionalPendulum pendulum(/*inertia=*/2.0, /*stiffness=*/50.0, /*damping=*/1.0);
  const double theta0 = 0.1, omega0 = 0.3;
  // Y = [theta, omega]: theta' = omega, omega' = -(c theta + d omega) / I, exact here.
  Eigen::MatrixXd jacobian(2, 2);
  jacobian << 0.0, 1.0, -50.0 / 2.0, -1.0 / 2.0;
  for (Method method : {Method::kBdf, Method::kAdams}) {
    CvodesIntegrator integrator(pendulum.system, Options(method, 1e-10, 1e-12));
    integrator.set_jacobian(jacobian);
    integrator.Initialize(pendulum.MakeState(theta0, omega0));
    double max_error = 0.0;
    for (double t : SampleTimes(5.0, 50)) {
      const SimTK::State& state = integrator.AdvanceTo(t);
      const double theta = pendulum.pin.getOneQ(state, SimTK::MobilizerQIndex(0));
      max_error = std::max(max_error, std::abs(theta - pendulum.ExactTheta(t, theta0, omega0)));
    }
    const IntegratorStatistics statistics = integrator.statistics();
    // Same bound as without a Jacobian (MatchesDampedOscillatorClosedForm).
    EXPECT_LT(max_error, 1e-8) << (method == Method::kBdf ? "BDF" : "Adams");
    EXPECT_EQ(statistics.rhs_evaluations_for_jacobian, 0);
    EXPECT_GT(statistics.jacobian_evaluations, 0);  // Newton, also for Adams
  }
}

TEST(CvodesIntegratorTest, ApproximateJacobianKeepsTheAccuracy) {
  // A constant Jacobian of the nonlinear double pendulum, taken at rest at q = 0: Newton then
  // converges more slowly, but the error test keeps the solution at the tolerance.
  DoublePendulum pendulum(/*with_spring_damper=*/true);
  const SimTK::State initial = pendulum.MakeState();
  IntegratorOptions reference_options = Options(Method::kAdams, 1e-12, 1e-14);
  CvodesIntegrator reference(pendulum.system, reference_options);
  reference.Initialize(initial);
  const SimTK::Vector y_reference = reference.AdvanceTo(3.0).getY();

  SimTK::State at_rest = initial;
  at_rest.updY() = 0;
  pendulum.system.realize(at_rest, SimTK::Stage::Acceleration);
  const SimTK::Vector f0 = at_rest.getYDot();
  Eigen::MatrixXd jacobian(4, 4);
  for (int j = 0; j < 4; ++j) {
    SimTK::State perturbed = at_rest;
    perturbed.updY()[j] = 1e-6;
    pendulum.system.realize(perturbed, SimTK::Stage::Acceleration);
    for (int i = 0; i < 4; ++i) jacobian(i, j) = (perturbed.getYDot()[i] - f0[i]) / 1e-6;
  }
  for (Method method : {Method::kBdf, Method::kAdams}) {
    CvodesIntegrator integrator(pendulum.system, Options(method, 1e-8, 1e-10));
    integrator.set_jacobian(jacobian);
    integrator.Initialize(initial);
    const SimTK::Vector y = integrator.AdvanceTo(3.0).getY();
    const double difference = SimTK::max(SimTK::abs(y - y_reference));
    std::printf("%s, constant Jacobian: max |Y - reference| = %.3g\n",
                method == Method::kBdf ? "BDF" : "Adams", difference);
    // 3e-8 here, against 1.4e-7 (BDF) and 1.8e-7 (Adams) without a Jacobian (rtol 1e-8,
    // values of order 1, a few swings); a Jacobian error leaking into Y would be far larger.
    EXPECT_LT(difference, 1e-6) << (method == Method::kBdf ? "BDF" : "Adams");
  }
}

TEST(CvodesIntegratorTest, RejectsJacobianOfWrongSize) {
  const TorsionalPendulum pendulum(2.0, 50.0, 1.0);
  CvodesIntegrator integrator(pendulum.system, IntegratorOptions());
  integrator.set_jacobian(Eigen::MatrixXd::Identity(3, 3));
  EXPECT_THROW(integrator.Initialize(pendulum.MakeState(0.1, 0.0)), std::invalid_argument);
  integrator.set_jacobian(Eigen::MatrixXd());  // back to difference quotients
  EXPECT_NO_THROW(integrator.Initialize(pendulum.MakeState(0.1, 0.0)));
}

TEST(CvodesIntegratorTest, ConservesEnergyOfUndampedDoublePendulum) {
  DoublePendulum pendulum(/*with_spring_damper=*/false);
  const SimTK::State initial = pendulum.MakeState();
  pendulum.system.realize(initial, SimTK::Stage::Acceleration);
  const double energy0 = pendulum.system.calcEnergy(initial);
  ASSERT_GT(std::abs(energy0), 1.0);  // a relative measure needs a non-zero reference
  for (Method method : {Method::kBdf, Method::kAdams}) {
    CvodesIntegrator integrator(pendulum.system, Options(method, 1e-12, 1e-14));
    integrator.Initialize(initial);
    double max_drift = 0.0;
    for (double t : SampleTimes(10.0, 100)) {
      const double energy = pendulum.system.calcEnergy(integrator.AdvanceTo(t));
      max_drift = std::max(max_drift, std::abs(energy - energy0) / std::abs(energy0));
    }
    std::printf("%s: max relative energy drift over 10 s = %.3g (E0 = %.6g J)\n",
                method == Method::kBdf ? "BDF" : "Adams", max_drift, energy0);
    // At tolerance 1e-12 the state error stays near 1e-10 over 10 s, so energy drifts far
    // less than 1e-8; a wrong derivative (e.g. q' = u assumed wrongly) drifts by >> 1e-8.
    EXPECT_LT(max_drift, 1e-8);
  }
}

TEST(CvodesIntegratorTest, PersistentRhsExceptionBecomesNumericalError) {
  TorsionalPendulum pendulum(2.0, 50.0, 1.0);
  CvodesIntegrator integrator(pendulum.system, Options(Method::kBdf, 1e-8, 1e-10));
  integrator.set_time_dependent_inputs(
      [](SimTK::State&) { throw std::runtime_error("input table exhausted"); });
  integrator.Initialize(pendulum.MakeState(0.1, 0.0));
  try {
    integrator.AdvanceTo(1.0);
    FAIL() << "expected NumericalError";
  } catch (const NumericalError& error) {
    const std::string what = error.what();
    std::printf("what(): %s\n", what.c_str());
    EXPECT_EQ(error.stage(), "CVODES");
    EXPECT_NE(what.find("CVODES"), std::string::npos) << what;
    EXPECT_NE(what.find("CV_FIRST_RHSFUNC_ERR"), std::string::npos) << what;
    EXPECT_NE(what.find("input table exhausted"), std::string::npos) << what;
  }
  // A failed integrator must be initialized again.
  EXPECT_THROW(integrator.AdvanceTo(2.0), std::logic_error);
  integrator.set_time_dependent_inputs(nullptr);
  integrator.Initialize(pendulum.MakeState(0.1, 0.0));
  EXPECT_NO_THROW(integrator.AdvanceTo(1.0));
}

TEST(CvodesIntegratorTest, RhsExceptionLaterInTimeBecomesNumericalError) {
  TorsionalPendulum pendulum(2.0, 50.0, 1.0);
  // BDF's Newton iteration passes the unrecoverable RHS failure through; SUNDIALS 6.4.1's
  // fixed-point iteration (Adams) reports it as a repeated convergence failure instead.
  const std::pair<Method, const char*> cases[] = {{Method::kBdf, "CV_RHSFUNC_FAIL"},
                                                  {Method::kAdams, "CV_CONV_FAILURE"}};
  for (const auto& [method, flag] : cases) {
    CvodesIntegrator integrator(pendulum.system, Options(method, 1e-8, 1e-10));
    integrator.set_time_dependent_inputs([](SimTK::State& state) {
      if (state.getTime() > 0.5) throw std::runtime_error("input table ends at 0.5 s");
    });
    integrator.Initialize(pendulum.MakeState(0.1, 0.0));
    try {
      integrator.AdvanceTo(1.0);
      FAIL() << "expected NumericalError";
    } catch (const NumericalError& error) {
      const std::string what = error.what();
      std::printf("what(): %s\n", what.c_str());
      EXPECT_NE(what.find("CVODES"), std::string::npos) << what;
      EXPECT_NE(what.find(flag), std::string::npos) << what;
      EXPECT_NE(what.find("input table ends at 0.5 s"), std::string::npos) << what;
      // CVODES stopped just before the end of the inputs.
      EXPECT_NEAR(integrator.time(), 0.5, 1e-6);
      EXPECT_LE(integrator.time(), 0.5);
    }
  }
}

TEST(CvodesIntegratorTest, TooFewStepsIsTooMuchWork) {
  TorsionalPendulum pendulum(2.0, 50.0, 1.0);
  IntegratorOptions options = Options(Method::kBdf, 1e-8, 1e-10);
  options.max_steps = 5;
  CvodesIntegrator integrator(pendulum.system, options);
  integrator.Initialize(pendulum.MakeState(0.1, 0.0));
  try {
    integrator.AdvanceTo(100.0);
    FAIL() << "expected NumericalError";
  } catch (const NumericalError& error) {
    const std::string what = error.what();
    std::printf("what(): %s\n", what.c_str());
    EXPECT_EQ(error.stage(), "CVODES");
    EXPECT_NE(what.find("CV_TOO_MUCH_WORK"), std::string::npos) << what;
  }
}

TEST(CvodesIntegratorTest, StatisticsCountWorkAndGrowWithTighterTolerance) {
  DoublePendulum pendulum(/*with_spring_damper=*/true);
  for (Method method : {Method::kBdf, Method::kAdams}) {
    std::vector<IntegratorStatistics> statistics;
    for (double rtol : {1e-6, 1e-10}) {
      CvodesIntegrator integrator(pendulum.system, Options(method, rtol, rtol * 1e-2));
      integrator.Initialize(pendulum.MakeState());
      integrator.AdvanceTo(5.0);
      statistics.push_back(integrator.statistics());
    }
    for (const IntegratorStatistics& s : statistics) {
      EXPECT_GT(s.steps, 0);
      EXPECT_GT(s.rhs_evaluations, s.steps);
      EXPECT_GT(s.nonlinear_iterations, 0);
      EXPECT_GT(s.last_step_s, 0.0);
      EXPECT_GE(s.last_order, 1);
      if (method == Method::kBdf) {
        EXPECT_GT(s.linear_solver_setups, 0);
        EXPECT_GT(s.jacobian_evaluations, 0);
        // The dense difference-quotient Jacobian costs one RHS call per state variable.
        EXPECT_EQ(s.rhs_evaluations_for_jacobian, 4 * s.jacobian_evaluations);
      } else {
        EXPECT_EQ(s.jacobian_evaluations, 0);
      }
    }
    std::printf("%s: rhs evaluations %ld at rtol 1e-6, %ld at rtol 1e-10\n",
                method == Method::kBdf ? "BDF" : "Adams", statistics[0].rhs_evaluations,
                statistics[1].rhs_evaluations);
    EXPECT_GT(statistics[1].rhs_evaluations, statistics[0].rhs_evaluations);
    EXPECT_GT(statistics[1].steps, statistics[0].steps);
  }
}

TEST(CvodesIntegratorTest, ConstantTorqueHookGivesStaticDeflection) {
  // Critically damped (d = 2 sqrt(c I)): the transient decays like (1 + 5 t) exp(-5 t).
  const TorsionalPendulum pendulum(/*inertia=*/2.0, /*stiffness=*/50.0, /*damping=*/20.0);
  const double torque = 2.0;  // N m
  CvodesIntegrator integrator(pendulum.system, Options(Method::kBdf, 1e-10, 1e-12));
  int calls = 0;
  integrator.set_time_dependent_inputs([&](SimTK::State& state) {
    ++calls;
    pendulum.discrete.setOneMobilityForce(state, pendulum.pin, SimTK::MobilizerUIndex(0), torque);
  });
  integrator.Initialize(pendulum.MakeState(0.0, 0.0));
  const SimTK::State& state = integrator.AdvanceTo(20.0);
  const double theta = pendulum.pin.getOneQ(state, SimTK::MobilizerQIndex(0));
  const double expected = torque / pendulum.stiffness;
  std::printf("static deflection %.15g rad, T/c = %.15g rad, error %.3g\n", theta, expected,
              std::abs(theta - expected));
  // At t = 20 s the transient is ~1e-41 of T/c; what remains is the integrator's error at
  // rest, bounded by the local tolerance rtol |theta| + atol ~ 1e-11.
  EXPECT_NEAR(theta, expected, 1e-10);
  EXPECT_NEAR(pendulum.pin.getOneU(state, SimTK::MobilizerUIndex(0)), 0.0, 1e-10);
  EXPECT_GT(calls, 0);
  // The returned state carries the input: its acceleration is balanced.
  EXPECT_NEAR(pendulum.pin.getOneUDot(state, SimTK::MobilizerUIndex(0)), 0.0, 1e-8);
}

TEST(CvodesIntegratorTest, RejectsMisuse) {
  {
    SimTK::MultibodySystem system;
    SimTK::SimbodyMatterSubsystem matter(system);
    SimTK::MobilizedBody::Free body(matter.Ground(), SimTK::Body::Rigid());
    system.realizeTopology();
    CvodesIntegrator integrator(system, IntegratorOptions());
    EXPECT_THROW(integrator.Initialize(system.getDefaultState()), std::invalid_argument);
  }
  {
    SimTK::MultibodySystem system;
    SimTK::SimbodyMatterSubsystem matter(system);
    SimTK::MobilizedBody::Slider slider(matter.Ground(), SimTK::Body::Rigid());
    SimTK::MobilizedBody::Slider second(slider, SimTK::Body::Rigid());
    SimTK::Constraint::Rod(slider, SimTK::Vec3(0), second, SimTK::Vec3(0), 1.0);
    system.realizeTopology();
    CvodesIntegrator integrator(system, IntegratorOptions());
    EXPECT_THROW(integrator.Initialize(system.getDefaultState()), std::invalid_argument);
  }
  DoublePendulum pendulum(false);
  IntegratorOptions options;
  options.relative_tolerance = -1.0;
  std::string why;
  EXPECT_FALSE(options.IsValid(&why));
  EXPECT_NE(why.find("relative_tolerance"), std::string::npos) << why;
  EXPECT_THROW(CvodesIntegrator(pendulum.system, options), std::invalid_argument);
  options = IntegratorOptions();
  options.max_steps = 0;
  EXPECT_FALSE(options.IsValid(nullptr));
  EXPECT_TRUE(IntegratorOptions().IsValid(nullptr));

  CvodesIntegrator integrator(pendulum.system, IntegratorOptions());
  EXPECT_THROW(integrator.AdvanceTo(1.0), std::logic_error);
  EXPECT_THROW(integrator.state(), std::logic_error);
  integrator.Initialize(pendulum.MakeState());
  EXPECT_GE(integrator.state().getSystemStage(), SimTK::Stage::Velocity);
  EXPECT_GE(integrator.AdvanceTo(0.0).getSystemStage(), SimTK::Stage::Acceleration);
  integrator.AdvanceTo(1.0);
  EXPECT_THROW(integrator.AdvanceTo(0.5), std::invalid_argument);
  // Advancing to the current time is allowed and changes nothing.
  EXPECT_EQ(integrator.AdvanceTo(1.0).getTime(), 1.0);
  // Positions only: the same point, forces and accelerations left unrealized.
  const SimTK::Vector y = integrator.state().getY();
  const SimTK::State& positions =
      integrator.AdvanceTo(1.0, CvodesIntegrator::Realization::kPositions);
  EXPECT_EQ(positions.getSystemStage(), SimTK::Stage::Position);
  EXPECT_EQ(SimTK::max(SimTK::abs(positions.getY() - y)), 0.0);
  // Nothing realized: t and Y set, every stage from Position on left for the caller (the Time
  // stage stays valid when the time is the one already set).
  const SimTK::State& unrealized = integrator.AdvanceTo(1.0, CvodesIntegrator::Realization::kNone);
  EXPECT_LT(unrealized.getSystemStage(), SimTK::Stage::Position);
  EXPECT_EQ(unrealized.getTime(), 1.0);
  EXPECT_EQ(SimTK::max(SimTK::abs(unrealized.getY() - y)), 0.0);
}

}  // namespace
}  // namespace mbid::simulation
