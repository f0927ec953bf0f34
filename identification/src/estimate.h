#pragma once

// What an identification method (methods/method.h) hands back to Identify, and the pole helpers
// the methods share; not part of the public API.

#include <Eigen/Core>
#include <complex>
#include <string>
#include <vector>

#include "mbid/identification/modal_fit.h"
#include "mbid/identification/modal_result.h"
#include "mbid/identification/options.h"
#include "record.h"

namespace mbid::identification {

using Poles = std::vector<std::complex<double>>;

struct Estimate {
  Poles lambda;
  std::vector<double> significance;
  int model_order = 0;
  int effective_rank = 0;
  Eigen::VectorXd weights;  // per channel, for the covariance on the decimated record
  // Per channel noise level of the decimated record, independent of the fit (hankel_svd.h).
  Eigen::VectorXd noise_std;
  AmplitudeFit fit;  // on the decimated record, for the poles in `lambda`
  std::string termination = "converged";
  std::string termination_message;
  int iterations = 0;
  std::vector<StabilizationOrder> stabilization;
  std::vector<std::string> warnings;
  std::vector<std::string> doubts;  // what the data do not support: AssessReliability's reasons
};

// The decimated record less the estimate's fit: what its modes leave, samples x channels.
Eigen::MatrixXd DecimatedResidual(const AnalysisRecord& record, const Estimate& estimate);

// The lowest noise level channel c of `values` is judged against: a noiseless record's
// round-off, 1e-6 of the channel's RMS (in variance, 1e-12 of its mean square).
double RoundOffNoiseStd(const Eigen::MatrixXd& values, Eigen::Index c);

// NumericalError("identification", "no modes found: <reason>").
[[noreturn]] void NoModes(const std::string& reason);

// Step 5 of method.md: a continuous pole is a mode if it oscillates inside the band and its
// damping and decay are inside the limits.
bool PassesFilter(std::complex<double> lambda, const IdentificationOptions& options,
                  double max_frequency_hz);
// Eq. 4: the continuous poles of discrete ones mu at the sample interval tau.
Poles ToContinuous(const Poles& mu, double tau);
// Whether some pole of `others` lies within tolerance * |lambda| of lambda.
bool HasMatch(std::complex<double> lambda, const Poles& others, double tolerance);

// Keeps the modes that pass `keep`; returns how many were dropped.
template <typename Keep>
int DropModes(Poles* lambda, Keep&& keep) {
  Poles kept;
  for (size_t k = 0; k < lambda->size(); ++k) {
    if (keep(k)) kept.push_back((*lambda)[k]);
  }
  const int dropped = static_cast<int>(lambda->size() - kept.size());
  *lambda = kept;
  return dropped;
}

// The highest order of the stabilization data: stabilization_max_order, or automatic from the
// effective rank; at most `cap`.
int AutoStabilizationOrder(const IdentificationOptions& options, int effective_rank, int cap);
// Marks poles of each order that reappear at order + 2 within `tolerance` * |lambda|.
void MarkStable(std::vector<StabilizationOrder>* orders, double tolerance);
// The stabilization entry of one order: its finite poles in the upper half plane.
StabilizationOrder UpperHalf(int order, const Poles& lambda);

}  // namespace mbid::identification
