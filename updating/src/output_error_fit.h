#pragma once

// One fit of the output-error problem (UpdateModel's stages). Not part of the public API.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "mbid/model/mechanical_model.h"
#include "mbid/updating/output_error.h"

namespace mbid::updating::internal {

// One fit of the whole problem (one continuation stage; with estimated noise two passes). The
// initial cost is reported at `report_start` (values of the unknowns) if given, else at the
// options' starts.
UpdateResult Fit(const model::MechanicalModel& model, const std::vector<TestRecord>& tests,
                 const UpdateOptions& options, int first_stage, const std::string& stage_label,
                 const std::vector<double>* report_start);

// The cost (0.5 sum of squared weighted residuals) at the options' starts: what one Ceres
// iteration reports as its initial cost, from simulations without sensitivities. Throws
// NumericalError if a simulation fails there.
double CalcStartCost(const model::MechanicalModel& model, const std::vector<TestRecord>& tests,
                     const UpdateOptions& options);

// The Fisher covariance (Ceres' coordinates, the unknowns' order; NaN rows in a flat direction)
// at each of `points`, with the tests' weights as given. Each point costs one simulation with
// sensitivities.
std::vector<Eigen::MatrixXd> CalcCovarianceAt(const model::MechanicalModel& model,
                                              const std::vector<TestRecord>& tests,
                                              const UpdateOptions& options,
                                              const std::vector<Eigen::VectorXd>& points);

}  // namespace mbid::updating::internal
