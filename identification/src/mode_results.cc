#include "mode_results.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "internal.h"
#include "mbid/identification/backbone.h"
#include "mbid/identification/modal_fit.h"
#include "mbid/identification/prony_svd.h"
#include "mbid/identification/refinement.h"

namespace mbid::identification {
namespace {

// The decimated record with every mode outside `members` (and the offset) taken away.
Eigen::MatrixXd KeepModes(const AnalysisRecord& record, const Estimate& estimate,
                          const std::vector<size_t>& members) {
  std::vector<std::complex<double>> poles;
  Eigen::MatrixXd coefficients(2 * static_cast<Eigen::Index>(members.size()),
                               record.decimated.cols());
  for (size_t m = 0; m < members.size(); ++m) {
    poles.push_back(estimate.lambda[members[m]]);
    coefficients.middleRows(2 * static_cast<Eigen::Index>(m), 2) =
        estimate.fit.coefficients.middleRows(2 * static_cast<Eigen::Index>(members[m]), 2);
  }
  return record.decimated - estimate.fit.reconstruction +
         CalcDampedSinusoidBasis(poles, record.decimated_interval_s,
                                 static_cast<int>(record.decimated.rows()), false) *
             coefficients;
}

// A mode drifting with amplitude, split into two poles, has one shape: their modal assurance
// criterion (ShapeCorrelation, channels weighed by their noise) is near 1; for two modes of
// their own shapes, in other channels or out of phase, it is near 0.
constexpr double kSameShape = 0.8;

// Poles within 3 % of each other are, in a free decay, one mode whose frequency drifts with
// amplitude far more often than two modes the record resolves. Each such cluster is measured in
// sliding windows (backbone.h) with the other modes subtracted; when the windows confirm a drift,
// the cluster is reported as its largest member with the backbone attached. With
// `backbone: always` every other mode gets its backbone too; with `never` nothing is measured or
// merged. `result->modes` and `shapes` are in `estimate.lambda`'s order.
void MergeDriftingModes(const AnalysisRecord& record, const Estimate& estimate,
                        const IdentificationOptions& options, ModalResult* result,
                        std::vector<Eigen::VectorXcd>* shapes) {
  if (options.backbone == BackboneMode::kNever) return;
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
      const std::vector<size_t> close(order.begin() + static_cast<long>(i),
                                      order.begin() + static_cast<long>(j));
      size_t dominant = close.front();
      for (size_t k : close) {
        if (result->modes[k].amplitude.sum() > result->modes[dominant].amplitude.sum()) {
          dominant = k;
        }
      }
      // One mode drifting with amplitude keeps its shape; two modes of other shapes are two
      // modes however close (a mast's two bending directions 2.6 % apart, each in a channel of
      // its own, were merged and one dropped with all of its channel's signal).
      std::vector<size_t> cluster;
      for (size_t k : close) {
        if (k == dominant ||
            ShapeCorrelation((*shapes)[k], (*shapes)[dominant], estimate.noise_std) >= kSameShape) {
          cluster.push_back(k);
        }
      }
      if (cluster.size() < 2) {
        i = j;
        continue;
      }
      // The record with every mode outside the cluster (and the offset) taken away.
      const Eigen::MatrixXd alone = KeepModes(record, estimate, cluster);
      Backbone backbone =
          CalcBackbone(alone, record.decimated_interval_s, record.decimated_start_time_s,
                       estimate.lambda[dominant], estimate.weights, options.refinement);
      // One mode's free decay never grows: windows whose amplitude rises again by more than
      // 5 % are two modes beating (2.00 and 2.04 Hz of like shapes read as one mode drifting
      // from 1.905 to 2.019 Hz), which stay two, doubted as too close to separate.
      bool rises = false;
      for (size_t w = 1; w < backbone.amplitude.size(); ++w) {
        rises = rises || backbone.amplitude[w] > 1.05 * backbone.amplitude[w - 1];
      }
      if (backbone.amplitude_dependent && !rises) {
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
  if (options.backbone == BackboneMode::kAlways) {
    // Every other mode's backbone, measured alone (the rest of the record subtracted).
    for (size_t k = 0; k < n; ++k) {
      if (drop[k] || result->modes[k].backbone) continue;
      result->modes[k].backbone = CalcBackbone(
          KeepModes(record, estimate, {k}), record.decimated_interval_s,
          record.decimated_start_time_s, estimate.lambda[k], estimate.weights, options.refinement);
    }
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

// Amplitudes, phases, reconstruction and correlation on the full-rate record; the fit the modes'
// amplitudes come from.
AmplitudeFit FitFullRate(const AnalysisRecord& record, const IdentificationOptions& options,
                         const Estimate& estimate, ModalResult* result) {
  const bool with_offset = options.offset == OffsetRemoval::kFit;
  const AmplitudeFit fit =
      record.decimation == 1
          ? estimate.fit
          : FitAmplitudes(record.centered, record.sample_interval_s, estimate.lambda, with_offset);
  result->reconstruction = fit.reconstruction.rowwise() + record.mean.transpose();
  // K in the analysed band: the filtered record the poles came from against the fit on it.
  result->correlation = CalcCorrelation(record.decimated, estimate.fit.reconstruction);
  result->noise_std = fit.residual_variance.cwiseSqrt();
  result->offset = record.mean;
  if (with_offset) result->offset += fit.coefficients.row(fit.coefficients.rows() - 1).transpose();
  return fit;
}

// The covariance is the Cramer-Rao bound at the poles, which holds for the likelihood's maximum;
// prony-svd's poles come from a linear prediction, which does not reach it (a trial's errors at
// low signal-to-noise: 2.0-2.7 of those standard deviations rms). Each variance gains the
// squared distance of its pole to the maximum (the default method's refinement started there):
// an estimate of what the method adds to the maximum's own error. A warning says by how much.
void WidenByDistanceToTheMaximum(const AnalysisRecord& record, const IdentificationOptions& options,
                                 const Estimate& estimate, const ModalModel& model,
                                 std::vector<Eigen::Matrix2d>* covariance, ModalResult* result) {
  const RefinementSummary maximum = RefineModalModel(record.decimated, record.decimated_interval_s,
                                                     estimate.weights, model, options.refinement);
  if (maximum.termination == "failure" || maximum.model.lambda.size() != model.lambda.size()) {
    return;
  }
  std::vector<std::string> widened;
  for (size_t k = 0; k < model.lambda.size(); ++k) {
    const std::complex<double> distance = maximum.model.lambda[k] - model.lambda[k];
    Eigen::Matrix2d& c = (*covariance)[k];
    const double before = std::sqrt(c(1, 1));
    c(0, 0) += distance.real() * distance.real();  // decay = -Re lambda
    c(1, 1) += distance.imag() * distance.imag();
    if (std::sqrt(c(1, 1)) > 1.5 * before) {
      widened.push_back(fmt::format("{:.4g} Hz x{:.2g}", model.lambda[k].imag() / (2 * M_PI),
                                    std::sqrt(c(1, 1)) / before));
    }
  }
  if (!widened.empty()) {
    result->warnings.push_back(fmt::format(
        "prony-svd: standard deviations widened by the poles' distance to the likelihood's "
        "maximum, which the method does not reach (frequency's): {}",
        fmt::join(widened, ", ")));
  }
}

// One mode per pole of the estimate, with its standard deviations (Fisher information on the
// decimated record); returns each mode's complex amplitudes per channel.
std::vector<Eigen::VectorXcd> AddModes(const AnalysisRecord& record,
                                       const IdentificationOptions& options,
                                       const Estimate& estimate, const AmplitudeFit& fit,
                                       ModalResult* result) {
  const bool with_offset = options.offset == OffsetRemoval::kFit;
  std::vector<Eigen::Matrix2d> covariance;
  if (options.compute_uncertainty) {
    ModalModel model;
    model.lambda = estimate.lambda;
    model.with_offset = with_offset;
    model.coefficients = estimate.fit.coefficients;
    covariance =
        CalcPoleCovariance(record.decimated, record.decimated_interval_s, estimate.weights, model);
    if (options.method == Method::kPronySvd)
      WidenByDistanceToTheMaximum(record, options, estimate, model, &covariance, result);
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
    mode.significant = mode.significance >= result->significance_threshold;
    result->modes.push_back(mode);
  }
  return shapes;
}

void SortByFrequency(ModalResult* result) {
  std::vector<size_t> order(result->modes.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [result](size_t a, size_t b) {
    return result->modes[a].frequency_hz < result->modes[b].frequency_hz;
  });
  std::vector<IdentifiedMode> sorted;
  for (size_t i : order) sorted.push_back(result->modes[i]);
  result->modes = std::move(sorted);
}

}  // namespace

void AddEstimate(const AnalysisRecord& record, const IdentificationOptions& options,
                 Estimate* estimate, ModalResult* result) {
  result->model_order = estimate->model_order;
  result->effective_rank = estimate->effective_rank;
  result->termination = estimate->termination;
  result->iterations = estimate->iterations;
  result->stabilization = std::move(estimate->stabilization);
  result->warnings.insert(result->warnings.end(), estimate->warnings.begin(),
                          estimate->warnings.end());

  const AmplitudeFit fit = FitFullRate(record, options, *estimate, result);
  std::vector<Eigen::VectorXcd> shapes = AddModes(record, options, *estimate, fit, result);
  MergeDriftingModes(record, *estimate, options, result, &shapes);
  // Eq. 5 with the output vectors w_k = the modes' complex amplitudes per channel.
  std::vector<std::complex<double>> poles;
  for (const IdentifiedMode& mode : result->modes) poles.push_back(mode.lambda);
  result->eq2_coefficients = CalcEq2Coefficients(poles, shapes);
  SortByFrequency(result);
}

}  // namespace mbid::identification
