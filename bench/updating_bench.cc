// Model updating (issue 5): the eight joint parameters of the reference crane from 30% off in
// one run of Route 2, the Jacobian from CVODES forward sensitivities against central
// differences of whole simulations. The record is reference-crane.yaml (initial deflection,
// 8 s at 100 Hz, sensor noise 1e-5 rad with seed 1), the noise level given to the fit.
// Argument: worker threads (sensitivity groups, or columns of the numeric Jacobian); for
// BM_UpdateSpeculative a second, updating.speculative_jacobians off (0) or on (1).
// Counters: Ceres iterations, right-hand-side evaluations of every kind, simulations, and the
// largest relative error of the eight estimates against the truth. Anchors in the same run: one
// plain simulation of the record and one sensitivity run of all eight parameters, the units the
// fit's cost is made of.

#include <benchmark/benchmark.h>

#include <cmath>
#include <memory>
#include <optional>

#include "mbid/common/yaml_reader.h"
#include "mbid/model/linear_model.h"
#include "mbid/model/model_factory.h"
#include "mbid/simulation/scenario_sections.h"
#include "mbid/simulation/sensitivity.h"
#include "mbid/simulation/simulate.h"
#include "mbid/updating/characteristic.h"
#include "mbid/updating/output_error.h"

namespace {

using mbid::updating::UpdateOptions;

struct Setup {
  std::unique_ptr<mbid::model::MechanicalModel> model;
  mbid::updating::TestRecord test;
  mbid::simulation::IntegratorOptions integrator;
};

const Setup& Reference() {
  static const Setup setup = [] {
    const mbid::YamlReader root = mbid::YamlReader::FromFile(std::string(MBID_SOURCE_DIR) +
                                                             "/scenarios/reference-crane.yaml");
    Setup s;
    s.model = mbid::model::MakeModel(root.Child("model"));
    const auto excitation = mbid::simulation::ReadExcitation(root.Child("excitation"), *s.model);
    const auto simulation = mbid::simulation::ReadSimulationOptions(root.Child("simulation"));
    const auto sensors = mbid::simulation::ReadSensorOptions(root.Child("sensors"), *s.model);
    s.test.name = "reference-crane";
    s.test.record = mbid::simulation::Simulate(*s.model, excitation, simulation, sensors).measured;
    s.test.excitation = excitation;
    s.test.noise_std = sensors.noise_std;
    s.integrator = simulation.integrator;
    return s;
  }();
  return setup;
}

using Method = mbid::simulation::IntegratorOptions::Method;

// `method`: the scenario's (auto) unless given.
void RunUpdate(benchmark::State& state, UpdateOptions::Jacobian jacobian,
               mbid::simulation::SensitivityOptions::DifferenceQuotient quotient,
               std::optional<Method> method = std::nullopt, bool speculative = true) {
  const Setup& setup = Reference();
  UpdateOptions options;
  for (const mbid::model::Parameter& p : setup.model->parameters()) {
    options.parameters.push_back({p.name, 1.3 * p.value});
  }
  options.jacobian = jacobian;
  options.sensitivity.difference_quotient = quotient;
  options.integrator = setup.integrator;
  options.integrator.interpolate_outputs = true;
  if (method) options.integrator.method = *method;
  options.threads = static_cast<int>(state.range(0));
  options.speculative_jacobians = speculative;
  options.quiet = true;
  mbid::updating::UpdateResult result;
  for (auto _ : state) {
    result = mbid::updating::UpdateModel(*setup.model, {setup.test}, options);
  }
  double worst = 0;
  for (const auto& estimate : result.parameters) {
    worst =
        std::max(worst, std::abs(estimate.value / setup.model->GetParameter(estimate.name) - 1));
  }
  state.counters["iterations"] = result.iterations;
  state.counters["rhs_evaluations"] = static_cast<double>(result.rhs_evaluations);
  state.counters["simulations"] = static_cast<double>(result.simulations);
  state.counters["sensitivity_runs"] = static_cast<double>(result.sensitivity_simulations);
  state.counters["worst_rel_error"] = worst;
  state.counters["converged"] =
      result.termination == mbid::updating::UpdateResult::Termination::kConverged;
}

mbid::simulation::SimulationOptions FitSimulation(const Setup& setup) {
  mbid::simulation::SimulationOptions options;
  options.duration_s = (setup.test.record.samples() - 1) * setup.test.record.sample_interval_s;
  options.integrator = setup.integrator;
  options.integrator.interpolate_outputs = true;
  return options;
}

mbid::simulation::SensorOptions FitSensors(const Setup& setup) {
  mbid::simulation::SensorOptions sensors;
  sensors.sample_rate_hz = 1.0 / setup.test.record.sample_interval_s;
  sensors.channels = setup.test.record.channels;
  return sensors;
}

// Argument 0: the scenario's method (auto: Adams), 1: Adams.
void BM_AnchorPlainSimulation(benchmark::State& state) {
  const Setup& setup = Reference();
  mbid::simulation::SimulationOptions options = FitSimulation(setup);
  if (state.range(0) == 1) options.integrator.method = Method::kAdams;
  mbid::simulation::SimulationResult result;
  for (auto _ : state) {
    result =
        mbid::simulation::Simulate(*setup.model, setup.test.excitation, options, FitSensors(setup));
  }
  state.counters["rhs_evaluations"] = static_cast<double>(
      result.statistics.rhs_evaluations + result.statistics.rhs_evaluations_for_jacobian);
}

void BM_AnchorSensitivityRun(benchmark::State& state) {
  const Setup& setup = Reference();
  std::vector<std::string> names;
  for (const mbid::model::Parameter& p : setup.model->parameters()) names.push_back(p.name);
  mbid::simulation::SensitivityOptions sensitivity;
  sensitivity.difference_quotient =
      state.range(0) % 2 == 0 ? mbid::simulation::SensitivityOptions::DifferenceQuotient::kCentered
                              : mbid::simulation::SensitivityOptions::DifferenceQuotient::kForward;
  if (state.range(0) >= 2) {
    sensitivity.right_hand_side =
        mbid::simulation::SensitivityOptions::RightHandSide::kStateJacobian;
  }
  if (state.range(0) >= 4) {
    sensitivity.corrector = mbid::simulation::SensitivityOptions::Corrector::kStaggered;
  }
  // Third argument 1: the four initial deflections beside the joints (as
  // updating.fit_initial_deflection adds them): twelve sensitivities for eight states.
  std::vector<mbid::simulation::InitialStateDirection> directions;
  if (state.range(2) == 1) {
    const int n = setup.model->coordinate_count();
    for (int j = 0; j < n; ++j) {
      mbid::simulation::InitialStateDirection direction;
      direction.name = "deflection_" + std::to_string(j);
      direction.dq0_dp = Eigen::VectorXd::Unit(n, j);
      direction.scale = 0.01;  // rad, the fit's span for a deflection near 0
      directions.push_back(direction);
    }
  }
  mbid::simulation::SimulationOptions simulation = FitSimulation(setup);
  if (state.range(1) == 1) simulation.integrator.method = Method::kBdf;
  mbid::simulation::SensitivityResult result;
  for (auto _ : state) {
    result = mbid::simulation::SimulateWithSensitivities(*setup.model, setup.test.excitation,
                                                         simulation, FitSensors(setup), names,
                                                         directions, sensitivity);
  }
  const auto& s = result.statistics;
  state.counters["rhs_evaluations"] = static_cast<double>(
      s.rhs_evaluations + s.rhs_evaluations_for_jacobian + s.rhs_evaluations_for_sensitivities);
  state.counters["rhs_sensitivities"] = static_cast<double>(s.rhs_evaluations_for_sensitivities);
  state.counters["steps"] = static_cast<double>(s.steps);
  state.counters["jacobians"] = static_cast<double>(s.sensitivity_jacobians);
  state.counters["jacobian_reuses"] = static_cast<double>(s.sensitivity_jacobian_reuses);
  state.counters["nonlinear_iterations"] = static_cast<double>(s.nonlinear_iterations);
}

// A sensitivity run of the excavator arm (scenarios/excavator-arm.yaml, 100 Hz, its six joint
// parameters) for a record of its two inclinometers (argument 0) and, the anchor, of the
// inclinometers and the two accelerometers (1). The angles need positions alone: before session
// 27 every output was computed, and the accelerometers' forward dynamics made both cost the same.
// scenarios/excavator-arm.yaml's test, and its joint parameters' names.
struct Excavator {
  std::unique_ptr<mbid::model::MechanicalModel> model;
  mbid::simulation::Excitation excitation;
  mbid::simulation::SimulationOptions simulation;
  mbid::simulation::SensorOptions sensors;
  std::vector<std::string> names;
};

Excavator LoadExcavator() {
  const mbid::YamlReader root =
      mbid::YamlReader::FromFile(std::string(MBID_SOURCE_DIR) + "/scenarios/excavator-arm.yaml");
  Excavator e;
  e.model = mbid::model::MakeModel(root.Child("model"));
  e.excitation = mbid::simulation::ReadExcitation(root.Child("excitation"), *e.model);
  e.simulation = mbid::simulation::ReadSimulationOptions(root.Child("simulation"));
  e.sensors = mbid::simulation::ReadSensorOptions(root.Child("sensors"), *e.model);
  for (const mbid::model::Parameter& p : e.model->parameters()) e.names.push_back(p.name);
  return e;
}

void BM_ExcavatorSensitivityRun(benchmark::State& state) {
  Excavator e = LoadExcavator();
  if (state.range(0) == 0) e.sensors.channels = {"boom_incl", "stick_incl"};
  mbid::simulation::SensitivityResult result;
  for (auto _ : state) {
    result = mbid::simulation::SimulateWithSensitivities(*e.model, e.excitation, e.simulation,
                                                         e.sensors, e.names, {}, {});
  }
  state.counters["steps"] = static_cast<double>(result.statistics.steps);
}

// The excavator arm's test (all four channels) sampled at 100 Hz (the anchor) and at a logger's
// 1, 5 and 10 kHz: a plain simulation (second argument 0) and a sensitivity run of its six joint
// parameters (1). Its fastest mode (7.4 Hz) needs 120 output evaluations per period: above
// 893 Hz only every 2nd, 5th, 11th sample is evaluated, the rest interpolated (sample_rows.h).
// Before, the cost grew with the samples (each a Simbody realization, and for sensitivities
// their difference quotients).
void BM_ExcavatorHighRate(benchmark::State& state) {
  Excavator e = LoadExcavator();
  e.sensors.sample_rate_hz = static_cast<double>(state.range(0));
  for (auto _ : state) {
    if (state.range(1) == 0) {
      benchmark::DoNotOptimize(
          mbid::simulation::Simulate(*e.model, e.excitation, e.simulation, e.sensors)
              .exact.values.data());
    } else {
      benchmark::DoNotOptimize(mbid::simulation::SimulateWithSensitivities(
                                   *e.model, e.excitation, e.simulation, e.sensors, e.names, {}, {})
                                   .exact.values.data());
    }
  }
  state.counters["samples"] = e.simulation.duration_s * e.sensors.sample_rate_hz + 1;
}

// Route 1 (eq. 7, 100 starts, then eq. 8 on the record for each set) for the crane's exact
// poles: what `mbid update` and `mbid run` spend between identification and the fit.
void BM_Route1(benchmark::State& state) {
  const Setup& setup = Reference();
  std::vector<std::complex<double>> lambda;
  for (const mbid::model::Mode& mode : mbid::model::CalcModes(setup.model->Linearize())) {
    lambda.push_back(mode.lambda);
  }
  const mbid::updating::CharacteristicProblem problem = mbid::updating::MakeCharacteristicProblem(
      *setup.model, lambda, setup.test.record, setup.test.excitation);
  mbid::updating::CharacteristicResult result;
  for (auto _ : state) {
    result = mbid::updating::SolveCharacteristicEquation(problem, {});
  }
  state.counters["sets"] = static_cast<double>(result.solutions.size());
}

void BM_UpdateSensitivitiesCentered(benchmark::State& state) {
  RunUpdate(state, UpdateOptions::Jacobian::kSensitivities,
            mbid::simulation::SensitivityOptions::DifferenceQuotient::kCentered);
}
void BM_UpdateSensitivitiesForward(benchmark::State& state) {
  RunUpdate(state, UpdateOptions::Jacobian::kSensitivities,
            mbid::simulation::SensitivityOptions::DifferenceQuotient::kForward);
}
void BM_UpdateSensitivitiesForwardAdams(benchmark::State& state) {
  RunUpdate(state, UpdateOptions::Jacobian::kSensitivities,
            mbid::simulation::SensitivityOptions::DifferenceQuotient::kForward, Method::kAdams);
}
// Argument 1: updating.speculative_jacobians (the default), 0: every trial point plain.
void BM_UpdateSpeculative(benchmark::State& state) {
  RunUpdate(state, UpdateOptions::Jacobian::kSensitivities,
            mbid::simulation::SensitivityOptions::DifferenceQuotient::kForward, std::nullopt,
            state.range(1) == 1);
}
void BM_UpdateNumeric(benchmark::State& state) {
  RunUpdate(state, UpdateOptions::Jacobian::kNumeric,
            mbid::simulation::SensitivityOptions::DifferenceQuotient::kCentered);
}

BENCHMARK(BM_AnchorPlainSimulation)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
// First argument: CVODES' quotients centered (0) or forward (1), the state-Jacobian right-hand
// side with central (2) or forward (3) columns, 5: 3 with the staggered corrector; second 0:
// the scenario's method (auto: Adams), 1: BDF (what the scenario named before session 8); third
// 1: twelve sensitivities (the initial deflections beside the joints).
BENCHMARK(BM_AnchorSensitivityRun)
    ->ArgsProduct({{0, 1, 2, 3, 5}, {0, 1}, {0}})
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_AnchorSensitivityRun)->ArgsProduct({{1, 3}, {0}, {1}})->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Route1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ExcavatorHighRate)
    ->ArgsProduct({{100, 1000, 5000, 10000}, {0, 1}})
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ExcavatorSensitivityRun)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
// One fit takes seconds: one iteration each, wall time (the threads work in parallel).
BENCHMARK(BM_UpdateSensitivitiesCentered)
    ->Arg(1)
    ->Arg(2)
    ->Iterations(1)
    ->UseRealTime()
    ->Unit(benchmark::kSecond);
BENCHMARK(BM_UpdateSensitivitiesForward)
    ->Arg(1)
    ->Arg(2)
    ->Iterations(1)
    ->UseRealTime()
    ->Unit(benchmark::kSecond);
BENCHMARK(BM_UpdateSensitivitiesForwardAdams)
    ->Arg(1)
    ->Iterations(1)
    ->UseRealTime()
    ->Unit(benchmark::kSecond);
// Arguments: threads, then speculative Jacobians off (0) and on (1), process CPU time.
BENCHMARK(BM_UpdateSpeculative)
    ->Args({1, 0})
    ->Args({1, 1})
    ->Iterations(1)
    ->Unit(benchmark::kSecond);
BENCHMARK(BM_UpdateNumeric)->Arg(1)->Arg(2)->Iterations(1)->UseRealTime()->Unit(benchmark::kSecond);

}  // namespace
