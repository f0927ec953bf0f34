#include "mbid/identification/identify.h"

#include <fmt/format.h>

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>

#include "internal.h"
#include "mbid/common/error.h"
#include "mbid/identification/backbone.h"
#include "mbid/identification/hankel_svd.h"
#include "mbid/identification/modal_fit.h"
#include "mbid/identification/prony_svd.h"
#include "mbid/identification/refinement.h"
#include "mbid/identification/release.h"
#include "mbid/identification/significance.h"
#include "mbid/identification/spectrum.h"
#include "record.h"

namespace mbid::identification {
namespace {

using Poles = std::vector<std::complex<double>>;

[[noreturn]] void NoModes(const std::string& reason) {
  throw NumericalError("identification", "no modes found: " + reason);
}

// Step 5 of method.md: a continuous pole is a mode if it oscillates inside the band and its
// damping and decay are inside the limits.
bool PassesFilter(std::complex<double> lambda, const IdentificationOptions& options,
                  double max_frequency_hz) {
  if (!std::isfinite(lambda.real()) || !std::isfinite(lambda.imag())) return false;
  const double frequency_hz = lambda.imag() / (2 * M_PI);
  const double decay = -lambda.real();
  const double damping_ratio = decay / std::abs(lambda);
  return frequency_hz > options.min_frequency_hz && frequency_hz <= max_frequency_hz &&
         damping_ratio >= options.min_damping_ratio && damping_ratio <= options.max_damping_ratio &&
         decay <= options.max_decay_rate_per_s;
}

Poles ToContinuous(const Poles& mu, double tau) {
  Poles lambda;
  for (const auto& z : mu) lambda.push_back(std::log(z) / tau);  // eq. 4
  return lambda;
}

bool HasMatch(std::complex<double> lambda, const Poles& others, double tolerance) {
  return std::any_of(others.begin(), others.end(), [&](std::complex<double> other) {
    return std::abs(other - lambda) <= tolerance * std::abs(lambda);
  });
}

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
};

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

double SignificanceThreshold(const AnalysisRecord& record, const IdentificationOptions& options) {
  if (options.min_significance > 0) return options.min_significance;
  return CalcSignificanceThreshold(static_cast<int>(record.decimated.rows()),
                                   static_cast<int>(record.values.cols()),
                                   options.significance_false_alarm);
}

// A noiseless record's residual is round-off, against which any component is "significant":
// poles found to 1e-10 leave components of about that relative size. A mode smaller than
// kRoundOffAmplitude of every channel's RMS carries nothing and gets significance 0.
constexpr double kRoundOffAmplitude = 1e-8;

void ZeroRoundOffModes(const AnalysisRecord& record, const AmplitudeFit& fit,
                       Eigen::VectorXd* significance) {
  const Eigen::VectorXd rms =
      (record.decimated.colwise().squaredNorm().transpose() / record.decimated.rows()).cwiseSqrt();
  for (Eigen::Index k = 0; k < significance->size(); ++k) {
    bool round_off = true;
    for (Eigen::Index c = 0; c < rms.size(); ++c) {
      round_off = round_off && fit.Amplitude(static_cast<int>(k), static_cast<int>(c)) <=
                                   kRoundOffAmplitude * rms(c);
    }
    if (round_off) (*significance)(k) = 0;
  }
}

// Significance on the record the poles come from (the decimated one: the band where the modes
// are, and one fit per dropped mode stays cheap on long records); drops insignificant modes (when
// asked) until every remaining mode is significant. `refit` re-estimates the poles of a reduced
// set.
template <typename Refit>
void SelectSignificant(const AnalysisRecord& record, const IdentificationOptions& options,
                       Estimate* estimate, Refit&& refit) {
  const bool with_offset = options.offset == OffsetRemoval::kFit;
  const double threshold = SignificanceThreshold(record, options);
  int dropped = 0;
  double largest_dropped = 0;
  const auto note_dropped = [&] {
    if (dropped > 0) {
      estimate->warnings.push_back(fmt::format(
          "dropped {} candidate mode(s) below the significance threshold {:.3g} (largest "
          "dropped: {:.3g})",
          dropped, threshold, largest_dropped));
    }
  };
  for (;;) {
    estimate->fit =
        FitAmplitudes(record.decimated, record.decimated_interval_s, estimate->lambda, with_offset);
    Eigen::VectorXd significance = CalcSignificance(estimate->fit);
    ZeroRoundOffModes(record, estimate->fit, &significance);
    estimate->significance.assign(significance.data(), significance.data() + significance.size());
    if (!options.drop_insignificant) {
      const int weak = static_cast<int>((significance.array() < threshold).count());
      if (weak > 0) {
        estimate->warnings.push_back(fmt::format(
            "{} mode(s) below the significance threshold {:.3g} kept and flagged significant = "
            "false",
            weak, threshold));
      }
      return;
    }
    // Drop the weakest insignificant mode only: two close poles that share one real mode are
    // each insignificant while together they are not.
    Eigen::Index weakest = 0;
    const double smallest = significance.minCoeff(&weakest);
    if (smallest >= threshold) {
      note_dropped();
      return;
    }
    if (estimate->lambda.size() == 1) {
      NoModes(fmt::format(
          "no candidate mode is significant (largest significance {:.3g}, threshold {:.3g}, "
          "significance_false_alarm {}): the record looks like noise",
          std::max(smallest, largest_dropped), threshold, options.significance_false_alarm));
    }
    ++dropped;
    largest_dropped = std::max(largest_dropped, smallest);
    DropModes(&estimate->lambda, [&](size_t k) { return static_cast<Eigen::Index>(k) != weakest; });
    refit(estimate);
  }
}

int AutoStabilizationOrder(const IdentificationOptions& options, int effective_rank, int cap) {
  const int wanted = options.stabilization_max_order > 0 ? options.stabilization_max_order
                                                         : std::max(2 * effective_rank + 10, 20);
  return std::min(wanted, cap);
}

// Marks poles of each order that reappear at order + 2 within `tolerance` * |lambda|.
void MarkStable(std::vector<StabilizationOrder>* orders, double tolerance) {
  for (size_t i = 0; i < orders->size(); ++i) {
    StabilizationOrder& entry = (*orders)[i];
    const StabilizationOrder* next = nullptr;
    for (size_t j = i + 1; j < orders->size(); ++j) {
      if ((*orders)[j].order == entry.order + 2) next = &(*orders)[j];
    }
    entry.stable.assign(entry.lambda.size(), false);
    if (next == nullptr) continue;
    for (size_t k = 0; k < entry.lambda.size(); ++k) {
      entry.stable[k] = HasMatch(entry.lambda[k], next->lambda, tolerance);
    }
  }
}

StabilizationOrder UpperHalf(int order, const Poles& lambda) {
  StabilizationOrder entry;
  entry.order = order;
  for (const auto& pole : lambda) {
    if (pole.imag() >= 0 && std::isfinite(pole.real())) entry.lambda.push_back(pole);
  }
  return entry;
}

// ---- hankel-nls ----------------------------------------------------------------------------

Estimate EstimateHankelNls(const AnalysisRecord& record, const IdentificationOptions& options) {
  const Eigen::MatrixXd& values = record.decimated;
  const double tau = record.decimated_interval_s;
  const int samples = static_cast<int>(values.rows());
  const int columns = std::max(8, std::min(samples / 3, options.hankel.max_columns));
  const int max_order = 2 * options.max_modes + 1;  // + 1: a constant or real pole
  const HankelSvd hankel(values, columns, max_order);

  // Continuous poles per order, each computed once (the stabilization data and the stability
  // check ask for the same orders).
  std::map<int, Poles> poles_by_order;
  const auto poles_at = [&](int order) -> const Poles& {
    auto found = poles_by_order.find(order);
    if (found == poles_by_order.end()) {
      found = poles_by_order.emplace(order, ToContinuous(hankel.CalcPoles(order), tau)).first;
    }
    return found->second;
  };

  Estimate estimate;
  estimate.noise_std = hankel.channel_noise_std();
  estimate.model_order = columns - 1;
  const int order = hankel.CountSignal(options.hankel.noise_floor_factor,
                                       options.hankel.min_relative_singular_value, max_order);
  estimate.effective_rank = order;
  if (options.compute_stabilization) {
    const int highest = AutoStabilizationOrder(options, order, columns - 2);
    for (int m = 1; m <= highest; ++m) estimate.stabilization.push_back(UpperHalf(m, poles_at(m)));
    MarkStable(&estimate.stabilization, options.hankel.stability_tolerance);
  }
  if (order == 0) {
    const double s = hankel.singular_values()(0);
    NoModes(fmt::format(
        "no singular value of the Hankel matrix is above the noise (the largest squared one is "
        "{:.3g} times what white noise gives, the threshold hankel.noise_floor_factor is {})",
        s * s / (hankel.noise_floor() * hankel.noise_edge()), options.hankel.noise_floor_factor));
  }

  // Candidates: upper-half poles at the signal order inside the step-5 limits, stable across
  // the next orders.
  const Poles& poles = poles_at(order);
  int unstable = 0;
  for (const auto& lambda : poles) {
    if (lambda.imag() <= 0 || !PassesFilter(lambda, options, record.max_frequency_hz)) continue;
    bool stable = true;
    for (int s = 1; s <= options.hankel.stability_orders; ++s) {
      const int higher = order + 2 * s;
      if (higher >= columns - 1) break;
      stable = stable && HasMatch(lambda, poles_at(higher), options.hankel.stability_tolerance);
    }
    if (stable) {
      estimate.lambda.push_back(lambda);
    } else {
      ++unstable;
    }
  }
  if (unstable > 0) {
    estimate.warnings.push_back(fmt::format(
        "dropped {} pole(s) of order {} that are not stable across orders", unstable, order));
  }
  if (estimate.lambda.empty()) {
    NoModes(
        fmt::format("none of the {} poles at signal order {} is an oscillation inside the band "
                    "({} .. {} Hz), the damping limits ({} .. {}) and stable across orders",
                    poles.size(), order, options.min_frequency_hz, record.max_frequency_hz,
                    options.min_damping_ratio, options.max_damping_ratio));
  }

  const bool with_offset = options.offset == OffsetRemoval::kFit;
  Eigen::VectorXd weights = Eigen::VectorXd::Ones(values.cols());
  if (options.refinement.weight_channels_by_noise) {
    weights = hankel.channel_noise_std().cwiseInverse();
    weights /= weights.maxCoeff();  // only ratios matter; keeps the cost of order one
  }
  // Refines the poles of estimate->lambda; drops those that leave the step-5 limits.
  const auto refine = [&](Estimate* e) {
    for (;;) {
      ModalModel initial;
      initial.lambda = e->lambda;
      initial.with_offset = with_offset;
      initial.coefficients = FitAmplitudes(values, tau, e->lambda, with_offset).coefficients;
      RefinementSummary summary =
          RefineModalModel(values, tau, weights, initial, options.refinement);
      // Maximum likelihood weighs channels by their noise; if the Hankel estimate of the
      // ratios was off by more than 20 %, refine once more with the residuals' levels.
      if (options.refinement.weight_channels_by_noise && values.cols() > 1) {
        const AmplitudeFit fit = FitAmplitudes(values, tau, summary.model.lambda, with_offset);
        const Eigen::VectorXd noise = fit.residual_variance.cwiseSqrt();
        Eigen::VectorXd updated = noise.cwiseMax(1e-300).cwiseInverse();
        updated /= updated.maxCoeff();
        const double change = (updated.array() / weights.array()).maxCoeff() /
                              (updated.array() / weights.array()).minCoeff();
        if (change > 1.2) {
          weights = updated;
          initial.lambda = summary.model.lambda;
          initial.coefficients = summary.model.coefficients;
          const int previous = summary.iterations;
          summary = RefineModalModel(values, tau, weights, initial, options.refinement);
          summary.iterations += previous;
        }
      }
      e->termination = summary.termination;
      e->termination_message = summary.message;
      e->iterations += summary.iterations;
      e->lambda = summary.model.lambda;
      const int left = DropModes(&e->lambda, [&](size_t k) {
        return PassesFilter(e->lambda[k], options, record.max_frequency_hz);
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
  };
  refine(&estimate);
  SelectSignificant(record, options, &estimate, refine);
  if (options.drop_insignificant && options.hankel.extra_orders > 0) {
    int added = 0;
    const int highest = std::min(order + 2 * options.hankel.extra_orders, columns - 2);
    for (int higher = order + 2; higher <= highest; higher += 2) {
      Estimate trial;
      trial.warnings = estimate.warnings;
      trial.model_order = estimate.model_order;
      trial.effective_rank = estimate.effective_rank;
      for (const auto& lambda : poles_at(higher)) {
        if (lambda.imag() > 0 && PassesFilter(lambda, options, record.max_frequency_hz)) {
          trial.lambda.push_back(lambda);
        }
      }
      if (trial.lambda.size() <= estimate.lambda.size()) continue;
      try {
        refine(&trial);
        SelectSignificant(record, options, &trial, refine);
      } catch (const NumericalError&) {
        continue;  // nothing significant from this start: the estimate stands
      }
      if (trial.lambda.size() <= estimate.lambda.size()) continue;
      // On a noiseless record every mode is "significant": a mode must also carry more than
      // round-off of the record's amplitude.
      const double largest = trial.fit.coefficients.cwiseAbs().maxCoeff();
      bool real_modes = true;
      for (size_t k = 0; k < trial.lambda.size(); ++k) {
        const double peak = trial.fit.coefficients.middleRows(2 * static_cast<Eigen::Index>(k), 2)
                                .cwiseAbs()
                                .maxCoeff();
        real_modes = real_modes && peak > 1e-6 * largest;
      }
      if (!real_modes) continue;
      added += static_cast<int>(trial.lambda.size() - estimate.lambda.size());
      trial.iterations += estimate.iterations;
      trial.stabilization = std::move(estimate.stabilization);
      estimate = std::move(trial);
    }
    if (added > 0) {
      estimate.warnings.push_back(fmt::format(
          "{} more significant mode(s) found by restarting from orders above the signal order {}",
          added, order));
    }
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
  estimate.weights = weights;
  return estimate;
}

// ---- prony-svd -----------------------------------------------------------------------------

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

// Where the free decay starts, and the options with the analysis window starting there.
IdentificationOptions ApplyRelease(const Measurement& measurement,
                                   const IdentificationOptions& options, ModalResult* result,
                                   bool* from_rest) {
  *from_rest = false;
  IdentificationOptions applied = options;
  result->release_time_s = measurement.start_time_s;
  switch (options.release) {
    case ReleaseMode::kNone:
      result->release = "none";
      return applied;
    case ReleaseMode::kGiven:
      result->release = "given";
      result->release_time_s = options.release_time_s;
      break;
    case ReleaseMode::kDetect: {
      const ReleaseDetection detection = DetectRelease(measurement);
      result->release = detection.detected ? "detected" : "record start";
      result->release_time_s = detection.release_time_s;
      *from_rest = detection.from_rest;
      if (detection.detected) {
        result->warnings.push_back(fmt::format(
            "{}; the analysis starts there (--release none to analyse the whole record)",
            detection.description));
      }
      break;
    }
  }
  // Samples at or after the release: PrepareRecord keeps t >= window_start_s - tau / 2.
  applied.window_start_s =
      std::max(options.window_start_s,
               result->release_time_s + 0.5 * measurement.sample_interval_s * (1 - 1e-9));
  return applied;
}

// Poles within 3 % of each other are, in a free decay, one mode whose frequency drifts with
// amplitude far more often than two modes the record resolves. Each such cluster is measured in
// sliding windows (backbone.h) with the other modes subtracted; when the windows confirm a drift,
// the cluster is reported as its largest member with the backbone attached. `result->modes` and
// `shapes` are in `estimate.lambda`'s order.
void MergeDriftingModes(const AnalysisRecord& record, const Estimate& estimate,
                        const IdentificationOptions& options, ModalResult* result,
                        std::vector<Eigen::VectorXcd>* shapes) {
  const size_t n = result->modes.size();
  std::vector<size_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return result->modes[a].frequency_hz < result->modes[b].frequency_hz;
  });
  std::vector<bool> drop(n, false);
  for (size_t i = 0; i < n;) {
    size_t j = i + 1;
    while (j < n &&
           result->modes[order[j]].frequency_hz - result->modes[order[j - 1]].frequency_hz <
               0.03 * result->modes[order[j]].frequency_hz) {
      ++j;
    }
    if (j - i >= 2) {
      std::vector<size_t> cluster(order.begin() + static_cast<long>(i),
                                  order.begin() + static_cast<long>(j));
      size_t dominant = cluster.front();
      for (size_t k : cluster) {
        if (result->modes[k].amplitude.sum() > result->modes[dominant].amplitude.sum()) {
          dominant = k;
        }
      }
      // The record with every mode outside the cluster (and the offset) taken away.
      std::vector<std::complex<double>> members;
      Eigen::MatrixXd coefficients(2 * static_cast<Eigen::Index>(cluster.size()),
                                   record.decimated.cols());
      for (size_t m = 0; m < cluster.size(); ++m) {
        members.push_back(estimate.lambda[cluster[m]]);
        coefficients.middleRows(2 * static_cast<Eigen::Index>(m), 2) =
            estimate.fit.coefficients.middleRows(2 * static_cast<Eigen::Index>(cluster[m]), 2);
      }
      const Eigen::MatrixXd alone =
          record.decimated - estimate.fit.reconstruction +
          CalcDampedSinusoidBasis(members, record.decimated_interval_s,
                                  static_cast<int>(record.decimated.rows()), false) *
              coefficients;
      Backbone backbone =
          CalcBackbone(alone, record.decimated_interval_s, record.decimated_start_time_s,
                       estimate.lambda[dominant], estimate.weights, options.refinement);
      if (backbone.amplitude_dependent) {
        const auto [low, high] =
            std::minmax_element(backbone.frequency_hz.begin(), backbone.frequency_hz.end());
        std::string merged;
        for (size_t k : cluster) {
          merged +=
              fmt::format("{}{:.4g}", merged.empty() ? "" : ", ", result->modes[k].frequency_hz);
          if (k != dominant) drop[k] = true;
        }
        result->warnings.push_back(fmt::format(
            "modes at {} Hz are one mode drifting with amplitude: reported as the mode at "
            "{:.4g} Hz with its backbone (frequency {:.4g} to {:.4g} Hz over {} windows)",
            merged, result->modes[dominant].frequency_hz, *low, *high,
            backbone.frequency_hz.size()));
        result->modes[dominant].backbone = std::move(backbone);
      }
    }
    i = j;
  }
  std::vector<IdentifiedMode> kept;
  std::vector<Eigen::VectorXcd> kept_shapes;
  for (size_t k = 0; k < n; ++k) {
    if (drop[k]) continue;
    kept.push_back(result->modes[k]);
    kept_shapes.push_back((*shapes)[k]);
  }
  result->modes = std::move(kept);
  *shapes = std::move(kept_shapes);
}

// Reasons the data do not support the result (ModalResult::reliable).
void AssessReliability(const AnalysisRecord& record, const IdentificationOptions& options,
                       const Estimate& estimate, ModalResult* result) {
  std::vector<std::string>& reasons = result->reasons;
  // The fit's residual against the record's own noise level: a record the modes explain leaves
  // noise (ratio about 1; coloured noise a little more). 3 x the noise, or a residual above a
  // millionth of the signal when the record is noiseless, means something in the record is not
  // in the modes (a start before the free decay, a nonlinearity, a missed mode).
  const Eigen::VectorXd& residual = estimate.fit.residual_variance;
  for (Eigen::Index c = 0; c < residual.size() && c < estimate.noise_std.size(); ++c) {
    const double rms = std::sqrt(record.decimated.col(c).squaredNorm() / record.decimated.rows());
    const double level = std::max(estimate.noise_std(c), 1e-6 * rms);
    const double ratio = std::sqrt(residual(c)) / level;
    if (ratio > 3) {
      reasons.push_back(fmt::format(
          "the residual in channel {} is {:.3g} times the record's noise level: the modes do not "
          "explain the record",
          result->channels[static_cast<size_t>(c)], ratio));
    }
  }
  for (Eigen::Index c = 0; c < result->correlation.size(); ++c) {
    if (!(result->correlation(c) >= options.min_correlation)) {
      reasons.push_back(fmt::format(
          "K = {:.3f} in channel {} is below min_correlation {}: the modes do not explain the "
          "record in the analysed band",
          result->correlation(c), result->channels[static_cast<size_t>(c)],
          options.min_correlation));
    }
  }
  const double top_hz = std::min(record.max_frequency_hz, record.flat_frequency_hz);
  for (const IdentifiedMode& mode : result->modes) {
    if (mode.frequency_hz > 0.95 * top_hz) {
      reasons.push_back(fmt::format(
          "the mode at {:.4g} Hz is at the top of the analysed band ({:.4g} Hz{}): it may be "
          "cut by the band or the decimation filter",
          mode.frequency_hz, top_hz,
          record.decimation > 1 ? fmt::format(", decimation {}", record.decimation) : ""));
    }
    if (options.min_frequency_hz > 0 && mode.frequency_hz < 1.05 * options.min_frequency_hz) {
      reasons.push_back(fmt::format("the mode at {:.4g} Hz is at the bottom of the band ({} Hz)",
                                    mode.frequency_hz, options.min_frequency_hz));
    }
    if (mode.std_frequency_hz > 0.1 * mode.frequency_hz ||
        (mode.decay_rate_per_s > 0 && mode.std_decay_rate_per_s > mode.decay_rate_per_s)) {
      reasons.push_back(fmt::format(
          "the mode at {:.4g} Hz is undetermined (std of frequency {:.3g} Hz, of decay {:.3g} "
          "1/s)",
          mode.frequency_hz, mode.std_frequency_hz, mode.std_decay_rate_per_s));
    }
  }
  for (const IdentifiedMode& mode : result->modes) {
    if (mode.backbone && mode.backbone->amplitude_dependent) {
      const auto [low, high] = std::minmax_element(mode.backbone->frequency_hz.begin(),
                                                   mode.backbone->frequency_hz.end());
      reasons.push_back(fmt::format(
          "the mode at {:.4g} Hz is amplitude dependent ({:.4g} to {:.4g} Hz): its constant "
          "frequency and damping hold at no amplitude; use its backbone",
          mode.frequency_hz, *low, *high));
    }
  }
  // Modes within 3 % of each other: one mode whose frequency drifts with amplitude, or two the
  // record cannot tell apart; either way not two modes to size dampers on.
  for (size_t k = 1; k < result->modes.size(); ++k) {
    const double low = result->modes[k - 1].frequency_hz;
    const double high = result->modes[k].frequency_hz;
    if (high - low < 0.03 * high) {
      reasons.push_back(fmt::format(
          "modes at {:.4g} and {:.4g} Hz are {:.2g} % apart: one mode drifting with amplitude "
          "or two the record cannot separate",
          low, high, 100 * (high - low) / high));
    }
  }
  if (result->termination != "converged") {
    reasons.push_back("the refinement did not converge (" + result->termination + ")");
  }
  result->reliable = reasons.empty();
}

}  // namespace

ModalResult Identify(const Measurement& measurement, const IdentificationOptions& options,
                     const std::string& origin) {
  ModalResult result;
  if (const auto problem = FindOptionProblem(options)) {
    throw InputError("identification options", problem->field, problem->problem, problem->expected);
  }
  bool from_rest = false;
  const IdentificationOptions applied = ApplyRelease(measurement, options, &result, &from_rest);
  const AnalysisRecord record = PrepareRecord(measurement, applied, origin);
  result.channels = record.channels;
  result.units = record.units;
  result.sample_interval_s = record.sample_interval_s;
  result.samples = static_cast<int>(record.values.rows());
  result.start_time_s = record.start_time_s;
  result.decimation = record.decimation;
  result.max_frequency_hz = record.max_frequency_hz;
  result.min_correlation = options.min_correlation;
  result.method = MethodName(options.method);
  result.significance_threshold = SignificanceThreshold(record, options);
  if (options.compute_spectrum) {
    result.spectrum = CalcSpectrum(record.centered, record.sample_interval_s, options.spectrum);
    result.has_spectrum = true;
  }

  Estimate estimate = options.method == Method::kPronySvd ? EstimatePronySvd(record, options)
                                                          : EstimateHankelNls(record, options);
  result.model_order = estimate.model_order;
  result.effective_rank = estimate.effective_rank;
  result.termination = estimate.termination;
  result.iterations = estimate.iterations;
  result.stabilization = std::move(estimate.stabilization);
  result.warnings.insert(result.warnings.end(), estimate.warnings.begin(), estimate.warnings.end());

  // Amplitudes, phases, reconstruction and correlation on the full-rate record.
  const bool with_offset = options.offset == OffsetRemoval::kFit;
  const AmplitudeFit fit =
      record.decimation == 1
          ? estimate.fit
          : FitAmplitudes(record.centered, record.sample_interval_s, estimate.lambda, with_offset);
  result.reconstruction = fit.reconstruction.rowwise() + record.mean.transpose();
  // K in the analysed band: the filtered record the poles came from against the fit on it.
  result.correlation = CalcCorrelation(record.decimated, estimate.fit.reconstruction);
  result.noise_std = fit.residual_variance.cwiseSqrt();
  result.offset = record.mean;
  if (with_offset) result.offset += fit.coefficients.row(fit.coefficients.rows() - 1).transpose();

  std::vector<Eigen::Matrix2d> covariance;
  if (options.compute_uncertainty) {
    ModalModel model;
    model.lambda = estimate.lambda;
    model.with_offset = with_offset;
    model.coefficients = estimate.fit.coefficients;
    covariance =
        CalcPoleCovariance(record.decimated, record.decimated_interval_s, estimate.weights, model);
  }
  const int channels = static_cast<int>(record.channels.size());
  std::vector<Eigen::VectorXcd> shapes;
  for (size_t k = 0; k < estimate.lambda.size(); ++k) {
    IdentifiedMode mode;
    mode.SetPole(estimate.lambda[k]);
    mode.amplitude.resize(channels);
    mode.phase_rad.resize(channels);
    Eigen::VectorXcd shape(channels);
    for (int c = 0; c < channels; ++c) {
      mode.amplitude(c) = fit.Amplitude(static_cast<int>(k), c);
      mode.phase_rad(c) = fit.Phase(static_cast<int>(k), c);
      shape(c) = std::polar(mode.amplitude(c), mode.phase_rad(c));
    }
    shapes.push_back(shape);
    const double nan = std::numeric_limits<double>::quiet_NaN();
    mode.std_decay_rate_per_s = covariance.empty() ? nan : std::sqrt(covariance[k](0, 0));
    mode.std_frequency_hz = covariance.empty() ? nan : std::sqrt(covariance[k](1, 1)) / (2 * M_PI);
    mode.significance = estimate.significance.at(k);
    mode.significant = mode.significance >= result.significance_threshold;
    result.modes.push_back(mode);
  }
  MergeDriftingModes(record, estimate, options, &result, &shapes);
  // Eq. 5 with the output vectors w_k = the modes' complex amplitudes per channel.
  std::vector<std::complex<double>> poles;
  for (const IdentifiedMode& mode : result.modes) poles.push_back(mode.lambda);
  result.eq2_coefficients = CalcEq2Coefficients(poles, shapes);

  std::vector<size_t> order(result.modes.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return result.modes[a].frequency_hz < result.modes[b].frequency_hz;
  });
  std::vector<IdentifiedMode> sorted;
  for (size_t i : order) sorted.push_back(result.modes[i]);
  result.modes = std::move(sorted);
  if (from_rest) {
    // The whole decay knows the release better than its first samples (release.h).
    result.release_time_s = RefineReleaseFromModes(result, result.release_time_s);
  }
  AssessReliability(record, options, estimate, &result);
  return result;
}

}  // namespace mbid::identification
