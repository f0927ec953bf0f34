#pragma once

// A Simbody force element that applies a model's external load function (private to model/).
#include <functional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "mbid/model/mechanical_model.h"
#include "mbid/model/simbody.h"

namespace mbid::model {

// Adds the loads of `load` (may be empty) at the state's time: point loads as body forces,
// generalized forces as mobility forces. `locate` maps a load point's name to its body and
// station. Shared by the force element below and MultibodyModel's state derivative.
using LoadPointLocator =
    std::function<std::pair<SimTK::MobilizedBodyIndex, SimTK::Vec3>(const std::string& point)>;
inline void AddExternalLoads(const SimTK::SimbodyMatterSubsystem& matter,
                             const MechanicalModel::ExternalLoadFunction& load,
                             const LoadPointLocator& locate, const SimTK::State& state,
                             SimTK::Vector_<SimTK::SpatialVec>& body_forces,
                             SimTK::Vector& mobility_forces) {
  if (!load) return;
  std::vector<PointLoad> loads;
  Eigen::VectorXd generalized_forces;
  load(state.getTime(), loads, generalized_forces);
  for (const PointLoad& point_load : loads) {
    const auto [body, station] = locate(point_load.point);
    const Eigen::Vector3d& f = point_load.force_G;
    matter.addInStationForce(state, body, station, SimTK::Vec3(f[0], f[1], f[2]), body_forces);
  }
  if (generalized_forces.size() == 0) return;
  if (generalized_forces.size() != mobility_forces.size()) {
    throw std::invalid_argument("external load: one generalized force per coordinate expected");
  }
  for (int i = 0; i < mobility_forces.size(); ++i) mobility_forces[i] += generalized_forces[i];
}

// A Simbody force element that applies a model's external load function at every force
// evaluation. Reading the time from the state keeps Simbody's caching right: a new time
// invalidates the Dynamics stage.
class ExternalLoadForce : public SimTK::Force::Custom::Implementation {
 public:
  ExternalLoadForce(const SimTK::SimbodyMatterSubsystem& matter,
                    const MechanicalModel::ExternalLoadFunction& load, LoadPointLocator locate)
      : matter_(matter), load_(load), locate_(std::move(locate)) {}

  void calcForce(const SimTK::State& state, SimTK::Vector_<SimTK::SpatialVec>& body_forces,
                 SimTK::Vector_<SimTK::Vec3>& /*particle_forces*/,
                 SimTK::Vector& mobility_forces) const override {
    AddExternalLoads(matter_, load_, locate_, state, body_forces, mobility_forces);
  }
  SimTK::Real calcPotentialEnergy(const SimTK::State&) const override { return 0; }
  bool dependsOnlyOnPositions() const override { return false; }

 private:
  const SimTK::SimbodyMatterSubsystem& matter_;
  const MechanicalModel::ExternalLoadFunction& load_;
  LoadPointLocator locate_;
};

}  // namespace mbid::model
