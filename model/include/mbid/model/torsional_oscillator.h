#pragma once

#include <memory>
#include <string>
#include <vector>

#include "mbid/model/mechanical_model.h"

namespace mbid::model {

// The simplest machine: one rigid body on a pin (no gravity), a spring and a damper,
//   J theta'' + d theta' + c theta = tau(t),   y = theta,
// with the closed-form poles lambda = -d / (2 J) +- i sqrt(c / J - (d / (2 J))^2). It checks the
// framework against analytic truth and shows that a new machine is a new model, not a fork:
// coordinate and output "angle", parameters c_angle, d_angle. Load point "rim": a point at
// radius 1 m on the body's x axis, so a force (0, F, 0) there is a torque F.
struct TorsionalOscillatorParameters {
  double inertia_kgm2 = 1.0;
  double stiffness_Nm_per_rad = 1.0;
  double damping_Nms_per_rad = 0.0;
  void Validate() const;  // InputError unless J, c > 0 and d >= 0, all finite
};

class TorsionalOscillator final : public MechanicalModel {
 public:
  explicit TorsionalOscillator(const TorsionalOscillatorParameters& parameters);
  ~TorsionalOscillator() override;

  std::string type() const override { return "torsional_oscillator"; }
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

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mbid::model
