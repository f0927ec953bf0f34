#pragma once

// A test record prepared for the output-error fit: its simulation settings, baseline and
// weights. Not part of the public API.

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "baseline.h"
#include "fit_unknowns.h"
#include "mbid/simulation/sensor.h"
#include "mbid/simulation/simulate.h"
#include "mbid/updating/output_error.h"

namespace mbid::updating::internal {

// A record prepared for the fit: a simulation sampled at the record's own times.
struct PreparedTest {
  const TestRecord* test = nullptr;
  simulation::SimulationOptions simulation;
  simulation::SensorOptions sensors;         // rate, start and channels only
  std::shared_ptr<const Baseline> baseline;  // offsets (and drifts) eliminated, or 0 terms
  Eigen::VectorXd sigma;                     // weights in use, per channel
  std::vector<bool> sigma_given;
  std::vector<int> unknowns;  // indices of the unknowns that act on this test
};

// Checks the record against the model and the test's options; `index` is the test's position
// (its nuisance parameters are the unknowns with that test).
PreparedTest PrepareTest(const model::MechanicalModel& model, const TestRecord& test, int index,
                         const std::vector<Unknown>& unknowns, const UpdateOptions& options);

// The baseline of `test` fitted to the difference of record and `fit.simulated` (the model's
// re-simulation), added to it, with standard deviations from the block inverse of the full
// problem: Cov(a) = sigma^2 (B^T B)^-1 + G Cov(x) G^T, G = da/dx (`regression`).
void AddBaseline(const PreparedTest& test, const Eigen::MatrixXd& regression,
                 const Eigen::MatrixXd& covariance, TestFit& fit);

}  // namespace mbid::updating::internal
