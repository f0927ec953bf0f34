#include "coloured_noise.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "out_of_band.h"

namespace mbid::identification {
namespace {

// Bins of the near band at least: the mean of n bins of a mirrored spectrum (one degree of
// freedom each) scatters by sqrt(2 / n), 0.18 at 64.
constexpr Eigen::Index kNearBins = 64;

// Half-power bandwidth (Hz), at least the record's resolution.
double Bandwidth(const IdentifiedMode& mode, double duration_s) {
  return std::max(std::abs(mode.decay_rate_per_s) / M_PI, 1 / duration_s);
}

}  // namespace

std::vector<double> CalcLocalNoiseRatio(const Eigen::MatrixXd& residual, double sample_interval_s,
                                        const Eigen::VectorXd& residual_variance,
                                        const std::vector<IdentifiedMode>& modes) {
  std::vector<double> local(modes.size(), 1.0);
  const Eigen::Index samples = residual.rows();
  if (samples < 4 * kNearBins || modes.empty()) return local;
  Eigen::VectorXd frequency_hz;
  const Eigen::MatrixXd power = MirroredPower(residual, sample_interval_s, &frequency_hz);
  const Eigen::Index bins = power.rows();
  const double duration_s = static_cast<double>(samples) * sample_interval_s;
  // Each channel's mean over the band, without the constant bin.
  const Eigen::RowVectorXd mean = power.bottomRows(bins - 1).colwise().mean();
  // Bins within 2 bandwidths of any mode (the mode's own included): its fit's notch, or
  // another mode's residual, not the noise's level.
  std::vector<bool> at_a_mode(static_cast<size_t>(bins), false);
  for (const IdentifiedMode& mode : modes) {
    const double width = Bandwidth(mode, duration_s);
    for (Eigen::Index b = 0; b < bins; ++b) {
      if (std::abs(frequency_hz(b) - mode.frequency_hz) < 2 * width) {
        at_a_mode[static_cast<size_t>(b)] = true;
      }
    }
  }
  for (size_t k = 0; k < modes.size(); ++k) {
    const IdentifiedMode& mode = modes[k];
    const double width = Bandwidth(mode, duration_s);
    std::vector<Eigen::Index> near;
    for (double outer = 8 * width; near.size() < static_cast<size_t>(kNearBins); outer *= 1.5) {
      near.clear();
      for (Eigen::Index b = 1; b < bins; ++b) {
        if (!at_a_mode[static_cast<size_t>(b)] &&
            std::abs(frequency_hz(b) - mode.frequency_hz) <= outer) {
          near.push_back(b);
        }
      }
      if (outer > frequency_hz(bins - 1)) break;  // the whole band
    }
    if (near.size() < static_cast<size_t>(kNearBins)) continue;
    const double margin = 1 + 3 * std::sqrt(2.0 / static_cast<double>(near.size()));
    double weights = 0, weighted = 0;
    for (Eigen::Index c = 0; c < residual.cols(); ++c) {
      double level = 0;
      for (Eigen::Index b : near) level += power(b, c);
      level /= static_cast<double>(near.size());
      // The level where it stands above the mean by more than three of its scatter, whole: a
      // margin taken off it too let a mode of AR(1) noise (coefficient 0.5, 2.4 Hz of 50) stand
      // out. The fit's notch thins the noise within a few tenths of a hertz of a mode (by 25 %
      // in white noise), so the level is a low estimate there: the margin keeps white noise at 1.
      const double factor = mean(c) > 0 && level > margin * mean(c) ? level / mean(c) : 1.0;
      const double amplitude = c < mode.amplitude.size() ? mode.amplitude(c) : 0;
      const double weight =
          residual_variance(c) > 0 ? amplitude * amplitude / residual_variance(c) : 0;
      weights += weight;
      weighted += weight / factor;
    }
    if (weighted > 0) local[k] = weights / weighted;
  }
  return local;
}

}  // namespace mbid::identification
