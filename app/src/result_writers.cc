#include "mbid/app/result_writers.h"

#include <fmt/format.h>

namespace mbid::app {
namespace {

Eigen::VectorXd ModeField(const std::vector<model::Mode>& modes,
                          double (model::Mode::*field)() const) {
  Eigen::VectorXd values(static_cast<Eigen::Index>(modes.size()));
  for (size_t k = 0; k < modes.size(); ++k)
    values[static_cast<Eigen::Index>(k)] = (modes[k].*field)();
  return values;
}

}  // namespace

void WriteTruth(H5Writer& file, const model::MechanicalModel& model,
                const simulation::SimulationResult& result) {
  WriteModelTruth(file, model);
  file.WriteVector("/truth", "initial_q", result.initial_q, "rad");
  file.WriteStrings("/truth", "coordinates", model.coordinate_names());
  for (int c = 0; c < result.exact.channel_count(); ++c) {
    file.WriteVector("/truth/exact", result.exact.channels[c], result.exact.values.col(c),
                     result.exact.units[c]);
  }
}

void WriteModelTruth(H5Writer& file, const model::MechanicalModel& model) {
  for (const model::Parameter& parameter : model.parameters()) {
    file.WriteScalar("/truth/parameters", parameter.name, parameter.value, parameter.units);
  }
  const model::LinearModel linear = model.Linearize();
  file.WriteStrings("/truth/linear_model", "coordinates", linear.coordinates);
  file.WriteStrings("/truth/linear_model", "outputs", linear.outputs);
  file.WriteMatrix("/truth/linear_model", "M", linear.M, "kg*m^2");
  file.WriteMatrix("/truth/linear_model", "D", linear.D, "N*m*s/rad");
  file.WriteMatrix("/truth/linear_model", "C", linear.C, "N*m/rad");
  file.WriteMatrix("/truth/linear_model", "H", linear.H, "rad/rad");

  const std::vector<model::Mode> modes = model::CalcModes(linear);
  file.WriteVector("/truth/modes", "frequency_hz", ModeField(modes, &model::Mode::frequency_hz),
                   "Hz");
  file.WriteVector("/truth/modes", "decay_rate_per_s",
                   ModeField(modes, &model::Mode::decay_rate_per_s), "1/s");
  file.WriteVector("/truth/modes", "damping_ratio", ModeField(modes, &model::Mode::damping_ratio),
                   "1");
  file.WriteVector("/truth/modes", "undamped_frequency_hz",
                   ModeField(modes, &model::Mode::undamped_frequency_hz), "Hz");
  file.WriteVector("/truth/modes", "half_life_s", ModeField(modes, &model::Mode::half_life_s), "s");
}

void WriteSimulationInfo(H5Writer& file, const simulation::Excitation& excitation,
                         const simulation::SimulationOptions& options,
                         const simulation::SimulationResult& result) {
  file.WriteStringAttribute("/simulation", "excitation", excitation.type_name());
  file.WriteScalar("/simulation", "forcing_end_s", result.forcing_end_s, "s");
  file.WriteScalar("/simulation", "duration_s", options.duration_s, "s");
  // The method that ran (`auto` resolved).
  file.WriteStringAttribute(
      "/simulation", "integrator",
      std::string("cvodes_") + simulation::MethodName(result.statistics.method));
  file.WriteScalar("/simulation", "relative_tolerance", options.integrator.relative_tolerance, "1");
  file.WriteScalar("/simulation", "absolute_tolerance", options.integrator.absolute_tolerance, "1");
  const nlohmann::json statistics = IntegratorStatisticsToJson(result.statistics);
  for (const auto& [name, value] : statistics.items()) {
    if (!value.is_number()) continue;  // the method: the `integrator` attribute above
    file.WriteScalar("/simulation/statistics", name, value.get<double>(),
                     name == "last_step_s" ? "s" : "1");
  }
}

nlohmann::json IntegratorStatisticsToJson(const simulation::IntegratorStatistics& s) {
  return {{"method", simulation::MethodName(s.method)},
          {"steps", s.steps},
          {"rhs_evaluations", s.rhs_evaluations},
          {"rhs_evaluations_for_jacobian", s.rhs_evaluations_for_jacobian},
          {"jacobian_evaluations", s.jacobian_evaluations},
          {"linear_solver_setups", s.linear_solver_setups},
          {"error_test_failures", s.error_test_failures},
          {"nonlinear_iterations", s.nonlinear_iterations},
          {"nonlinear_convergence_failures", s.nonlinear_convergence_failures},
          {"last_step_s", s.last_step_s},
          {"last_order", s.last_order}};
}

}  // namespace mbid::app
