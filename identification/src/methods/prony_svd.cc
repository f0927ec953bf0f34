// prony-svd: the paper's method, steps 2-5 of method.md (vector AR with constant term, eq. 3-4),
// then the same linear amplitude fit and significance test as the default, no refinement.
#include "mbid/identification/prony_svd.h"

#include <fmt/format.h>

#include <algorithm>
#include <numeric>

#include "estimate.h"
#include "mbid/identification/hankel_svd.h"
#include "mbid/identification/modal_fit.h"
#include "mbid/identification/significance.h"
#include "methods/method.h"
#include "mode_selection.h"

namespace mbid::identification {
namespace {

Estimate EstimatePronySvd(const AnalysisRecord& record, const IdentificationOptions& options) {
  const Eigen::MatrixXd& values = record.decimated;
  const double tau = record.decimated_interval_s;
  // Each channel's noise level sets the scale of step 3's threshold.
  const int samples = static_cast<int>(values.rows());
  const int columns = std::max(8, std::min(samples / 3, options.hankel.max_columns));
  const Eigen::VectorXd noise =
      HankelSvd(values, columns, 2 * options.max_modes + 1).channel_noise_std();
  const auto solve = [&](int p) {
    return SolvePronySvd(values, tau, p, options.prony.rank_tolerance,
                         options.prony.noise_floor_factor,
                         options.prony.noise_floor_factor > 0 ? noise : Eigen::VectorXd());
  };
  // Steps 2-4.
  const PronySvdSolution solution = solve(options.prony.order);
  Estimate estimate;
  estimate.noise_std = noise;
  estimate.model_order = solution.order;
  estimate.effective_rank = solution.effective_rank;
  if (options.compute_stabilization) {
    const int highest = options.stabilization_max_order > 0
                            ? std::min(options.stabilization_max_order, options.prony.order)
                            : options.prony.order;
    // At most about 20 orders: each is an SVD of the whole record.
    const int step = std::max(1, (highest + 19) / 20);
    for (int p = step; p <= highest; p += step) {
      const PronySvdSolution at_order = p == solution.order ? solution : solve(p);
      estimate.stabilization.push_back(UpperHalf(p, at_order.lambda));
    }
    MarkStable(&estimate.stabilization, options.hankel.stability_tolerance);
  }
  // Step 5: the poles inside the limits.
  for (const auto& lambda : solution.lambda) {
    if (lambda.imag() > 0 && PassesFilter(lambda, options, record.max_frequency_hz)) {
      estimate.lambda.push_back(lambda);
    }
  }
  if (estimate.lambda.empty()) {
    NoModes(
        fmt::format("none of the {} roots of eq. 3 (p = {}) is an oscillation inside the "
                    "band and the damping limits",
                    solution.lambda.size(), solution.order));
  }
  if (static_cast<int>(estimate.lambda.size()) > options.max_modes) {
    // Keep exactly the max_modes most significant candidates (ties broken by frequency order).
    const bool with_offset = options.offset == OffsetRemoval::kFit;
    const AmplitudeFit fit =
        FitAmplitudes(record.decimated, record.decimated_interval_s, estimate.lambda, with_offset);
    const Eigen::VectorXd significance = CalcSignificance(fit);
    std::vector<size_t> rank(estimate.lambda.size());
    std::iota(rank.begin(), rank.end(), 0);
    std::stable_sort(rank.begin(), rank.end(),
                     [&](size_t a, size_t b) { return significance(a) > significance(b); });
    std::vector<bool> keep(rank.size(), false);
    for (int i = 0; i < options.max_modes; ++i) keep[rank[i]] = true;
    const int candidates = static_cast<int>(estimate.lambda.size());
    DropModes(&estimate.lambda, [&](size_t k) { return keep[k]; });
    estimate.warnings.push_back(
        fmt::format("kept the {} most significant of {} candidate poles (max_modes)",
                    options.max_modes, candidates));
  }
  SelectSignificant(record, options, &estimate, [](Estimate*) {});
  // Maximum-likelihood weights for the covariance: each channel's residual level.
  estimate.weights = estimate.fit.residual_variance.cwiseSqrt().cwiseInverse();
  return estimate;
}

// Rows j = 0..s-p of eq. 3 must at least match the m p + 1 unknowns per channel.
int PronyMinimumSamples(const IdentificationOptions& options, int channels) {
  return (channels + 1) * options.prony.order + 1;
}

std::string PronyRequirement(const IdentificationOptions& options, int channels) {
  return fmt::format("order p = {} with {} channels", options.prony.order, channels);
}

}  // namespace

MethodDefinition PronySvdMethod() {
  return {"prony-svd", &PronyMinimumSamples, &PronyRequirement, &EstimatePronySvd};
}

}  // namespace mbid::identification
