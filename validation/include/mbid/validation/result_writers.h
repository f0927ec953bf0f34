#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "mbid/common/hdf5_io.h"
#include "mbid/model/mechanical_model.h"
#include "mbid/simulation/simulate.h"

namespace mbid::validation {

// What /truth says of a model, computed from it once: a campaign's committer thread writes it
// while the worker that owns the model goes on using it.
struct ModelTruth {
  std::vector<model::Parameter> parameters;
  model::LinearModel linear;
  std::vector<model::Mode> modes;  // of `linear`
  std::vector<std::string> coordinate_names;
  std::vector<std::string> coordinate_units;
  std::vector<std::string> output_units;
};
ModelTruth CalcModelTruth(const model::MechanicalModel& model);

// /truth of a simulated measurement file (docs/interfaces.md): the model's parameters
// (/truth/parameters/<name>, units attribute), the linear model (/truth/linear_model/M, D, C, H),
// its exact modes (/truth/modes/<field>, one entry per mode), the initial coordinates and the
// noise-free record (/truth/exact/<channel>).
void WriteTruth(H5Writer& file, const ModelTruth& truth,
                const simulation::SimulationResult& result);
void WriteTruth(H5Writer& file, const model::MechanicalModel& model,
                const simulation::SimulationResult& result);

// The model's part of /truth alone (parameters, linear model, exact modes): what a campaign case
// that does not simulate keeps. WriteTruth writes it too.
void WriteModelTruth(H5Writer& file, const ModelTruth& truth);

// /simulation: excitation type, forcing end, integrator settings and statistics.
void WriteSimulationInfo(H5Writer& file, const simulation::Excitation& excitation,
                         const simulation::SimulationOptions& options,
                         const simulation::SimulationResult& result);

// The JSON form of the integrator statistics.
nlohmann::json IntegratorStatisticsToJson(const simulation::IntegratorStatistics& statistics);

}  // namespace mbid::validation
