#pragma once

// The torsional oscillator the Fisher and planning tests share: J theta'' + d theta' + c theta = 0
// with J = 2 kg m^2, c = 800 N m/rad, d = 8 N m s/rad: omega_0 = 20 rad/s (3.2 Hz), damping ratio
// d / (2 sqrt(c J)) = 0.1; a 2 s release at 100 Hz holds about 6 decaying cycles.
#include <memory>
#include <string>

#include "mbid/common/yaml_reader.h"
#include "mbid/model/model_factory.h"
#include "mbid/updating/fisher.h"

namespace mbid::updating::testing {

inline std::unique_ptr<model::MechanicalModel> MakeOscillator(double stiffness = 800.0) {
  return model::MakeModel(
      YamlReader::FromString("type: torsional_oscillator\ninertia_kgm2: 2.0\n"
                             "joints: {angle: {stiffness_Nm_per_rad: " +
                                 std::to_string(stiffness) + ", damping_Nms_per_rad: 8.0}}\n",
                             "oscillator"));
}

// A release from rest at `deflection_rad`, 2 s at 100 Hz, the angle measured with `noise_rad`.
inline TestDesign OscillatorRelease(const std::string& name, double deflection_rad,
                                    double noise_rad) {
  TestDesign design;
  design.name = name;
  simulation::InitialDeflection deflection;
  deflection.deflection_rad["angle"] = deflection_rad;
  design.excitation = deflection;
  design.simulation.duration_s = 2.0;
  design.simulation.integrator.method = simulation::IntegratorOptions::Method::kBdf;
  design.sensors.sample_rate_hz = 100.0;
  design.sensors.channels = {"angle"};
  design.sensors.noise_std["angle"] = noise_rad;
  return design;
}

}  // namespace mbid::updating::testing
