#include "simulation_setup.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "mbid/common/error.h"
#include "mbid/model/simbody.h"

namespace mbid::simulation::internal {

SampleGrid MakeSampleGrid(double duration_s, const SensorOptions& sensors) {
  const double tau = sensors.sample_interval_s();
  const double start = sensors.start_time_s;
  if (!(start >= 0) || !std::isfinite(start) || start > duration_s) {
    throw std::invalid_argument("sampling start time must lie in [0, duration]");
  }
  SampleGrid grid;
  grid.tau = tau;
  // j = 0..s with s tau <= duration; the tolerance keeps 8 s at 100 Hz at 801 samples.
  const double k = std::round(start / tau);
  if (std::abs(start / tau - k) <= kWholeSampleTolerance) {
    const int total = static_cast<int>(std::floor(duration_s / tau + 1e-9)) + 1;
    grid.skipped = static_cast<int>(k);
    grid.count = total - grid.skipped;
  } else {
    grid.start_s = start;
    grid.count = static_cast<int>(std::floor((duration_s - start) / tau + 1e-9)) + 1;
  }
  if (grid.count < 1) throw std::invalid_argument("no sample between the start and the duration");
  return grid;
}

std::vector<ChannelSource> ResolveChannels(const model::MechanicalModel& model,
                                           const std::vector<std::string>& channels) {
  std::vector<ChannelSource> sources;
  for (const std::string& channel : channels) {
    const auto& outputs = model.output_names();
    const auto& coordinates = model.coordinate_names();
    const auto output = std::find(outputs.begin(), outputs.end(), channel);
    const auto coordinate = std::find(coordinates.begin(), coordinates.end(), channel);
    if (output != outputs.end()) {
      const int i = static_cast<int>(output - outputs.begin());
      sources.push_back({true, i, model.output_units()[i]});
    } else if (coordinate != coordinates.end()) {
      const int i = static_cast<int>(coordinate - coordinates.begin());
      sources.push_back({false, i, model.coordinate_units()[static_cast<size_t>(i)]});
    } else {
      throw InputError("sensors", "channels", "unknown channel '" + channel + "'",
                       "an output or a coordinate of the model");
    }
  }
  return sources;
}

int HighestOrderRead(const model::MechanicalModel& model,
                     const std::vector<ChannelSource>& sources) {
  const std::vector<int> orders = model.output_derivative_orders();
  int highest = 0;
  for (const ChannelSource& source : sources) {
    if (source.is_output) highest = std::max(highest, orders[static_cast<size_t>(source.index)]);
  }
  return highest;
}

std::unique_ptr<model::MechanicalModel> MakeForcedModel(const model::MechanicalModel& model,
                                                        const Excitation& excitation) {
  if (!(excitation.CalcForcingEndTime() > 0)) return nullptr;
  const ForceTarget* target = excitation.force_target();
  if (target == nullptr) return nullptr;
  std::unique_ptr<model::MechanicalModel> forced = model.Clone();
  const int n = model.coordinate_count();
  int torque_index = -1;
  for (int i = 0; i < n; ++i) {
    if (model.coordinate_names()[i] == target->coordinate) torque_index = i;
  }
  forced->SetExternalLoad(
      [excitation, on = *target, n, torque_index](double t, std::vector<model::PointLoad>& loads,
                                                  Eigen::VectorXd& generalized_forces) {
        const double factor = excitation.CalcForcingFactor(t);
        if (factor == 0.0) return;
        if (!on.point.empty()) loads.push_back({on.point, factor * on.force_N});
        if (torque_index >= 0) {
          generalized_forces = Eigen::VectorXd::Zero(n);
          generalized_forces[torque_index] = factor * on.torque_Nm;
        }
      });
  return forced;
}

Eigen::MatrixXd CalcNewtonJacobian(const model::MechanicalModel& model,
                                   const SimTK::State& initial) {
  if (initial.getNY() != 2 * model.coordinate_count()) return Eigen::MatrixXd();
  const model::LinearModel linear = model.Linearize();
  const Eigen::Index n = linear.M.rows();
  const Eigen::LDLT<Eigen::MatrixXd> mass(linear.M);  // symmetric positive definite
  Eigen::MatrixXd jacobian = Eigen::MatrixXd::Zero(2 * n, 2 * n);
  jacobian.topRightCorner(n, n).setIdentity();
  jacobian.bottomLeftCorner(n, n) = -mass.solve(linear.C);
  jacobian.bottomRightCorner(n, n) = -mass.solve(linear.D);
  return jacobian;
}

CvodesIntegrator MakeIntegrator(const model::MechanicalModel& model,
                                const IntegratorOptions& options, const Eigen::MatrixXd& jacobian) {
  CvodesIntegrator made(model.system(), options);
  made.set_jacobian(jacobian);
  made.set_state_derivative(model.MakeStateDerivative());
  return made;
}

}  // namespace mbid::simulation::internal
