// hankel-nls, the default method: block-Hankel SVD (matrix pencil) initialization with the order
// from the noise floor and stability across orders, then a Ceres refinement of all poles and
// amplitudes.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <string>

#include "close_modes.h"
#include "estimate.h"
#include "internal.h"
#include "mbid/common/error.h"
#include "mbid/identification/hankel_svd.h"
#include "mbid/identification/modal_fit.h"
#include "mbid/identification/refinement.h"
#include "methods/method.h"
#include "mode_selection.h"
#include "mode_trials.h"
#include "residual_windows.h"

namespace mbid::identification {
namespace {

// Continuous poles per order, each computed once (the stabilization data and the stability
// check ask for the same orders).
class PolesByOrder {
 public:
  PolesByOrder(const HankelSvd& hankel, double tau) : hankel_(hankel), tau_(tau) {}

  const Poles& At(int order) {
    auto found = poles_.find(order);
    if (found == poles_.end()) {
      found = poles_.emplace(order, ToContinuous(hankel_.CalcPoles(order), tau_)).first;
    }
    return found->second;
  }

 private:
  const HankelSvd& hankel_;
  double tau_;
  std::map<int, Poles> poles_;
};

// A pole that may start a mode: in the upper half plane, inside the step-5 limits and below the
// Nyquist frequency. A pole at the Nyquist frequency is the continuous image of a real negative
// discrete pole, a sequence that changes sign at every sample: no oscillation the samples
// resolve (its sine column vanishes), but the form white noise often takes above the signal
// order. Refined as a mode, it is a weakly determined pole whose Gauss-Newton steps converge
// only linearly (26 of the 28 iterations on the reference crane's record) before the
// significance test drops it.
bool IsCandidate(std::complex<double> lambda, const AnalysisRecord& record,
                 const IdentificationOptions& options) {
  const bool at_nyquist = lambda.imag() >= (1 - 1e-6) * M_PI / record.decimated_interval_s;
  return lambda.imag() > 0 && !at_nyquist && PassesFilter(lambda, options, record.max_frequency_hz);
}

// Whether `lambda`, a pole at `order`, reappears at each of the next stability_orders orders
// (those the Hankel matrix's columns allow).
bool IsStable(std::complex<double> lambda, int order, int columns,
              const IdentificationOptions& options, PolesByOrder& poles_at) {
  for (int s = 1; s <= options.hankel.stability_orders; ++s) {
    const int higher = order + 2 * s;
    if (higher >= columns - 1) break;
    if (!HasMatch(lambda, poles_at.At(higher), options.hankel.stability_tolerance)) return false;
  }
  return true;
}

// Candidates: upper-half poles at the signal order inside the step-5 limits, below the Nyquist
// frequency and stable across the next orders.
void AddStableCandidates(const AnalysisRecord& record, const IdentificationOptions& options,
                         int order, int columns, PolesByOrder& poles_at, Estimate* estimate) {
  const Poles& poles = poles_at.At(order);
  int unstable = 0;
  for (const auto& lambda : poles) {
    if (!IsCandidate(lambda, record, options)) continue;
    if (IsStable(lambda, order, columns, options, poles_at)) {
      estimate->lambda.push_back(lambda);
    } else {
      ++unstable;
    }
  }
  if (unstable > 0) {
    estimate->warnings.push_back(fmt::format(
        "dropped {} pole(s) of order {} that are not stable across orders", unstable, order));
  }
  if (estimate->lambda.empty()) {
    NoModes(
        fmt::format("none of the {} poles at signal order {} is an oscillation inside the band "
                    "({} .. {} Hz), the damping limits ({} .. {}) and stable across orders",
                    poles.size(), order, options.min_frequency_hz, record.max_frequency_hz,
                    options.min_damping_ratio, options.max_damping_ratio));
  }
}

// Refines the poles of an estimate; drops those that leave the step-5 limits. Keeps the channel
// weights across calls: a reweighting found once holds for later refits.
class Refiner {
 public:
  Refiner(const AnalysisRecord& record, const IdentificationOptions& options,
          const Eigen::VectorXd& channel_noise_std)
      : record_(record),
        options_(options),
        values_(record.decimated),
        tau_(record.decimated_interval_s),
        with_offset_(options.offset == OffsetRemoval::kFit),
        weights_(Eigen::VectorXd::Ones(record.decimated.cols())) {
    if (options.refinement.weight_channels_by_noise) {
      weights_ = channel_noise_std.cwiseInverse();
      weights_ /= weights_.maxCoeff();  // only ratios matter; keeps the cost of order one
    }
  }

  const Eigen::VectorXd& weights() const { return weights_; }

  void operator()(Estimate* e) {
    for (;;) {
      const RefinementSummary summary = RefineOnce(e->lambda);
      e->termination = summary.termination;
      e->termination_message = summary.message;
      e->iterations += summary.iterations;
      e->lambda = summary.model.lambda;
      const int left = DropModes(&e->lambda, [&](size_t k) {
        return PassesFilter(e->lambda[k], options_, record_.max_frequency_hz);
      });
      if (left > 0) {
        e->warnings.push_back(fmt::format(
            "dropped {} mode(s) that the refinement moved outside the step-5 limits", left));
      }
      if (e->lambda.empty()) {
        NoModes("every refined pole left the band or the damping limits");
      }
      if (left == 0) return;
    }
  }

 private:
  RefinementSummary RefineOnce(const Poles& lambda) {
    ModalModel initial;
    initial.lambda = lambda;
    initial.with_offset = with_offset_;
    initial.coefficients = FitAmplitudes(values_, tau_, lambda, with_offset_).coefficients;
    RefinementSummary summary =
        RefineModalModel(values_, tau_, weights_, initial, options_.refinement);
    // Maximum likelihood weighs channels by their noise; if the Hankel estimate of the
    // ratios was off by more than 20 %, refine once more with the residuals' levels.
    if (options_.refinement.weight_channels_by_noise && values_.cols() > 1) {
      const AmplitudeFit fit = FitAmplitudes(values_, tau_, summary.model.lambda, with_offset_);
      const Eigen::VectorXd noise = fit.residual_variance.cwiseSqrt();
      Eigen::VectorXd updated = noise.cwiseMax(1e-300).cwiseInverse();
      updated /= updated.maxCoeff();
      const double change = (updated.array() / weights_.array()).maxCoeff() /
                            (updated.array() / weights_.array()).minCoeff();
      if (change > 1.2) {
        weights_ = updated;
        initial.lambda = summary.model.lambda;
        initial.coefficients = summary.model.coefficients;
        const int previous = summary.iterations;
        summary = RefineModalModel(values_, tau_, weights_, initial, options_.refinement);
        summary.iterations += previous;
      }
    }
    return summary;
  }

  const AnalysisRecord& record_;
  const IdentificationOptions& options_;
  const Eigen::MatrixXd& values_;
  double tau_;
  bool with_offset_;
  Eigen::VectorXd weights_;
};

// A mode that lives in few of many channels brings its energy to one channel but the noise of
// all to the summed Hankel matrix, and may stay under the signal order there (a machine's slew
// mode seen by its gyro alone beside three channels that barely see it). Where a channel's
// residual stays above 3 times its noise (as AssessReliability flags it), that residual alone is
// searched at its own signal order: its poles, stable across orders, that the estimate lacks join
// the estimate's, and the refit with more significant modes is kept.
void AddModesFromSingleChannels(const AnalysisRecord& record, const IdentificationOptions& options,
                                int columns, int max_order, const Eigen::VectorXd& noise_std,
                                const std::function<void(Estimate*)>& refine, Estimate* estimate) {
  const Eigen::MatrixXd& values = record.decimated;
  if (values.cols() < 2) return;
  // Also a channel whose residual has 4 times its noise power in some window (a weak tone at
  // the start of an excavator's accelerometer record).
  const Eigen::VectorXd window_ratio =
      AnalyseResidualWindows(values, DecimatedResidual(record, *estimate),
                             options.significance_false_alarm)
          .channel_ratio;
  int added = 0;
  for (Eigen::Index c = 0; c < values.cols(); ++c) {
    const Eigen::VectorXd& residual = estimate->fit.residual_variance;
    if (c >= residual.size() || c >= noise_std.size()) break;
    if (!(std::sqrt(residual(c)) > 3 * std::max(noise_std(c), RoundOffNoiseStd(values, c))) &&
        !(window_ratio(c) >= 4)) {
      continue;
    }
    // The channel's residual: the modes found no longer hide the one it lacks.
    const Eigen::VectorXd left =
        values.col(c) - estimate->fit.reconstruction.col(c).head(values.rows());
    const HankelSvd single(left, columns, max_order);
    const int order = single.CountSignal(options.hankel.noise_floor_factor,
                                         options.hankel.min_relative_singular_value, max_order);
    if (order == 0) continue;
    PolesByOrder poles_at(single, record.decimated_interval_s);
    Estimate trial = TrialFrom(*estimate);
    for (const auto& lambda : poles_at.At(order)) {
      if (!IsCandidate(lambda, record, options) ||
          HasMatch(lambda, estimate->lambda, options.hankel.stability_tolerance)) {
        continue;
      }
      if (IsStable(lambda, order, columns, options, poles_at)) trial.lambda.push_back(lambda);
    }
    if (trial.lambda.size() == estimate->lambda.size()) continue;
    added += KeepIfMoreModes(record, options, refine, std::move(trial), estimate);
  }
  NoteAddedModes(added,
                 "found in single channels whose residual the other modes left above the noise",
                 estimate);
}

// HankelOptions::extra_orders: restarts from every pole at the orders above the signal order;
// a start that ends with more significant modes replaces the estimate.
void AddModesFromHigherOrders(const AnalysisRecord& record, const IdentificationOptions& options,
                              int order, int columns, PolesByOrder& poles_at,
                              const std::function<void(Estimate*)>& refine, Estimate* estimate) {
  int added = 0;
  const int highest = std::min(order + 2 * options.hankel.extra_orders, columns - 2);
  for (int higher = order + 2; higher <= highest; higher += 2) {
    Estimate trial = TrialFrom(*estimate);
    trial.lambda.clear();
    for (const auto& lambda : poles_at.At(higher)) {
      if (IsCandidate(lambda, record, options)) trial.lambda.push_back(lambda);
    }
    if (trial.lambda.size() <= estimate->lambda.size()) continue;
    added += KeepIfMoreModes(record, options, refine, std::move(trial), estimate);
  }
  NoteAddedModes(added,
                 fmt::format("found by restarting from orders above the signal order {}", order),
                 estimate);
}

Estimate EstimateHankelNls(const AnalysisRecord& record, const IdentificationOptions& options) {
  const Eigen::MatrixXd& values = record.decimated;
  const double tau = record.decimated_interval_s;
  const int samples = static_cast<int>(values.rows());
  const int columns = std::max(8, std::min(samples / 3, options.hankel.max_columns));
  const int max_order = 2 * options.max_modes + 1;  // + 1: a constant or real pole
  const HankelSvd hankel(values, columns, max_order);
  PolesByOrder poles_at(hankel, tau);

  Estimate estimate;
  estimate.noise_std = hankel.channel_noise_std();
  estimate.model_order = columns - 1;
  const int order = hankel.CountSignal(options.hankel.noise_floor_factor,
                                       options.hankel.min_relative_singular_value, max_order);
  estimate.effective_rank = order;
  if (options.compute_stabilization) {
    const int highest = AutoStabilizationOrder(options, order, columns - 2);
    for (int m = 1; m <= highest; ++m) {
      estimate.stabilization.push_back(UpperHalf(m, poles_at.At(m)));
    }
    MarkStable(&estimate.stabilization, options.hankel.stability_tolerance);
  }
  if (order == 0) {
    const double s = hankel.singular_values()(0);
    NoModes(fmt::format(
        "no singular value of the Hankel matrix is above the noise (the largest squared one is "
        "{:.3g} times what white noise gives, the threshold hankel.noise_floor_factor is {})",
        s * s / (hankel.noise_floor() * hankel.noise_edge()), options.hankel.noise_floor_factor));
  }
  AddStableCandidates(record, options, order, columns, poles_at, &estimate);

  Refiner refiner(record, options, hankel.channel_noise_std());
  const std::function<void(Estimate*)> refine = [&refiner](Estimate* e) { refiner(e); };
  refine(&estimate);
  SelectSignificant(record, options, &estimate, refine);
  if (options.drop_insignificant && options.hankel.extra_orders > 0) {
    AddModesFromHigherOrders(record, options, order, columns, poles_at, refine, &estimate);
  }
  if (options.drop_insignificant) {
    AddModesFromSingleChannels(record, options, columns, max_order, hankel.channel_noise_std(),
                               refine, &estimate);
    SplitCloseModes(record, options, refine, refiner.weights(), &estimate);
  }
  if (estimate.termination == "failure") {
    throw NumericalError("Ceres",
                         "the refinement of the poles failed: " + estimate.termination_message);
  }
  if (estimate.termination == "no_convergence") {
    estimate.warnings.push_back(fmt::format(
        "the refinement stopped at the iteration limit ({}); the last iterate is reported",
        options.refinement.max_iterations));
  }
  estimate.weights = refiner.weights();
  return estimate;
}

// The Hankel matrix needs 8 columns (4 poles plus room for the noise floor) and as many rows.
int MinimumSamples(const IdentificationOptions& /*options*/, int /*channels*/) { return 24; }

std::string Requirement(const IdentificationOptions& /*options*/, int /*channels*/) {
  return "the Hankel matrix";
}

}  // namespace

MethodDefinition HankelNlsMethod() {
  return {"hankel-nls", &MinimumSamples, &Requirement, &EstimateHankelNls};
}

}  // namespace mbid::identification
