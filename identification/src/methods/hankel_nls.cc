// hankel-nls, the default method: block-Hankel SVD (matrix pencil) initialization with the order
// from the noise floor and stability across orders, then a Ceres refinement of all poles and
// amplitudes.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <numeric>
#include <optional>
#include <string>

#include "estimate.h"
#include "internal.h"
#include "mbid/common/error.h"
#include "mbid/identification/hankel_svd.h"
#include "mbid/identification/modal_fit.h"
#include "mbid/identification/refinement.h"
#include "mbid/identification/significance.h"
#include "methods/method.h"
#include "mode_selection.h"
#include "reliability.h"
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

// A trial estimate that starts from `estimate`'s poles and keeps its warnings and orders.
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
                    Estimate* estimate,
                    const std::function<bool(const Estimate&)>& accept = nullptr) {
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
      AnalyseResidualWindows(values, values - estimate->fit.reconstruction.topRows(values.rows()),
                             options.significance_false_alarm)
          .channel_ratio;
  int added = 0;
  for (Eigen::Index c = 0; c < values.cols(); ++c) {
    const Eigen::VectorXd& residual = estimate->fit.residual_variance;
    if (c >= residual.size() || c >= noise_std.size()) break;
    const double rms = std::sqrt(values.col(c).squaredNorm() / static_cast<double>(values.rows()));
    if (!(std::sqrt(residual(c)) > 3 * std::max(noise_std(c), 1e-6 * rms)) &&
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

// The score of "mode k hides a second one": two poles lambda +- delta whose shapes differ add,
// beside the one mode's term, the Taylor terms t e^(lambda t) and t^2 e^(lambda t) with their
// own amplitude per channel, which one shared pole cannot absorb. A mode whose frequency or
// decay drifts with amplitude (the reference crane's, by 1e-4 at 4 mrad, enough in 1 record of
// 6) adds them too, but in its own shape: coefficients delta_1 (C + i S)_c, delta_2 (C + i S)_c
// over the channels c. The score is the terms' least-squares reduction of the residual, over
// each channel's residual variance, less that of the drift in the mode's shape: chi-square with
// 4 (channels - 1) degrees of freedom when the one mode is all there is. One channel cannot
// tell a pair from a drift: no score (0).
double CloseModeScore(const AnalysisRecord& record, const Estimate& estimate,
                      const Eigen::HouseholderQR<Eigen::MatrixXd>& model_qr,
                      const Eigen::MatrixXd& residual, const Eigen::VectorXd& variance, size_t k) {
  if (residual.cols() < 2) return 0;
  const Eigen::Index samples = residual.rows();
  Eigen::MatrixXd terms(samples, 4);
  ForEachModeSample(estimate.lambda[k], record.decimated_interval_s, 0, static_cast<int>(samples),
                    [&](int j, std::complex<double> z) {
                      const double t = static_cast<double>(j) / static_cast<double>(samples);
                      terms.row(j) << t * z.real(), -t * z.imag(), t * t * z.real(),
                          -t * t * z.imag();
                    });
  // Only the terms' part outside the modes' basis reduces the residual (orthogonal to it).
  const Eigen::Index p = model_qr.matrixQR().cols();
  const Eigen::MatrixXd rotated = model_qr.householderQ().transpose() * terms;
  const Eigen::Matrix4d outside =
      rotated.bottomRows(samples - p).transpose() * rotated.bottomRows(samples - p);
  const Eigen::MatrixXd projections = terms.transpose() * residual;
  const Eigen::Matrix4d inverse = outside.completeOrthogonalDecomposition().pseudoInverse();
  // Per channel the terms' coefficients beta_c, and the drift's fit beta_c = A_c delta
  // (delta_1, delta_2 complex; A_c multiplies by the mode's C + i S in channel c).
  double score = 0;
  Eigen::Matrix4d normal = Eigen::Matrix4d::Zero();
  Eigen::Vector4d right = Eigen::Vector4d::Zero();
  for (Eigen::Index c = 0; c < residual.cols(); ++c) {
    score += projections.col(c).dot(inverse * projections.col(c)) / variance(c);
    const double cosine = estimate.fit.coefficients(2 * static_cast<Eigen::Index>(k), c);
    const double sine = estimate.fit.coefficients(2 * static_cast<Eigen::Index>(k) + 1, c);
    Eigen::Matrix4d shape = Eigen::Matrix4d::Zero();
    shape.block<2, 2>(0, 0) << cosine, -sine, sine, cosine;
    shape.block<2, 2>(2, 2) = shape.block<2, 2>(0, 0);
    normal += shape.transpose() * outside * shape / variance(c);
    right += shape.transpose() * outside * (inverse * projections.col(c)) / variance(c);
  }
  return score - right.dot(normal.completeOrthogonalDecomposition().pseudoInverse() * right);
}

// Two modes closer than their bandwidths (a platform's boom modes 7.8 and 8.5 Hz at 11 and 15 %
// damping) can pass the signal order as one, refined to a frequency between them with a small
// standard deviation and a residual at the noise level. Where a mode's CloseModeScore is
// significant (significance_false_alarm per mode), it is split into lambda +- i delta, delta
// half its decay rate (at least 1 % of its frequency), and the refit is kept when it has more
// significant modes, two of them inside the bandwidth of the one (1.5 decay rates from its
// pole): a refit that moves a pole far off has found something else (a heavily damped pole
// fitting coloured noise of the decimation filter on a 500 Hz crane record), not a pair. Both
// must be determined by the record (reliability.h's IsDetermined); where they are not, the one
// mode stands, and the result is unreliable: the record holds two modes (or one whose shape
// changes with amplitude) it cannot separate, and the one mode is neither.
void SplitCloseModes(const AnalysisRecord& record, const IdentificationOptions& options,
                     const std::function<void(Estimate*)>& refine, const Eigen::VectorXd& weights,
                     Estimate* estimate) {
  const Eigen::MatrixXd& values = record.decimated;
  const Eigen::Index samples = values.rows();
  if (values.cols() < 2) return;  // no score (CloseModeScore)
  const double threshold = CalcChiSquareThreshold(2 * static_cast<int>(values.cols()) - 2,
                                                  options.significance_false_alarm);
  // The modes' basis, its QR and the residual: once, and again after a kept split.
  std::optional<Eigen::HouseholderQR<Eigen::MatrixXd>> model_qr;
  Eigen::MatrixXd residual;
  Eigen::VectorXd variance;
  const auto score_of = [&](size_t k) {
    if (!model_qr) {
      Eigen::MatrixXd basis;
      FillDampedSinusoidBasis(estimate->lambda, record.decimated_interval_s,
                              options.offset == OffsetRemoval::kFit, static_cast<int>(samples),
                              &basis);
      if (basis.cols() + 4 >= samples) return 0.0;
      model_qr.emplace(basis);
      residual = values - estimate->fit.reconstruction.topRows(samples);
      // A noiseless record's round-off is no second mode: the level at least 1e-6 of the RMS,
      // as AssessReliability's.
      variance = estimate->fit.residual_variance;
      for (Eigen::Index c = 0; c < variance.size(); ++c) {
        variance(c) = std::max(variance(c), 1e-12 * values.col(c).squaredNorm() / samples);
      }
    }
    return CloseModeScore(record, *estimate, *model_qr, residual, variance, k);
  };
  int added = 0;
  std::vector<std::pair<std::complex<double>, std::string>> unsplit;  // pole, undetermined
  const size_t modes = estimate->lambda.size();
  for (size_t k = 0; k < modes && k < estimate->lambda.size(); ++k) {
    if (score_of(k) <= threshold) continue;
    Estimate trial = TrialFrom(*estimate);
    const std::complex<double> lambda = estimate->lambda[k];
    // The half-power half bandwidth, rad/s: the decay rate, at least 1 % of the frequency.
    const double half_width = std::max(-lambda.real(), 0.01 * lambda.imag());
    const std::complex<double> delta(0, 0.5 * half_width);
    trial.lambda[k] = lambda + delta;
    trial.lambda.push_back(lambda - delta);
    const double radius = 1.5 * half_width;
    std::string undetermined;  // the pair the record cannot place, when that refused the split
    Poles others = estimate->lambda;
    others.erase(others.begin() + static_cast<std::ptrdiff_t>(k));
    const auto is_pair = [&](const Estimate& split) {
      // The split's own two poles: what is left when each other mode has taken its nearest (a
      // heavily damped mode's bandwidth may hold neighbours).
      std::vector<size_t> pair(split.lambda.size());
      std::iota(pair.begin(), pair.end(), 0);
      for (std::complex<double> other : others) {
        if (pair.empty()) break;
        pair.erase(std::min_element(pair.begin(), pair.end(), [&](size_t a, size_t b) {
          return std::abs(split.lambda[a] - other) < std::abs(split.lambda[b] - other);
        }));
      }
      if (pair.size() != 2 || std::abs(split.lambda[pair[0]] - lambda) > radius ||
          std::abs(split.lambda[pair[1]] - lambda) > radius) {
        return false;
      }
      // The split's own amplitudes: `refine` leaves the fit to the significance test.
      const bool with_offset = options.offset == OffsetRemoval::kFit;
      const ModalModel model{
          split.lambda,
          FitAmplitudes(values, record.decimated_interval_s, split.lambda, with_offset)
              .coefficients,
          with_offset};
      const std::vector<Eigen::Matrix2d> covariance =
          CalcPoleCovariance(values, record.decimated_interval_s, weights, model);
      std::vector<std::string> poles;
      bool determined = true;
      for (size_t m : pair) {
        const double hz = split.lambda[m].imag() / (2 * M_PI);
        const double std_hz = std::sqrt(covariance[m](1, 1)) / (2 * M_PI);
        const double std_decay = std::sqrt(covariance[m](0, 0));
        determined &= IsDetermined(hz, std_hz, -split.lambda[m].real(), std_decay);
        poles.push_back(fmt::format("{:.4g} +- {:.2g} Hz, decay {:.3g} +- {:.2g} 1/s", hz, std_hz,
                                    -split.lambda[m].real(), std_decay));
      }
      undetermined = determined ? "" : fmt::format("{}", fmt::join(poles, " and "));
      return determined;
    };
    const int split = KeepIfMoreModes(record, options, refine, std::move(trial), estimate, is_pair);
    if (split > 0) model_qr.reset();
    added += split;
    if (split == 0) unsplit.emplace_back(lambda, undetermined);
  }
  NoteAddedModes(added, "found by splitting modes whose residual holds a second, close one",
                 estimate);
  // A mode left unsplit is judged on the final estimate: a later split may have taken from its
  // residual what a neighbouring pair left there. A second pole the record cannot place makes
  // the result unreliable; without one it is a warning: a weakly nonlinear mode's shape changes
  // with amplitude too (the reference crane's heavily damped modes in 2 % of them, 17 records
  // in 200), and so does a pair's that the split cannot find.
  for (const auto& [lambda, undetermined] : unsplit) {
    const Poles& poles = estimate->lambda;
    const size_t k =
        static_cast<size_t>(std::min_element(poles.begin(), poles.end(),
                                             [&](std::complex<double> a, std::complex<double> b) {
                                               return std::abs(a - lambda) < std::abs(b - lambda);
                                             }) -
                            poles.begin());
    const double score = score_of(k);
    if (score <= threshold) continue;
    const std::string what = fmt::format(
        "the mode at {:.4g} Hz leaves a residual of a shape of its own that one mode does not "
        "explain (close-mode score {:.3g}, threshold {:.3g})",
        poles[k].imag() / (2 * M_PI), score, threshold);
    if (undetermined.empty()) {
      estimate->warnings.push_back(
          what +
          ": two modes closer than its bandwidth, or one whose shape changes with "
          "amplitude; no two significant modes inside its bandwidth fit it better");
    } else {
      estimate->doubts.push_back(what +
                                 ", and the record does not determine the two modes it "
                                 "splits into (" +
                                 undetermined +
                                 "): two modes (or one whose shape changes with amplitude) the "
                                 "record cannot separate");
    }
  }
}

// HankelOptions::extra_orders: restarts from every pole at the orders above the signal order;
// a start that ends with more significant modes replaces the estimate.
void AddModesFromHigherOrders(const AnalysisRecord& record, const IdentificationOptions& options,
                              int order, int columns, PolesByOrder& poles_at,
                              const std::function<void(Estimate*)>& refine, Estimate* estimate) {
  int added = 0;
  const int highest = std::min(order + 2 * options.hankel.extra_orders, columns - 2);
  for (int higher = order + 2; higher <= highest; higher += 2) {
    Estimate trial;
    trial.warnings = estimate->warnings;
    trial.doubts = estimate->doubts;
    trial.model_order = estimate->model_order;
    trial.effective_rank = estimate->effective_rank;
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
