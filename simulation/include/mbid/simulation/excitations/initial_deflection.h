#pragma once

#include <Eigen/Core>
#include <map>
#include <string>

#include "mbid/model/mechanical_model.h"
#include "mbid/simulation/excitations/force_target.h"

namespace mbid::simulation {

// initial_deflection: starts at rest from given coordinates (how the paper chose its set).
struct InitialDeflection {
  static constexpr const char* kTypeName = "initial_deflection";
  static constexpr bool kStartDependsOnModel = false;

  // Per coordinate, in SI: rad for rotational coordinates, m for prismatic ones.
  std::map<std::string, double> deflection_rad;

  static InitialDeflection Read(const YamlReader& node, const model::MechanicalModel& model);
  Eigen::VectorXd CalcInitialCoordinates(const model::MechanicalModel& model) const;
  double CalcForcingEndTime() const { return 0.0; }
  double CalcForcingFactor(double /*t*/) const { return 0.0; }
  const ForceTarget* force_target() const { return nullptr; }
};

}  // namespace mbid::simulation
