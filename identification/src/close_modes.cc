// Two modes closer than their bandwidths, counted as one by the signal order
// (docs/identification.md, "Two modes inside each other's bandwidth").
#include "close_modes.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <numeric>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "internal.h"
#include "mbid/identification/modal_fit.h"
#include "mbid/identification/refinement.h"
#include "mbid/identification/significance.h"
#include "mode_trials.h"
#include "reliability.h"

namespace mbid::identification {
namespace {

// The score of "mode k hides a second one": two poles lambda +- delta whose shapes differ add,
// beside the one mode's term, the Taylor terms t e^(lambda t) and t^2 e^(lambda t) with their
// own amplitude per channel, which one shared pole cannot absorb. A mode whose frequency or
// decay drifts with amplitude (the reference crane's, by 1e-4 at 4 mrad, enough in 1 record of
// 6) adds them too, but in its own shape: coefficients delta_1 (C + i S)_c, delta_2 (C + i S)_c
// over the channels c. The score is the terms' least-squares reduction of the residual, over
// each channel's residual variance, less that of the drift in the mode's shape: chi-square with
// 4 (channels - 1) degrees of freedom when the one mode is all there is. One channel cannot
// tell a pair from a drift: its score is the whole reduction (4 degrees of freedom), and a pair
// it splits into is judged "drifting or two" (AssessReliability's 3 % rule).
double CloseModeScore(const AnalysisRecord& record, const Estimate& estimate,
                      const Eigen::HouseholderQR<Eigen::MatrixXd>& model_qr,
                      const Eigen::MatrixXd& residual, const Eigen::VectorXd& variance, size_t k) {
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
  if (residual.cols() < 2) return score;
  return score - right.dot(normal.completeOrthogonalDecomposition().pseudoInverse() * right);
}

}  // namespace

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
  const double threshold = CalcChiSquareThreshold(
      std::max(2, 2 * static_cast<int>(values.cols()) - 2), options.significance_false_alarm);
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
      residual = DecimatedResidual(record, *estimate);
      // A noiseless record's round-off is no second mode: AssessReliability's floor.
      variance = estimate->fit.residual_variance;
      for (Eigen::Index c = 0; c < variance.size(); ++c) {
        variance(c) = std::max(variance(c), std::pow(RoundOffNoiseStd(values, c), 2));
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

}  // namespace mbid::identification
