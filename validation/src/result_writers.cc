#include "mbid/validation/result_writers.h"

#include <fmt/format.h>

#include <algorithm>

namespace mbid::validation {
namespace {

Eigen::VectorXd ModeField(const std::vector<model::Mode>& modes,
                          double (model::Mode::*field)() const) {
  Eigen::VectorXd values(static_cast<Eigen::Index>(modes.size()));
  for (size_t k = 0; k < modes.size(); ++k)
    values[static_cast<Eigen::Index>(k)] = (modes[k].*field)();
  return values;
}

}  // namespace

ModelTruth CalcModelTruth(const model::MechanicalModel& model) {
  ModelTruth truth;
  truth.parameters = model.parameters();
  truth.linear = model.Linearize();
  truth.modes = model::CalcModes(truth.linear);
  truth.coordinate_names = model.coordinate_names();
  truth.coordinate_units = model.coordinate_units();
  truth.output_units = model.output_units();
  return truth;
}

void WriteTruth(H5Writer& file, const ModelTruth& truth,
                const simulation::SimulationResult& result) {
  WriteModelTruth(file, truth);
  // One unit where the coordinates share it (a slide's m), else /truth/linear_model's per
  // coordinate.
  const std::vector<std::string>& units = truth.coordinate_units;
  const bool one_unit =
      !units.empty() && std::all_of(units.begin(), units.end(),
                                    [&](const std::string& unit) { return unit == units[0]; });
  file.WriteVector("/truth", "initial_q", result.initial_q,
                   one_unit ? units[0] : "SI, per coordinate_units");
  file.WriteStrings("/truth", "coordinates", truth.coordinate_names);
  for (int c = 0; c < result.exact.channel_count(); ++c) {
    file.WriteVector("/truth/exact", result.exact.channels[c], result.exact.values.col(c),
                     result.exact.units[c]);
  }
}

void WriteTruth(H5Writer& file, const model::MechanicalModel& model,
                const simulation::SimulationResult& result) {
  WriteTruth(file, CalcModelTruth(model), result);
}

void WriteModelTruth(H5Writer& file, const ModelTruth& truth) {
  for (const model::Parameter& parameter : truth.parameters) {
    file.WriteScalar("/truth/parameters", parameter.name, parameter.value, parameter.units);
  }
  const model::LinearModel& linear = truth.linear;
  file.WriteStrings("/truth/linear_model", "coordinates", linear.coordinates);
  file.WriteStrings("/truth/linear_model", "outputs", linear.outputs);
  const std::vector<std::string>& coordinate_units = truth.coordinate_units;
  const bool angles = std::all_of(coordinate_units.begin(), coordinate_units.end(),
                                  [](const std::string& unit) { return unit == "rad"; });
  file.WriteStrings("/truth/linear_model", "coordinate_units", coordinate_units);
  file.WriteStrings("/truth/linear_model", "output_units", truth.output_units);
  std::vector<double> orders(linear.outputs.size(), 0.0);
  for (size_t i = 0; i < linear.output_orders.size() && i < orders.size(); ++i) {
    orders[i] = linear.output_orders[i];
  }
  file.WriteVector(
      "/truth/linear_model", "output_orders",
      Eigen::Map<const Eigen::VectorXd>(orders.data(), static_cast<Eigen::Index>(orders.size())),
      "1");
  // Mixed machines (angles and slides) have no single unit per matrix.
  const bool plain_outputs =
      std::all_of(truth.output_units.begin(), truth.output_units.end(),
                  [](const std::string& unit) { return unit == "rad"; }) &&
      std::all_of(orders.begin(), orders.end(), [](double order) { return order == 0; });
  file.WriteMatrix("/truth/linear_model", "M", linear.M, angles ? "kg*m^2" : "SI, per coordinate");
  file.WriteMatrix("/truth/linear_model", "D", linear.D,
                   model::DampingMatrixUnits(coordinate_units));
  file.WriteMatrix("/truth/linear_model", "C", linear.C,
                   model::StiffnessMatrixUnits(coordinate_units));
  file.WriteMatrix("/truth/linear_model", "H", linear.H,
                   angles && plain_outputs
                       ? "rad/rad"
                       : "output_units per coordinate_units (and output_orders)");

  const std::vector<model::Mode>& modes = truth.modes;
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

}  // namespace mbid::validation
