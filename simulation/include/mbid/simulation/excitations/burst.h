#pragma once

#include <Eigen/Core>

#include "mbid/model/mechanical_model.h"
#include "mbid/simulation/excitations/force_target.h"

namespace mbid::simulation {

// burst: from rest, a quasi-harmonic force F sin(2 pi f t) (or torque) for a whole number of
// cycles, then free decay.
struct Burst {
  static constexpr const char* kTypeName = "burst";
  static constexpr bool kStartDependsOnModel = false;

  ForceTarget target;
  double frequency_hz = 0.0;
  int cycles = 0;

  static Burst Read(const YamlReader& node, const model::MechanicalModel& model);
  Eigen::VectorXd CalcInitialCoordinates(const model::MechanicalModel& model) const;
  double CalcForcingEndTime() const { return cycles / frequency_hz; }
  double CalcForcingFactor(double t) const;
  const ForceTarget* force_target() const { return &target; }
};

}  // namespace mbid::simulation
