#pragma once

#include <Eigen/Core>
#include <array>
#include <memory>
#include <string>
#include <vector>

#include "mbid/model/mechanical_model.h"
#include "mbid/model/truck_crane_parameters.h"

namespace mbid::model {

// The truck crane as a Simbody system (docs/reference-crane.md): base B pitching about G's y
// axis through O_a (alpha), slewing mechanism S yawing about B's z through O_s (gamma), boom K
// on a universal joint at F: yaw about S's z (eta), then luffing about -y (theta).
// q = [alpha, gamma, eta, theta]; outputs psi, phi (absolute boom azimuth and elevation minus
// the configuration). Spring neutral angles make the unloaded crane rest at q = 0.
class TruckCrane final : public MechanicalModel {
 public:
  explicit TruckCrane(const TruckCraneParameters& parameters);
  ~TruckCrane() override;

  const TruckCraneParameters& crane_parameters() const;

  std::string type() const override { return "truck_crane"; }
  const std::vector<std::string>& coordinate_names() const override;
  const std::vector<std::string>& output_names() const override;
  const std::vector<std::string>& output_units() const override;
  std::vector<std::string> load_points() const override;
  std::vector<PointLoad> CalcPayloadLoads(double mass_kg) const override;

  std::vector<Parameter> parameters() const override;
  void SetParameter(const std::string& name, double value) override;
  void ApplyParameterToState(SimTK::State& state, const std::string& name,
                             double value) const override;

  const SimTK::MultibodySystem& system() const override;
  SimTK::State MakeState(const Eigen::VectorXd& q, const Eigen::VectorXd& u) const override;
  void SetExternalLoad(ExternalLoadFunction load) override;
  Eigen::VectorXd CalcOutputs(const SimTK::State& state) const override;
  double CalcEnergy(const SimTK::State& state) const override;
  Eigen::VectorXd SolveStaticEquilibrium(const std::vector<PointLoad>& loads) const override;
  LinearModel Linearize() const override;
  std::unique_ptr<MechanicalModel> Clone() const override;

  // The spring neutral angles q0 (rad) of the preload rule.
  Eigen::Vector4d neutral_angles() const;
  // Generalized applied force (N*m) at rest at q, with the static loads: springs, gravity,
  // loads. Zero at a static equilibrium.
  Eigen::VectorXd CalcStaticGeneralizedForce(const Eigen::VectorXd& q,
                                             const std::vector<PointLoad>& loads) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mbid::model
