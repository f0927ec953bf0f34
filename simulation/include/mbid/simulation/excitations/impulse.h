#pragma once

#include <Eigen/Core>

#include "mbid/model/mechanical_model.h"
#include "mbid/simulation/excitations/force_target.h"

namespace mbid::simulation {

// impulse: from the unloaded rest, a force at a load point (or a torque on a coordinate) acts
// for `duration_s` as a half-sine or rectangular pulse.
struct Impulse {
  static constexpr const char* kTypeName = "impulse";
  static constexpr bool kStartDependsOnModel = false;
  enum class PulseShape { kHalfSine, kRectangular };

  ForceTarget target;
  double duration_s = 0.0;
  PulseShape pulse_shape = PulseShape::kHalfSine;

  static Impulse Read(const YamlReader& node, const model::MechanicalModel& model);
  Eigen::VectorXd CalcInitialCoordinates(const model::MechanicalModel& model) const;
  double CalcForcingEndTime() const { return duration_s; }
  double CalcForcingFactor(double t) const;
  const ForceTarget* force_target() const { return &target; }
};

}  // namespace mbid::simulation
