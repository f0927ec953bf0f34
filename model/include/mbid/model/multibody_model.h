#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "mbid/model/machine_description.h"
#include "mbid/model/mechanical_model.h"

namespace mbid::model {

// Any machine of docs/machine-description.md as a Simbody system: one mobilizer per body
// (Pin, Slider, Universal or Weld turned onto the described axes), a linear spring and damper
// per sprung coordinate with neutral positions that hold the unloaded machine at q = 0, gravity,
// and the described outputs. q = the joint coordinates in tree order, q' = u.
class MultibodyModel final : public MechanicalModel {
 public:
  // Throws InputError (source "machine description", a key path as field) on a description that
  // breaks the contract, or on a free coordinate that gravity drives at q = 0. `type` is what
  // type() reports ("multibody", or a shorthand's name such as "truck_crane").
  explicit MultibodyModel(MachineDescription machine, std::string type = "multibody");
  ~MultibodyModel() override;
  MultibodyModel(MultibodyModel&&) noexcept;
  MultibodyModel& operator=(MultibodyModel&&) noexcept;

  const MachineDescription& description() const;

  std::string type() const override;
  const std::vector<std::string>& coordinate_names() const override;
  const std::vector<std::string>& output_names() const override;
  const std::vector<std::string>& output_units() const override;
  std::vector<int> output_derivative_orders() const override;
  std::vector<std::string> coordinate_units() const override;
  std::vector<std::string> load_points() const override;
  std::vector<PointLoad> CalcPayloadLoads(double mass_kg) const override;

  std::vector<Parameter> parameters() const override;
  void SetParameter(const std::string& name, double value) override;
  void ApplyParameterToState(SimTK::State& state, const std::string& name,
                             double value) const override;
  // -q_i e_i for c_i (the preload rule keeps the spring force -c q - g_0 affine in c), -u_i e_i
  // for d_i.
  ForceDerivative MakeParameterForceDerivative(const std::string& name) const override;
  // Gravity, the joints' springs and dampers and the external loads, summed as Simbody's force
  // elements sum them.
  StateDerivative MakeStateDerivative() const override;
  Residual MakeResidual() const override;

  const SimTK::MultibodySystem& system() const override;
  SimTK::State MakeState(const Eigen::VectorXd& q, const Eigen::VectorXd& u) const override;
  void SetExternalLoad(ExternalLoadFunction load) override;
  using MechanicalModel::CalcOutputs;
  Eigen::VectorXd CalcOutputs(const SimTK::State& state, int max_order) const override;
  double CalcEnergy(const SimTK::State& state) const override;
  Eigen::VectorXd SolveStaticEquilibrium(const std::vector<PointLoad>& loads) const override;
  LinearModel Linearize() const override;
  std::unique_ptr<MechanicalModel> Clone() const override;

  // The spring neutral positions q_n of the preload rule (0 for free coordinates).
  Eigen::VectorXd neutral_positions() const;
  // Generalized applied force at rest at q with the static loads: springs, gravity, loads. Zero
  // at a static equilibrium.
  Eigen::VectorXd CalcStaticGeneralizedForce(const Eigen::VectorXd& q,
                                             const std::vector<PointLoad>& loads) const;
  // Ground pose of a body at q from the description's kinematics (no Simbody realization):
  // rotation R_GB and origin p_GB (m).
  void CalcBodyPose(const Eigen::VectorXd& q, const std::string& body, Eigen::Matrix3d* R_GB,
                    Eigen::Vector3d* p_GB) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mbid::model
