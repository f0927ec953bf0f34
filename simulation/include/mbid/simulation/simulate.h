#pragma once

#include <Eigen/Core>

#include "mbid/common/measurement.h"
#include "mbid/model/mechanical_model.h"
#include "mbid/simulation/excitation.h"
#include "mbid/simulation/integrator_options.h"
#include "mbid/simulation/sensor.h"

namespace mbid::simulation {

// `simulation:` of a scenario.
struct SimulationOptions {
  SimulationOptions() { integrator.interpolate_outputs = true; }
  double duration_s = 10.0;
  // Free decays use CVODES' dense output at the sample times (its error is of the order of the
  // local error test, i.e. within the tolerances); forced stretches always stop at each sample.
  IntegratorOptions integrator;
};

struct SimulationResult {
  Measurement exact;          // the model's outputs at the sample times, no sensor effects
  Measurement measured;       // after the sensor model
  Eigen::VectorXd initial_q;  // rad, at t = 0
  IntegratorStatistics statistics;
  double forcing_end_s = 0.0;  // the record is a free decay after this time
};

// Simulates a test: the initial state of `excitation`, CVODES integration of the model's
// Simbody system, outputs (and coordinates, if asked as channels) sampled exactly at
// t_j = start + j / sample_rate up to the duration (start = sensors.start_time_s, 0 by default;
// the result's start_time_s). While a forcing acts the integrator stops
// at each sample time and at the forcing's end; the free decay after it uses dense output when
// options.integrator.interpolate_outputs (the default) is set. CVODES failures propagate as
// NumericalError("CVODES", reason).
SimulationResult Simulate(const model::MechanicalModel& model, const Excitation& excitation,
                          const SimulationOptions& options, const SensorOptions& sensors);

// One line when an initial_deflection starts the machine far from where it rests: its
// coordinates count from q = 0, the unloaded machine's rest, and a payload attached in the
// description rests it elsewhere (a 20 kg payload on a double pendulum: 80 mrad away, for a
// deflection of 4 mrad). For a load drop, one line when the payload deflects a coordinate by
// more than half a turn at rest. Empty otherwise.
std::vector<std::string> FindStartFarFromRest(const model::MechanicalModel& model,
                                              const Excitation& excitation);

// The state where a test's free decay begins: for a free decay the excitation's initial
// coordinates at rest at t = 0; for a forced test (an impulse, a burst) the coordinates and
// speeds where the forcing ends, integrated from rest through it.
struct FreeDecayStart {
  double time_s = 0;
  Eigen::VectorXd q;  // rad or m per coordinate
  Eigen::VectorXd u;  // rad/s or m/s
};
FreeDecayStart CalcFreeDecayStart(const model::MechanicalModel& model, const Excitation& excitation,
                                  const IntegratorOptions& integrator = {});

}  // namespace mbid::simulation
