#include <iostream>
#include <vector>

#include "mbid/app/commands.h"
#include "mbid/common/csv_io.h"
#include "mbid/common/error.h"
#include "mbid/common/hdf5_io.h"
#include "mbid/common/json_io.h"
#include "mbid/records/records.h"
#include "mbid/validation/json_summaries.h"
#include "mbid/validation/result_writers.h"
#include "mbid/validation/scenario.h"

namespace mbid::app {
using validation::IntegratorStatisticsToJson;
using validation::LinearModelToJson;
using validation::LoadScenario;
using validation::Scenario;
using validation::WriteSimulationInfo;
using validation::WriteTruth;

namespace {

enum class ExportFormat { kUff, kUffBinary, kMat, kCsv };

// The format an `--export` file asks for by its extension (case-insensitive).
ExportFormat ExportFormatOf(const std::string& path) {
  const std::string extension = records::LowerExtension(path);
  if (extension == ".uff" || extension == ".unv") return ExportFormat::kUff;
  if (extension == ".uffb") return ExportFormat::kUffBinary;
  if (extension == ".mat") return ExportFormat::kMat;
  if (extension == ".csv") return ExportFormat::kCsv;
  throw InputError(
      "--export", path,
      extension.empty() ? "no file extension" : "unknown file extension '" + extension + "'",
      ".uff or .unv (UFF58 ASCII), .uffb (UFF58b binary), .mat (MATLAB v5) or .csv");
}

void Export(const Measurement& measured, const std::string& path) {
  switch (ExportFormatOf(path)) {
    case ExportFormat::kUff:
      records::WriteUff58(measured, path, /*binary=*/false);
      break;
    case ExportFormat::kUffBinary:
      records::WriteUff58(measured, path, /*binary=*/true);
      break;
    case ExportFormat::kMat:
      records::WriteMat(measured, path);
      break;
    case ExportFormat::kCsv:
      WriteMeasurementCsv(measured, path);
      break;
  }
}

}  // namespace

int RunSimulateCommand(const std::string& scenario_path, const std::string& output_path,
                       const CommonOptions& common, const std::vector<std::string>& export_paths) {
  for (const std::string& path : export_paths) ExportFormatOf(path);  // before the simulation
  const Scenario scenario = LoadScenario(scenario_path);
  const auto model = scenario.MakeModel();
  const simulation::Excitation& excitation = scenario.RequireExcitation();
  if (!common.quiet) {
    std::cerr << "mbid: simulating " << scenario.name << " (" << excitation.type_name() << ", "
              << scenario.simulation.duration_s << " s)\n";
  }
  const simulation::SimulationResult result =
      simulation::Simulate(*model, excitation, scenario.simulation, scenario.sensors);

  const validation::ModelTruth truth = validation::CalcModelTruth(*model);
  std::vector<std::string> warnings = simulation::FindStartFarFromRest(*model, excitation);
  for (const std::string& line : model::FindModeDoubts(truth.modes)) warnings.push_back(line);
  for (const std::string& line :
       simulation::FindAliasedModes(truth.modes, result.measured.sample_interval_s)) {
    warnings.push_back(line);
  }
  for (const std::string& line : warnings) std::cerr << "mbid: warning: " << line << "\n";
  H5Writer file(output_path);
  file.WriteMeasurement(result.measured);
  file.WriteScenarioYaml(scenario.yaml_text);
  WriteTruth(file, truth, result);
  WriteSimulationInfo(file, excitation, scenario.simulation, result);

  if (!common.json_path.empty()) {
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
    summary["modes"] = LinearModelToJson(truth.linear, truth.modes)["modes"];
    summary["warnings"] = warnings;
    WriteJson(summary, common.json_path);
  }
  // Each export appears complete or not at all; the HDF5 file only when everything else has
  // succeeded.
  for (const std::string& path : export_paths) Export(result.measured, path);
  file.Commit();
  if (!common.quiet && common.json_path != "-") {
    std::cerr << "mbid: wrote " << output_path << " (" << result.measured.samples() << " samples x "
              << result.measured.channel_count() << " channels, " << result.statistics.steps
              << " CVODES " << simulation::MethodName(result.statistics.method) << " steps)\n";
    for (const std::string& path : export_paths) std::cerr << "mbid: wrote " << path << "\n";
  }
  return 0;
}

}  // namespace mbid::app
