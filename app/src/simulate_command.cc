#include <iostream>

#include "mbid/app/commands.h"
#include "mbid/app/json_summaries.h"
#include "mbid/app/result_writers.h"
#include "mbid/app/scenario.h"
#include "mbid/common/hdf5_io.h"
#include "mbid/common/json_io.h"

namespace mbid::app {

int RunSimulateCommand(const std::string& scenario_path, const std::string& output_path,
                       const CommonOptions& common) {
  const Scenario scenario = LoadScenario(scenario_path);
  const auto model = scenario.MakeModel();
  const simulation::Excitation& excitation = scenario.RequireExcitation();
  if (!common.quiet) {
    std::cerr << "mbid: simulating " << scenario.name << " (" << excitation.type_name() << ", "
              << scenario.simulation.duration_s << " s)\n";
  }
  const simulation::SimulationResult result =
      simulation::Simulate(*model, excitation, scenario.simulation, scenario.sensors);

  H5Writer file(output_path);
  file.WriteMeasurement(result.measured);
  file.WriteScenarioYaml(scenario.yaml_text);
  WriteTruth(file, *model, result);
  WriteSimulationInfo(file, excitation, scenario.simulation, result);

  if (!common.json_path.empty()) {
    const model::LinearModel linear = model->Linearize();
    nlohmann::json summary{
        {"scenario", scenario.name},
        {"output", output_path},
        {"channels", result.measured.channels},
        {"sample_interval_s", result.measured.sample_interval_s},
        {"samples", result.measured.samples()},
        {"excitation", {{"type", excitation.type_name()}, {"forcing_end_s", result.forcing_end_s}}},
        {"integrator", IntegratorStatisticsToJson(result.statistics)}};
    nlohmann::json initial_q;
    for (int i = 0; i < model->coordinate_count(); ++i) {
      initial_q[model->coordinate_names()[i]] = result.initial_q[i];
    }
    summary["initial_q"] = initial_q;
    summary["modes"] = LinearModelToJson(linear, model::CalcModes(linear))["modes"];
    WriteJson(summary, common.json_path);
  }
  // The HDF5 file appears only when everything else has succeeded.
  file.Commit();
  if (!common.quiet && common.json_path != "-") {
    std::cerr << "mbid: wrote " << output_path << " (" << result.measured.samples() << " samples x "
              << result.measured.channel_count() << " channels, " << result.statistics.steps
              << " CVODES " << simulation::MethodName(result.statistics.method) << " steps)\n";
  }
  return 0;
}

}  // namespace mbid::app
