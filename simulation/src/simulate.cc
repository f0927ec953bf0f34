#include "mbid/simulation/simulate.h"

#include <fmt/format.h>

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "mbid/common/error.h"
#include "mbid/model/simbody.h"
#include "mbid/simulation/cvodes_integrator.h"
#include "sample_rows.h"
#include "simulation_setup.h"

namespace mbid::simulation {
namespace {

// Outputs realize what they need themselves (the crane's: nothing); realizing here would cost
// up to a right-hand side per sample.
constexpr CvodesIntegrator::Realization kUnrealized = CvodesIntegrator::Realization::kNone;

}  // namespace

std::vector<std::string> FindStartFarFromRest(const model::MechanicalModel& model,
                                              const Excitation& excitation) {
  if (const LoadDrop* drop = excitation.get_if<LoadDrop>()) {
    // The springs' static answer to the payload: beyond half a turn they hold no such load (a
    // trial's 1e9 kg started at -9805 rad, unsaid).
    const Eigen::VectorXd start = drop->CalcInitialCoordinates(model);
    for (Eigen::Index i = 0; i < start.size(); ++i) {
      if (model.coordinate_units()[static_cast<size_t>(i)] == "rad" && std::abs(start[i]) > M_PI) {
        return {fmt::format(
            "the load drop's {:.6g} kg payload deflects {} to {:.4g} rad at rest, more than half "
            "a turn: no spring holds that; the test is no vibration of the structure (a mass or "
            "a stiffness in the wrong unit?)",
            drop->payload_mass_kg, model.coordinate_names()[static_cast<size_t>(i)], start[i])};
      }
    }
    // Held by springs, a tenth of the payload deflects about a tenth as far; where it deflects
    // more than a third as far, the machine hangs in its geometry's hold (an arm pulled down to
    // the vertical: 2e5 kg at 1 m on 3000 N m/rad rests at 1.569 rad, a tenth of it at 1.555).
    const Eigen::VectorXd tenth =
        model.SolveStaticEquilibrium(model.CalcPayloadLoads(0.1 * drop->payload_mass_kg));
    Eigen::Index worst = 0;
    const double deflection = start.cwiseAbs().maxCoeff(&worst);
    if (deflection > 0.1 && std::abs(tenth[worst]) > deflection / 3) {
      const auto c = static_cast<size_t>(worst);
      return {fmt::format(
          "the load drop's {:.6g} kg payload deflects {} to {:.4g} {} at rest, and a tenth of it "
          "to {:.4g} {}: no spring holds that load, the machine hangs in its geometry; the test "
          "is no vibration of the structure (a mass or a stiffness in the wrong unit?)",
          drop->payload_mass_kg, model.coordinate_names()[c], start[worst],
          model.coordinate_units()[c], tenth[worst], model.coordinate_units()[c])};
    }
    return {};
  }
  const InitialDeflection* deflection = excitation.get_if<InitialDeflection>();
  if (deflection == nullptr) return {};
  const Eigen::VectorXd start = deflection->CalcInitialCoordinates(model);
  Eigen::VectorXd rest;
  try {
    rest = model.SolveStaticEquilibrium({});
  } catch (const NumericalError&) {
    return {};  // a free coordinate: no rest to start from (the test moves it as a rigid body)
  }
  const double given = start.lpNorm<Eigen::Infinity>();
  Eigen::Index worst = 0;
  const double away = (start - rest).cwiseAbs().maxCoeff(&worst);
  // Twice the largest deflection given: the release is mostly the machine's sag, not the test.
  if (!(away > 2 * given)) return {};
  const std::string& name = model.coordinate_names()[static_cast<size_t>(worst)];
  const std::string unit = model.coordinate_units()[static_cast<size_t>(worst)];
  return {fmt::format(
      "initial_deflection starts {} at {:.4g} {}, {:.4g} {} from where the machine rests with its "
      "attached payload ({:.4g} {}): the coordinates count from q = 0, the unloaded rest, and "
      "the release is mostly the machine settling under its payload; add the rest to the "
      "deflection for a test about it",
      name, start[worst], unit, away, unit, rest[worst], unit)};
}

SimulationResult Simulate(const model::MechanicalModel& model, const Excitation& excitation,
                          const SimulationOptions& options, const SensorOptions& sensors) {
  if (!(options.duration_s > 0) || !(sensors.sample_rate_hz > 0)) {
    throw std::invalid_argument("Simulate: duration and sample rate must be positive");
  }
  const std::vector<internal::ChannelSource> sources =
      internal::ResolveChannels(model, sensors.channels);
  const int highest_order = internal::HighestOrderRead(model, sources);
  const double tau = sensors.sample_interval_s();
  const internal::SampleGrid grid = internal::MakeSampleGrid(options.duration_s, sensors);

  SimulationResult result;
  result.initial_q = CalcInitialCoordinates(model, excitation);
  result.forcing_end_s = excitation.CalcForcingEndTime();

  // A forced test gets its own model instance carrying the excitation's load function.
  const std::unique_ptr<model::MechanicalModel> forced_model =
      internal::MakeForcedModel(model, excitation);
  const bool forced = forced_model != nullptr;
  const model::MechanicalModel& simulated = forced ? *forced_model : model;
  // While forced, stop at every sample and at the forcing's end: no step may straddle the kink
  // where the load switches off. The free decay may use dense output.
  IntegratorOptions forced_options = options.integrator;
  forced_options.interpolate_outputs = false;
  SimTK::State initial =
      simulated.MakeState(result.initial_q, Eigen::VectorXd::Zero(model.coordinate_count()));
  const Eigen::MatrixXd jacobian = internal::CalcNewtonJacobian(simulated, initial);
  CvodesIntegrator integrator =
      internal::MakeIntegrator(simulated, forced ? forced_options : options.integrator, jacobian);
  integrator.Initialize(std::move(initial));

  Measurement exact;
  exact.channels = sensors.channels;
  for (const internal::ChannelSource& source : sources) exact.units.push_back(source.units);
  exact.sample_interval_s = tau;
  exact.start_time_s = grid.first_time_s();
  exact.source = "simulation";

  bool forcing_done = !forced;
  IntegratorStatistics before_restart;
  const int first_free = forced ? internal::FirstRowAtOrAfter(grid, result.forcing_end_s) : 0;
  const int stride =
      internal::ChooseOutputStride(tau, jacobian, options.integrator.interpolate_outputs);
  exact.values = internal::SampleRows(
      grid, first_free, stride, static_cast<int>(sources.size()), [&](double t, double* row) {
        if (!forcing_done && t >= result.forcing_end_s) {
          // Stop exactly where the forcing switches off (a kink in the load) and restart the
          // multistep history there.
          SimTK::State at_end = integrator.AdvanceTo(result.forcing_end_s, kUnrealized);
          before_restart = integrator.statistics();
          integrator = internal::MakeIntegrator(simulated, options.integrator, jacobian);
          integrator.Initialize(std::move(at_end));
          forcing_done = true;
        }
        const SimTK::State& state =
            t == 0 ? integrator.state() : integrator.AdvanceTo(t, kUnrealized);
        if (row == nullptr) return;
        const Eigen::VectorXd y = simulated.CalcOutputs(state, highest_order);
        for (size_t c = 0; c < sources.size(); ++c) {
          row[c] = sources[c].is_output ? y[sources[c].index] : state.getQ()[sources[c].index];
        }
      });
  // Counters restart with each integrator: the forced stretch, then the free decay.
  result.statistics = before_restart;
  result.statistics += integrator.statistics();
  result.exact = exact;
  result.measured = ApplySensor(exact, sensors);
  return result;
}

FreeDecayStart CalcFreeDecayStart(const model::MechanicalModel& model, const Excitation& excitation,
                                  const IntegratorOptions& integrator) {
  FreeDecayStart start;
  start.q = CalcInitialCoordinates(model, excitation);
  start.u = Eigen::VectorXd::Zero(model.coordinate_count());
  start.time_s = excitation.CalcForcingEndTime();
  const std::unique_ptr<model::MechanicalModel> forced =
      internal::MakeForcedModel(model, excitation);
  if (forced == nullptr || !(start.time_s > 0)) return start;
  SimTK::State initial = forced->MakeState(start.q, start.u);
  IntegratorOptions options = integrator;
  options.interpolate_outputs = false;  // stop exactly at the forcing's end
  CvodesIntegrator cvodes =
      internal::MakeIntegrator(*forced, options, internal::CalcNewtonJacobian(*forced, initial));
  cvodes.Initialize(std::move(initial));
  const SimTK::State& end = cvodes.AdvanceTo(start.time_s, kUnrealized);
  for (Eigen::Index i = 0; i < start.q.size(); ++i) {
    start.q[i] = end.getQ()[static_cast<int>(i)];
    start.u[i] = end.getU()[static_cast<int>(i)];
  }
  return start;
}

}  // namespace mbid::simulation
