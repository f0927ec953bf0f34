// The searches for more modes (hankel_nls.cc, close_modes.cc) try a trial estimate with more
// poles and keep it only when it holds more significant modes.
#include "mode_trials.h"

#include <fmt/format.h>

#include "mbid/common/error.h"
#include "mode_selection.h"

namespace mbid::identification {
namespace {

// On a noiseless record every mode is "significant": a mode must also carry more than round-off
// of the record's amplitude.
bool CarriesAmplitude(const Estimate& estimate) {
  const double largest = estimate.fit.coefficients.cwiseAbs().maxCoeff();
  for (size_t k = 0; k < estimate.lambda.size(); ++k) {
    const double peak = estimate.fit.coefficients.middleRows(2 * static_cast<Eigen::Index>(k), 2)
                            .cwiseAbs()
                            .maxCoeff();
    if (!(peak > 1e-6 * largest)) return false;
  }
  return true;
}

}  // namespace

// A trial estimate that starts from `estimate`'s poles and keeps its warnings, doubts and orders.
Estimate TrialFrom(const Estimate& estimate) {
  Estimate trial;
  trial.warnings = estimate.warnings;
  trial.doubts = estimate.doubts;
  trial.model_order = estimate.model_order;
  trial.effective_rank = estimate.effective_rank;
  trial.lambda = estimate.lambda;
  return trial;
}

// The warning of a search that added modes: "<added> more significant mode(s) <how>".
void NoteAddedModes(int added, const std::string& how, Estimate* estimate) {
  if (added > 0) {
    estimate->warnings.push_back(fmt::format("{} more significant mode(s) {}", added, how));
  }
}

// Refines `trial` (the estimate's modes and more) and tests it for significance; when it keeps
// more significant modes, all carrying amplitude (and passes `accept`, if given), it replaces the
// estimate. Returns how many modes it added (0: the estimate stands).
int KeepIfMoreModes(const AnalysisRecord& record, const IdentificationOptions& options,
                    const std::function<void(Estimate*)>& refine, Estimate trial,
                    Estimate* estimate, const std::function<bool(const Estimate&)>& accept) {
  try {
    refine(&trial);
    // A refit that `accept` refuses is not tested for significance (its drops refit again).
    if (accept && !accept(trial)) return 0;
    SelectSignificant(record, options, &trial, refine);
  } catch (const NumericalError&) {
    return 0;  // nothing significant from this start: the estimate stands
  }
  if (trial.lambda.size() <= estimate->lambda.size() || !CarriesAmplitude(trial)) return 0;
  if (accept && !accept(trial)) return 0;
  const int added = static_cast<int>(trial.lambda.size() - estimate->lambda.size());
  trial.iterations += estimate->iterations;
  trial.stabilization = std::move(estimate->stabilization);
  trial.noise_std =
      estimate->noise_std;  // the record's, not the trial's: AssessReliability's level
  *estimate = std::move(trial);
  return added;
}

}  // namespace mbid::identification
