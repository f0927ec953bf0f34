#pragma once

// What Simulate and SimulateWithSensitivities both need to set up a test (private to
// simulation/).
#include <memory>
#include <string>
#include <vector>

#include "mbid/model/mechanical_model.h"
#include "mbid/simulation/cvodes_integrator.h"
#include "mbid/simulation/excitation.h"
#include "mbid/simulation/sensor.h"

namespace mbid::simulation::internal {

// Channel c reads output `index` (is_output) or coordinate `index`.
struct ChannelSource {
  bool is_output = true;
  int index = 0;
  std::string units;
};

// Throws InputError for a channel that is neither an output nor a coordinate of `model`.
std::vector<ChannelSource> ResolveChannels(const model::MechanicalModel& model,
                                           const std::vector<std::string>& channels);
// The highest derivative order of the outputs `sources` read (0 positions, 1 rates, 2
// accelerations): how far CalcOutputs must go for them.
int HighestOrderRead(const model::MechanicalModel& model,
                     const std::vector<ChannelSource>& sources);

// A clone of `model` carrying the excitation's time-dependent load, or null for a free decay:
// the caller's model stays unchanged.
std::unique_ptr<model::MechanicalModel> MakeForcedModel(const model::MechanicalModel& model,
                                                        const Excitation& excitation);

// The Newton iteration's Jacobian d[q' u']/d[q u] from the linearization M q'' + D q' + C q = 0:
// [0 I; -M^-1 C  -M^-1 D] (2n x 2n), computed once per simulation. Near the equilibrium it is
// the exact Jacobian; elsewhere an approximation that Newton tolerates. It costs less than one
// difference-quotient Jacobian (NY right-hand sides; 22 of them in the crane's load drop), lets
// Adams use Newton and lets method `auto` choose. Empty (CVODES' difference quotients) unless
// the state `initial` of `model` has Y = [q | u], as every MechanicalModel's has.
Eigen::MatrixXd CalcNewtonJacobian(const model::MechanicalModel& model,
                                   const SimTK::State& initial);

// CVODES on `model`'s state derivative with the Newton Jacobian `jacobian` (CalcNewtonJacobian).
CvodesIntegrator MakeIntegrator(const model::MechanicalModel& model,
                                const IntegratorOptions& options, const Eigen::MatrixXd& jacobian);

// Where the samples of a simulation lie. Rows i = 0..skipped + count - 1 at Time(i); the first
// `skipped` are visited (the integrator stops there as it would for a record from t = 0, so a
// whole-sample start keeps the bits) but not kept.
struct SampleGrid {
  double tau = 0;
  double start_s = 0;  // fractional start; 0 on the whole-sample grid
  int skipped = 0;
  int count = 0;

  double Time(int i) const { return start_s + i * tau; }
  double first_time_s() const { return Time(skipped); }
};

// The grid of `sensors` over [0, duration_s]; std::invalid_argument for a start that is negative,
// not finite or after the duration.
SampleGrid MakeSampleGrid(double duration_s, const SensorOptions& sensors);

}  // namespace mbid::simulation::internal
