#pragma once

// A Simbody force element that applies a model's external load function (private to model/).
#include <functional>
#include <string>
#include <utility>

#include "mbid/model/mechanical_model.h"
#include "mbid/model/simbody.h"

namespace mbid::model {

// Evaluates `load` (owned by the model, may be empty) at the state's time at every force
// evaluation. Reading the time from the state keeps Simbody's caching right: a new time
// invalidates the Dynamics stage. `locate` maps a load point's name to its body and station.
class ExternalLoadForce : public SimTK::Force::Custom::Implementation {
 public:
  using PointLocator =
      std::function<std::pair<SimTK::MobilizedBodyIndex, SimTK::Vec3>(const std::string& point)>;

  ExternalLoadForce(const SimTK::SimbodyMatterSubsystem& matter,
                    const MechanicalModel::ExternalLoadFunction& load, PointLocator locate)
      : matter_(matter), load_(load), locate_(std::move(locate)) {}

  void calcForce(const SimTK::State& state, SimTK::Vector_<SimTK::SpatialVec>& body_forces,
                 SimTK::Vector_<SimTK::Vec3>& /*particle_forces*/,
                 SimTK::Vector& mobility_forces) const override {
    if (!load_) return;
    std::vector<PointLoad> loads;
    Eigen::VectorXd generalized_forces;
    load_(state.getTime(), loads, generalized_forces);
    for (const PointLoad& point_load : loads) {
      const auto [body, station] = locate_(point_load.point);
      const Eigen::Vector3d& f = point_load.force_G;
      matter_.addInStationForce(state, body, station, SimTK::Vec3(f[0], f[1], f[2]), body_forces);
    }
    if (generalized_forces.size() == 0) return;
    if (generalized_forces.size() != mobility_forces.size()) {
      throw std::invalid_argument("external load: one generalized force per coordinate expected");
    }
    for (int i = 0; i < mobility_forces.size(); ++i) mobility_forces[i] += generalized_forces[i];
  }
  SimTK::Real calcPotentialEnergy(const SimTK::State&) const override { return 0; }
  bool dependsOnlyOnPositions() const override { return false; }

 private:
  const SimTK::SimbodyMatterSubsystem& matter_;
  const MechanicalModel::ExternalLoadFunction& load_;
  PointLocator locate_;
};

}  // namespace mbid::model
