#pragma once

#include <Eigen/Core>
#include <map>
#include <string>
#include <vector>

#include "mbid/model/mechanical_model.h"

namespace mbid::simulation {

// How a test excites the machine (docs/scenarios.md, `excitation:`).
//   load_drop           the payload hangs at the boom tip in static equilibrium and is released
//                       at t = 0: the crane then decays freely about its unloaded rest.
//   initial_deflection  starts at rest from given joint angles (how the paper chose its set).
//   impulse             from the unloaded rest, a force at a load point (or a torque on a
//                       coordinate) acts for `duration_s` as a half-sine or rectangular pulse.
//   burst               from rest, a quasi-harmonic force F sin(2 pi f t) for a whole number of
//                       cycles, then free decay.
struct Excitation {
  enum class Type { kLoadDrop, kInitialDeflection, kImpulse, kBurst };
  enum class PulseShape { kHalfSine, kRectangular };

  Type type = Type::kInitialDeflection;
  double payload_mass_kg = 0.0;                  // load_drop
  std::map<std::string, double> deflection_rad;  // initial_deflection, per coordinate
  // impulse and burst: either a force at a load point (N, ground frame) ...
  std::string point;
  Eigen::Vector3d force_N = Eigen::Vector3d::Zero();
  // ... or a torque on a coordinate (N*m).
  std::string coordinate;
  double torque_Nm = 0.0;
  double duration_s = 0.0;  // impulse
  PulseShape pulse_shape = PulseShape::kHalfSine;
  double frequency_hz = 0.0;  // burst
  int cycles = 0;             // burst

  std::string type_name() const;
  // When the forcing ends (s); 0 for load_drop and initial_deflection. The record after it is a
  // free decay.
  double CalcForcingEndTime() const;
  // The forcing's time factor in [-1, 1] at time t (0 outside the forcing).
  double CalcForcingFactor(double t) const;
};

// The state a test starts from, at rest: q (rad) for the model's coordinates.
Eigen::VectorXd CalcInitialCoordinates(const model::MechanicalModel& model,
                                       const Excitation& excitation);

}  // namespace mbid::simulation
