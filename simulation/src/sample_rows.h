#pragma once

// Which rows of a sample grid a simulation evaluates, and how it fills the others (private to
// simulation/). A free decay is smooth: sampled far faster than its fastest dynamics (a 1.3 Hz
// arm logged at 5 kHz), its outputs are evaluated at every `stride`-th sample only and
// interpolated between, which saves the model's output evaluations (Simbody realizations, and
// for sensitivities their difference quotients) that dominate a high-rate simulation's cost.

#include <Eigen/Core>
#include <functional>

#include "simulation_setup.h"

namespace mbid::simulation::internal {

// Nodes per period of the fastest eigenvalue: a 6-point Lagrange interpolation of a sinusoid
// errs by at most 0.0049 (omega h)^6 of its amplitude, 1e-10 at 120 nodes, a hundredth of the
// integrator's relative tolerance (1e-8); a harmonic of twice the frequency, a tenth as large as
// the fundamental, errs by 6e-10.
inline constexpr double kNodesPerPeriod = 120;

// Samples per node for a free decay sampled every `tau` by a model whose Newton Jacobian
// (CalcNewtonJacobian) is `jacobian`: the largest whole number that keeps kNodesPerPeriod nodes
// per period of the Jacobian's largest eigenvalue in modulus, or 1 (every sample evaluated)
// where that is 1, the Jacobian is empty, or the integrator does not interpolate its outputs
// (it would then stop at the nodes only, on another trajectory).
int ChooseOutputStride(double tau, const Eigen::MatrixXd& jacobian, bool interpolates_outputs);

// Fills the grid's `count` rows of `width` values. `visit(t, row)` is called in time order: it
// advances the simulation to t and, where `row` is not null, writes the values there. Rows
// before `first_free_row` (a forcing acts) and the first two strides of the free decay are
// visited and evaluated at every sample as before (rows before the record's start are visited
// only); then only every `stride`-th row from `first_free_row` on (a node, also past the grid's
// end where the last rows need it), and the rows between are interpolated from the six nearest
// nodes.
Eigen::MatrixXd SampleRows(const SampleGrid& grid, int first_free_row, int stride, int width,
                           const std::function<void(double t, double* row)>& visit);

// The first row at or after `time_s` (the forcing's end): where the free decay begins.
int FirstRowAtOrAfter(const SampleGrid& grid, double time_s);

}  // namespace mbid::simulation::internal
