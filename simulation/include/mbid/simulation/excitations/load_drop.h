#pragma once

#include <Eigen/Core>

#include "mbid/model/mechanical_model.h"
#include "mbid/simulation/excitations/force_target.h"

namespace mbid::simulation {

// load_drop: the payload hangs at the boom tip in static equilibrium and is released at t = 0:
// the machine then decays freely about its unloaded rest.
struct LoadDrop {
  static constexpr const char* kTypeName = "load_drop";
  // The loaded equilibrium moves with the model's parameters (sensitivity.cc differentiates it).
  static constexpr bool kStartDependsOnModel = true;

  double payload_mass_kg = 0.0;

  static LoadDrop Read(const YamlReader& node, const model::MechanicalModel& model);
  Eigen::VectorXd CalcInitialCoordinates(const model::MechanicalModel& model) const;
  double CalcForcingEndTime() const { return 0.0; }
  double CalcForcingFactor(double /*t*/) const { return 0.0; }
  const ForceTarget* force_target() const { return nullptr; }
};

}  // namespace mbid::simulation
