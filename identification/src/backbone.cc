#include "mbid/identification/backbone.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "mbid/identification/hilbert_backbone.h"
#include "mbid/identification/modal_fit.h"
#include "mbid/identification/refinement.h"

namespace mbid::identification {

Backbone CalcBackbone(const Eigen::MatrixXd& mode_alone, double sample_interval_s,
                      double start_time_s, std::complex<double> lambda,
                      const Eigen::VectorXd& channel_weights, const RefinementOptions& options) {
  Backbone backbone;
  const double tau = sample_interval_s;
  const int samples = static_cast<int>(mode_alone.rows());
  const double period_s = 2 * M_PI / lambda.imag();
  const int window = std::max(32, static_cast<int>(std::lround(8 * period_s / tau)));
  if (window > samples) return backbone;
  // The channel where the mode is largest carries its amplitude.
  Eigen::Index reference = 0;
  mode_alone.colwise().squaredNorm().maxCoeff(&reference);
  std::complex<double> start = lambda;
  std::vector<double> residual_stds;  // of the windows, in the reference channel: the noise
  for (int first = 0; first + window <= samples; first += window / 2) {
    const Eigen::MatrixXd part = mode_alone.middleRows(first, window);
    ModalModel initial;
    initial.lambda = {start};
    initial.with_offset = false;
    initial.coefficients = FitAmplitudes(part, tau, initial.lambda, false).coefficients;
    const RefinementSummary summary =
        RefineModalModel(part, tau, channel_weights, initial, options);
    if (summary.termination == "failure" || summary.model.lambda.size() != 1) continue;
    const std::complex<double> pole = summary.model.lambda.front();
    if (!(pole.imag() > 0)) continue;
    const auto covariance = CalcPoleCovariance(part, tau, channel_weights, summary.model);
    if (covariance.size() != 1) continue;
    const double frequency_hz = pole.imag() / (2 * M_PI);
    const double std_frequency_hz = std::sqrt(covariance[0](1, 1)) / (2 * M_PI);
    if (!(std_frequency_hz < 0.05 * frequency_hz)) continue;  // the mode has sunk into noise
    const double centre = 0.5 * (window - 1) * tau;
    const Eigen::Vector2d cs = summary.model.coefficients.block(0, reference, 2, 1);
    const double decay = -pole.real();
    // Where the mode's amplitude falls below twice the noise (the window's residual), a window
    // fits the noise, whose chance frequencies would read as a drift: the backbone ends there.
    const double amplitude = cs.norm() * std::exp(-decay * centre);
    const double residual_std = std::sqrt(
        FitAmplitudes(part, tau, summary.model.lambda, false).residual_variance(reference));
    if (!(amplitude > 2 * residual_std)) break;
    residual_stds.push_back(residual_std);
    // d zeta / d decay = 1 / |lambda| (omega fixed) up to the small omega term; the decay's std
    // dominates the damping ratio's.
    backbone.time_s.push_back(start_time_s + first * tau + centre);
    backbone.amplitude.push_back(amplitude);
    backbone.frequency_hz.push_back(frequency_hz);
    backbone.damping_ratio.push_back(decay / std::abs(pole));
    backbone.std_frequency_hz.push_back(std_frequency_hz);
    backbone.std_damping_ratio.push_back(std::sqrt(covariance[0](0, 0)) / std::abs(pole));
    start = pole;  // the next window continues from here: the drift is slow
  }
  const size_t n = backbone.frequency_hz.size();
  if (n >= 3) {
    double weight_sum = 0, mean = 0;
    for (size_t i = 0; i < n; ++i) {
      const double w = 1 / std::pow(backbone.std_frequency_hz[i], 2);
      weight_sum += w;
      mean += w * backbone.frequency_hz[i];
    }
    mean /= weight_sum;
    double chi_square = 0;
    for (size_t i = 0; i < n; ++i) {
      chi_square += std::pow((backbone.frequency_hz[i] - mean) / backbone.std_frequency_hz[i], 2);
    }
    // Half-overlapping windows share noise, so the statistic runs high even for a linear mode:
    // 4 per degree of freedom leaves that margin.
    backbone.spread_chi_square_per_dof = chi_square / static_cast<double>(n - 1);
    backbone.amplitude_dependent = backbone.spread_chi_square_per_dof > 4;
  }
  // The noise of the reference channel: the median of the windows' residuals.
  double noise_std = 0;
  if (!residual_stds.empty()) {
    std::nth_element(residual_stds.begin(),
                     residual_stds.begin() + static_cast<long>(residual_stds.size() / 2),
                     residual_stds.end());
    noise_std = residual_stds[residual_stds.size() / 2];
  }
  BackboneCurve hilbert = CalcHilbertBackbone(mode_alone.col(reference), tau, start_time_s,
                                              lambda.imag() / (2 * M_PI), noise_std);
  if (!hilbert.frequency_hz.empty()) backbone.hilbert = std::move(hilbert);
  return backbone;
}

std::string DescribeDrift(const BackboneCurve& backbone) {
  if (backbone.frequency_hz.empty()) return "no windows";
  const auto [low, high] =
      std::minmax_element(backbone.frequency_hz.begin(), backbone.frequency_hz.end());
  // Four digits hide a drift of a few parts in 1e4 that the windows' spread still shows.
  int digits = 4;
  while (digits < 9 &&
         fmt::format("{:.{}g}", *low, digits) == fmt::format("{:.{}g}", *high, digits)) {
    ++digits;
  }
  return fmt::format("{:.{}g} to {:.{}g} Hz, {:.2g} %", *low, digits, *high, digits,
                     100 * (*high - *low) / *high);
}

}  // namespace mbid::identification
