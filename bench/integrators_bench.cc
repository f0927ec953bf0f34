// Wall time and right-hand-side evaluations of CVODES (BDF, Adams) against Simbody's own
// integrators (RK-Merson, CPodes) for 10 s of a damped double pendulum at tolerance 1e-8.
// Argument: the number of equally spaced outputs (1 = straight to 10 s, 1000 = 100 Hz);
// "interpolated" runs use IntegratorOptions::interpolate_outputs.

#include <Simbody.h>
#include <benchmark/benchmark.h>

#include <algorithm>
#include <memory>

#include "mbid/simulation/cvodes_integrator.h"

namespace {

using mbid::simulation::CvodesIntegrator;
using mbid::simulation::IntegratorOptions;

constexpr double kDuration = 10.0;   // s
constexpr double kTolerance = 1e-8;  // relative; absolute is 1e-2 of it

// Two 1 kg bobs on 1 m Pin links under gravity, a spring and damper in the upper joint.
class DoublePendulum {
 public:
  DoublePendulum() {
    SimTK::Force::Gravity(forces_, matter_, -SimTK::YAxis, 9.81);
    const SimTK::Body::Rigid bob(
        SimTK::MassProperties(1.0, SimTK::Vec3(0), SimTK::Inertia(0.01, 0.01, 0.01)));
    const SimTK::Transform X_BM(SimTK::Vec3(0, 1.0, 0));
    upper_ = SimTK::MobilizedBody::Pin(matter_.Ground(), SimTK::Transform(), bob, X_BM);
    lower_ = SimTK::MobilizedBody::Pin(upper_, SimTK::Transform(), bob, X_BM);
    SimTK::Force::MobilityLinearSpring(forces_, upper_, SimTK::MobilizerQIndex(0), 20.0, 0.0);
    SimTK::Force::MobilityLinearDamper(forces_, upper_, SimTK::MobilizerUIndex(0), 0.5);
    system_.realizeTopology();
  }

  const SimTK::MultibodySystem& system() const { return system_; }

  SimTK::State MakeState() const {
    SimTK::State state = system_.getDefaultState();
    upper_.setOneQ(state, SimTK::MobilizerQIndex(0), 0.3);
    lower_.setOneQ(state, SimTK::MobilizerQIndex(0), -0.2);
    upper_.setOneU(state, SimTK::MobilizerUIndex(0), 0.2);
    return state;
  }

 private:
  SimTK::MultibodySystem system_;
  SimTK::SimbodyMatterSubsystem matter_{system_};
  SimTK::GeneralForceSubsystem forces_{system_};
  SimTK::MobilizedBody::Pin upper_;
  SimTK::MobilizedBody::Pin lower_;
};

const DoublePendulum& Pendulum() {
  static const DoublePendulum pendulum;
  return pendulum;
}

// The state at 10 s to a tolerance far below the benchmarked one.
const SimTK::Vector& Reference() {
  static const SimTK::Vector reference = [] {
    IntegratorOptions options;
    options.method = IntegratorOptions::Method::kAdams;
    options.relative_tolerance = 1e-13;
    options.absolute_tolerance = 1e-15;
    CvodesIntegrator integrator(Pendulum().system(), options);
    integrator.Initialize(Pendulum().MakeState());
    return SimTK::Vector(integrator.AdvanceTo(kDuration).getY());
  }();
  return reference;
}

void ReportError(benchmark::State& bench, const SimTK::Vector& y_end) {
  bench.counters["max_error"] = SimTK::max(SimTK::abs(y_end - Reference()));
}

void BM_Cvodes(benchmark::State& bench, IntegratorOptions::Method method, bool interpolate) {
  const int outputs = static_cast<int>(bench.range(0));
  IntegratorOptions options;
  options.method = method;
  options.interpolate_outputs = interpolate;
  options.relative_tolerance = kTolerance;
  options.absolute_tolerance = kTolerance * 1e-2;
  const SimTK::State initial = Pendulum().MakeState();
  Reference();
  CvodesIntegrator integrator(Pendulum().system(), options);
  for (auto _ : bench) {
    integrator.Initialize(initial);
    for (int i = 1; i <= outputs; ++i) integrator.AdvanceTo(kDuration * i / outputs);
    benchmark::DoNotOptimize(integrator.state().getY()[0]);
  }
  const mbid::simulation::IntegratorStatistics statistics = integrator.statistics();
  bench.counters["rhs_evaluations"] =
      static_cast<double>(statistics.rhs_evaluations + statistics.rhs_evaluations_for_jacobian);
  bench.counters["steps"] = static_cast<double>(statistics.steps);
  ReportError(bench, integrator.state().getY());
}

void BM_Simbody(benchmark::State& bench, bool cpodes) {
  const int outputs = static_cast<int>(bench.range(0));
  const SimTK::State initial = Pendulum().MakeState();
  Reference();
  std::unique_ptr<SimTK::Integrator> integrator;
  if (cpodes) {
    integrator = std::make_unique<SimTK::CPodesIntegrator>(Pendulum().system(), SimTK::CPodes::BDF);
  } else {
    integrator = std::make_unique<SimTK::RungeKuttaMersonIntegrator>(Pendulum().system());
  }
  integrator->setAccuracy(kTolerance);
  integrator->setInternalStepLimit(100000);  // as CVODES' max_steps; silences CPodes' mxstep
  SimTK::TimeStepper stepper(Pendulum().system(), *integrator);
  for (auto _ : bench) {
    stepper.initialize(initial);
    integrator->resetAllStatistics();
    for (int i = 1; i <= outputs; ++i) stepper.stepTo(kDuration * i / outputs);
    benchmark::DoNotOptimize(integrator->getState().getY()[0]);
  }
  // Simbody counts realizations through Acceleration: its right-hand-side evaluations.
  bench.counters["rhs_evaluations"] = integrator->getNumRealizations();
  bench.counters["steps"] = integrator->getNumStepsTaken();
  ReportError(bench, integrator->getState().getY());
}

// Straight to 10 s, and outputs at 100 Hz.
void OutputCounts(benchmark::internal::Benchmark* benchmark) {
  benchmark->Arg(1)->Arg(1000)->Unit(benchmark::kMillisecond)->UseRealTime();
}

BENCHMARK_CAPTURE(BM_Cvodes, bdf, IntegratorOptions::Method::kBdf, false)->Apply(OutputCounts);
BENCHMARK_CAPTURE(BM_Cvodes, bdf_interpolated, IntegratorOptions::Method::kBdf, true)
    ->Apply(OutputCounts);
BENCHMARK_CAPTURE(BM_Cvodes, adams, IntegratorOptions::Method::kAdams, false)->Apply(OutputCounts);
BENCHMARK_CAPTURE(BM_Cvodes, adams_interpolated, IntegratorOptions::Method::kAdams, true)
    ->Apply(OutputCounts);
BENCHMARK_CAPTURE(BM_Simbody, rk_merson, false)->Apply(OutputCounts);
BENCHMARK_CAPTURE(BM_Simbody, cpodes, true)->Apply(OutputCounts);

}  // namespace
