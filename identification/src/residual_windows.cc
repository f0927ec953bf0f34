#include "residual_windows.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "estimate.h"
#include "mbid/identification/significance.h"
#include "out_of_band.h"

namespace mbid::identification {
namespace {

// The shortest start judged on its own: a chi-square of 5 samples per channel at a false alarm of
// 1e-5 needs 5 times the noise's power, which a real excess of a few samples exceeds many times.
constexpr int kShortestStart = 5;

}  // namespace

ResidualWindows AnalyseResidualWindows(const Eigen::MatrixXd& values,
                                       const Eigen::MatrixXd& residual, double false_alarm,
                                       double start_band) {
  const int n = static_cast<int>(residual.rows());
  const Eigen::Index channels = residual.cols();
  ResidualWindows result;
  result.channel_ratio = Eigen::VectorXd::Zero(channels);
  // Windows of 2 % of the record, at least 20 samples: short enough for a mode decaying within
  // a tenth of the record, long enough for a power estimate.
  const int length = std::max(20, n / 50);
  const int windows = n / length;
  if (windows < 8 || channels == 0) return result;
  Eigen::MatrixXd power(windows, channels);
  Eigen::VectorXd levels = Eigen::VectorXd::Zero(channels);
  for (Eigen::Index c = 0; c < channels; ++c) {
    for (int w = 0; w < windows; ++w) {
      power(w, c) = residual.col(c).segment(w * length, length).squaredNorm() / length;
    }
    // The median window's power is the noise's: robust to the few windows that are not noise.
    std::vector<double> sorted(power.col(c).data(), power.col(c).data() + windows);
    std::nth_element(sorted.begin(), sorted.begin() + windows / 2, sorted.end());
    // A noiseless record's round-off is no excess: AssessReliability's floor.
    const double level = std::max(sorted[static_cast<size_t>(windows / 2)],
                                  std::pow(RoundOffNoiseStd(values, c), 2));
    levels(c) = level;
    if (level > 0) {
      power.col(c) /= level;
    } else {
      power.col(c).setZero();  // an exact fit: nothing to judge
    }
    result.channel_ratio(c) = power.col(c).maxCoeff();
  }
  // A full-rate record's start in halves of a window too, down to 5 samples: a mode gone within a
  // few milliseconds (200 Hz at 20 % damping on a 1 kHz record: 2400 noise variances in 3
  // channels) raises a window of 400 samples 3 times, its first 20 samples 40 times. Each length
  // has its own chi-square threshold; the false alarm is shared among all the windows judged. Not
  // a decimated record's: the filter's first outputs misfit by a few times the noise.
  const int shortest = start_band > 0 ? kShortestStart : length;
  int scales = 0;
  for (int shorter = length / 2; shorter >= shortest; shorter /= 2) ++scales;
  const double per_window = false_alarm / (windows + scales);
  // Band-limited noise has `start_band` of its samples' degrees of freedom: a few samples of it
  // wander together (a 100 Hz record limited to 10 Hz: 15 samples hold 3 independent ones).
  const auto threshold = [&](int samples, double band) {
    const int dof =
        std::max(1, static_cast<int>(std::lround(samples * band))) * static_cast<int>(channels);
    return std::max(2.0,
                    CalcChiSquareThreshold((dof + 1) / 2, per_window) / static_cast<double>(dof));
  };
  Eigen::Index worst = 0;
  const double ratio = power.rowwise().mean().maxCoeff(&worst);
  if (ratio > threshold(length, 1)) {
    result.excess = ResidualWindows::Excess{static_cast<int>(worst) * length, length, ratio};
  }
  for (int shorter = length / 2; shorter >= shortest; shorter /= 2) {
    // A band limit by mirroring (BandLimited) sums each early sample's noise with its mirror
    // image: white noise's power there is 1 + sinc(f (2 n + 1)) times its level (f the band's
    // fraction of Nyquist; twice the level at the start of a narrow band).
    double start = 0;
    for (Eigen::Index c = 0; c < channels; ++c) {
      if (levels(c) <= 0) continue;
      double sum = 0;
      for (int j = 0; j < shorter; ++j) {
        const double x = M_PI * start_band * (2 * j + 1);
        const double mirrored = start_band < 1 ? 1 + std::sin(x) / x : 1;
        sum += residual(j, c) * residual(j, c) / mirrored;
      }
      start += sum / (shorter * levels(c));
    }
    start /= static_cast<double>(channels);
    // Said over the longer window's ratio only where it is the plainer excess: its significance
    // over its own threshold is larger.
    const double band = std::min(1.0, start_band);
    if (start > threshold(shorter, band) &&
        (!result.excess || start / threshold(shorter, band) >
                               result.excess->power_ratio / threshold(result.excess->samples, 1))) {
      result.excess = ResidualWindows::Excess{0, shorter, start};
    }
  }
  return result;
}

std::optional<ResidualWindows::Excess> FindExcessAtTheStart(const Eigen::MatrixXd& values,
                                                            const Eigen::MatrixXd& residual,
                                                            double sample_interval_s, double top_hz,
                                                            double false_alarm) {
  const double band = std::min(1.0, 2 * top_hz * sample_interval_s);
  const ResidualWindows windows = AnalyseResidualWindows(
      values, BandLimited(residual, sample_interval_s, top_hz), false_alarm, band);
  if (!windows.excess || windows.excess->first_sample != 0) return std::nullopt;
  return windows.excess;
}

}  // namespace mbid::identification
