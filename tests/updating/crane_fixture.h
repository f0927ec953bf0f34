#pragma once

// The reference crane of docs/reference-crane.md as the updating tests use it: the scenario's
// model, excitation and simulation, and records simulated from it.
#include <cmath>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "mbid/common/yaml_reader.h"
#include "mbid/model/model_factory.h"
#include "mbid/simulation/scenario_sections.h"
#include "mbid/simulation/simulate.h"
#include "mbid/updating/output_error.h"

namespace mbid::updating::testing {

// The reference crane's joint parameters, as the updating tunes them.
inline const std::vector<std::string> kAllParameters{"c_alpha", "c_gamma", "c_eta", "c_theta",
                                                     "d_alpha", "d_gamma", "d_eta", "d_theta"};
inline const std::vector<std::string> kStiffnesses{"c_alpha", "c_gamma", "c_eta", "c_theta"};

// Measured numbers for the XML report (RecordProperty), in scientific notation.
inline std::string Sci(double value) {
  std::ostringstream out;
  out.precision(2);
  out << std::scientific << value;
  return out.str();
}

inline const std::string kReferenceScenario =
    std::string(MBID_SOURCE_DIR) + "/scenarios/reference-crane.yaml";
inline const std::string kLoadDropScenario =
    std::string(MBID_SOURCE_DIR) + "/scenarios/reference-crane-load-drop.yaml";

struct Crane {
  std::unique_ptr<model::MechanicalModel> model;
  simulation::Excitation excitation;
  simulation::SimulationOptions simulation;
  simulation::SensorOptions sensors;
};

inline Crane LoadCrane(const YamlReader& root) {
  Crane crane;
  crane.model = model::MakeModel(root.Child("model"));
  crane.excitation = simulation::ReadExcitation(root.Child("excitation"), *crane.model);
  crane.simulation = simulation::ReadSimulationOptions(root.Child("simulation"));
  crane.sensors = simulation::ReadSensorOptions(root.Child("sensors"), *crane.model);
  return crane;
}

inline Crane LoadCrane(const std::string& path) { return LoadCrane(YamlReader::FromFile(path)); }

// The crane's record of `duration_s` at `rate_hz` without sensor effects.
inline Measurement SimulateExact(const Crane& crane, double duration_s, double rate_hz) {
  simulation::SimulationOptions options = crane.simulation;
  options.duration_s = duration_s;
  simulation::SensorOptions sensors;
  sensors.sample_rate_hz = rate_hz;
  sensors.channels = crane.sensors.channels;
  return simulation::Simulate(*crane.model, crane.excitation, options, sensors).exact;
}

// A test `name` of `duration_s` simulated from the crane and measured by its sensors (their noise
// and seed), to be weighed with that noise.
inline TestRecord SimulateTest(const Crane& crane, const std::string& name, double duration_s) {
  simulation::SimulationOptions options = crane.simulation;
  options.duration_s = duration_s;
  const simulation::SimulationResult run =
      simulation::Simulate(*crane.model, crane.excitation, options, crane.sensors);
  return {name, run.measured, crane.excitation, crane.sensors.noise_std};
}

// The fit's settings for `crane`'s records as the scenario reader makes them (its integrator,
// outputs interpolated), quiet, with `names` tuned from `c_factor` (stiffnesses c_*) and
// `d_factor` (dampings d_*) times the truth.
inline UpdateOptions FitFromOff(const Crane& crane, const std::vector<std::string>& names,
                                double c_factor, double d_factor) {
  UpdateOptions options;
  for (const std::string& name : names) {
    ParameterSetting setting;
    setting.name = name;
    setting.initial = crane.model->GetParameter(name) * (name[0] == 'c' ? c_factor : d_factor);
    options.parameters.push_back(setting);
  }
  options.integrator = crane.simulation.integrator;
  options.integrator.interpolate_outputs = true;
  options.quiet = true;
  return options;
}

}  // namespace mbid::updating::testing
