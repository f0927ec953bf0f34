#include "mbid/identification/release.h"

#include <fmt/format.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <optional>
#include <vector>

#include "mbid/common/error.h"
#include "mbid/common/outliers.h"
#include "mbid/identification/modal_result.h"
#include "release_internal.h"

namespace mbid::identification {

using internal::BridgeGlitches;
using internal::kQuietSamples;
using internal::Reversals;
using internal::ThirdDifferenceNoise;

namespace {

// A coarse onset is where some channel has moved this fraction of its range from where the
// record begins; the onset model is fitted on the samples before it.
constexpr double kOnsetFraction = 0.25;
// Samples at rest deviate from their constant by less than this fraction of the range.
constexpr double kRestFraction = 0.1;
constexpr int kMinRestSamples = 3;
// A rest segment shorter than this is also held to the record's noise level.
constexpr int kShortRestSamples = 20;

bool IsRate(const std::string& unit) {
  const auto ends = [&unit](const char* suffix) {
    const std::string s(suffix);
    return unit.size() >= s.size() && unit.compare(unit.size() - s.size(), s.size(), s) == 0;
  };
  return ends("/s") || ends("/s^2") || ends("/s2") || ends("s-1") || ends("s-2");
}

// Least-squares cost of the onset model with the release at t0 (in samples from `first`) over
// samples [first, last], channels weighted by their range.
struct OnsetFit {
  const Eigen::MatrixXd* values;
  std::vector<bool> rate;
  Eigen::VectorXd range;
  int first = 0, last = 0;

  bool jump_everywhere = false;  // a jump in every channel, not only in rate channels
  // A slope in every channel (moving off: an impact) or only in rate channels (a release from
  // rest, whose positions start with curvature alone; a slope there fits noise as onset).
  bool slope_everywhere = true;

  double Cost(double t0) const {
    double cost = 0;
    const int n = last - first + 1;
    for (Eigen::Index c = 0; c < values->cols(); ++c) {
      // Unknowns: constant, jump (rate channels), slope, curvature, cubic term; set off from
      // rest, a position has the constant and the curvature alone (a cubic term from an earlier
      // t0 mimics a later quadratic onset: at 1e-4 rad the release came 7 samples early).
      const bool jump = rate[c] || jump_everywhere;
      const bool slope = rate[c] || jump_everywhere || slope_everywhere;
      const int p = 2 + (jump ? 1 : 0) + (slope ? 2 : 0);
      Eigen::MatrixXd basis(n, p);
      for (int i = 0; i < n; ++i) {
        const double s = std::max(0.0, static_cast<double>(first + i) - t0);
        const bool after = static_cast<double>(first + i) >= t0;
        int k = 0;
        basis(i, k++) = 1;
        if (jump) basis(i, k++) = after ? 1.0 : 0.0;
        if (slope) basis(i, k++) = s;
        basis(i, k++) = s * s;
        if (slope) basis(i, k++) = s * s * s;
      }
      const Eigen::VectorXd y = values->col(c).segment(first, n) / range(c);
      const Eigen::MatrixXd normal = basis.transpose() * basis;
      const Eigen::VectorXd rhs = basis.transpose() * y;
      const Eigen::VectorXd x = normal.ldlt().solve(rhs);
      cost += (y - basis * x).squaredNorm();
    }
    return cost;
  }
};

// Least-squares cost of one cubic per channel over samples [0, last], channels weighted by their
// range as in OnsetFit: a record in motion from its first sample.
double SmoothCost(const Eigen::MatrixXd& y, const Eigen::VectorXd& range, int last) {
  const int n = last + 1;
  Eigen::MatrixXd basis(n, 4);
  for (int i = 0; i < n; ++i) {
    const double s = static_cast<double>(i) / n;  // scaled: a well-conditioned normal matrix
    basis.row(i) << 1, s, s * s, s * s * s;
  }
  const Eigen::MatrixXd normal = basis.transpose() * basis;
  const auto solver = normal.ldlt();
  double cost = 0;
  for (Eigen::Index c = 0; c < y.cols(); ++c) {
    const Eigen::VectorXd v = y.col(c).head(n) / range(c);
    const Eigen::VectorXd x = solver.solve(basis.transpose() * v);
    cost += (v - basis * x).squaredNorm();
  }
  return cost;
}

// The release instant (in samples) that minimizes fit.Cost: every sample up to `early`, then a
// golden section between the neighbours of the best.
double FindOnset(const OnsetFit& fit, int early, double noise_variance, double* cost) {
  int best = fit.first;
  double best_cost = std::numeric_limits<double>::infinity();
  for (int j = fit.first; j <= early; ++j) {
    const double c = fit.Cost(j);
    if (c < best_cost) {
      best_cost = c;
      best = j;
    }
  }
  double low = std::max<double>(fit.first, best - 1), high = std::min<double>(early, best + 1);
  const double golden = 0.5 * (std::sqrt(5.0) - 1);
  double a = high - golden * (high - low), b = low + golden * (high - low);
  double fa = fit.Cost(a), fb = fit.Cost(b);
  for (int i = 0; i < 40 && high - low > 1e-4; ++i) {
    if (fa < fb) {
      high = b, b = a, fb = fa;
      a = high - golden * (high - low), fa = fit.Cost(a);
    } else {
      low = a, a = b, fa = fb;
      b = low + golden * (high - low), fb = fit.Cost(b);
    }
  }
  double t0 = fa < fb ? a : b;
  *cost = std::min(fa, fb);
  if (best_cost <= *cost) {
    t0 = best;
    *cost = best_cost;
  }
  // A jump alone places the release only between two samples (a shifted polynomial is still
  // one): the cost is then flat there, and the middle is the honest answer.
  const double inside = fit.Cost(best - 0.5);
  const double tolerance = 1e-9 * std::max(best_cost, 1e-300);
  if (best > fit.first && std::abs(best_cost - inside) <= tolerance &&
      std::abs(fit.Cost(best - 0.999) - best_cost) <= tolerance) {
    t0 = best - 0.5;
  }
  // A jump bounds the release to (best - 1, best]; a noisy position channel beside it pulls the
  // optimum anywhere inside, up to a sample early (an accelerometer with held angles at 1 %
  // noise: one sample early at every rate). Unless the middle fits worse by more than 4 noise
  // variances (2 standard deviations of the instant), the middle is the honest answer too.
  const bool jumps = fit.jump_everywhere ||
                     std::any_of(fit.rate.begin(), fit.rate.end(), [](bool rate) { return rate; });
  if (jumps && best > fit.first && t0 > best - 1 && t0 < best) {
    const double middle = fit.Cost(best - 0.5);
    if (middle - *cost <= 4 * noise_variance) {
      t0 = best - 0.5;
      *cost = middle;
    }
  }
  return t0;
}

// Median |second difference| over samples [begin, end) of `y` (0 when empty).
double MedianBend(const Eigen::Ref<const Eigen::VectorXd>& y, Eigen::Index begin,
                  Eigen::Index end) {
  std::vector<double> bends;
  for (Eigen::Index j = std::max<Eigen::Index>(1, begin); j < std::min(end, y.size() - 1); ++j) {
    bends.push_back(std::abs(y[j + 1] - 2 * y[j] + y[j - 1]));
  }
  if (bends.empty()) return 0;
  std::nth_element(bends.begin(), bends.begin() + bends.size() / 2, bends.end());
  return bends[bends.size() / 2];
}

}  // namespace

namespace internal {

// The record with its glitches bridged (outliers.h): a sample that jumps off a channel's course
// and back (its neighbours agree to a quarter of its jump) while the course goes on alike after
// it (the spread of the 16 samples after within 3 times that of the 16 before) is no release;
// a release's jump to a new level, and an impact that sets the structure ringing, stay.
Eigen::MatrixXd BridgeGlitches(const Eigen::MatrixXd& y) {
  Eigen::MatrixXd bridged = y;
  for (Eigen::Index c = 0; c < y.cols(); ++c) {
    for (const Outlier& outlier : FindOutliers(y.col(c))) {
      const Eigen::Index j = outlier.sample;
      if (j < 1 || j + 1 >= y.rows()) continue;
      const double before = MedianBend(y.col(c), j - 17, j - 1);
      const double after = MedianBend(y.col(c), j + 2, j + 18);
      const double middle = 0.5 * (y(j - 1, c) + y(j + 1, c));
      const bool returns = std::abs(y(j + 1, c) - y(j - 1, c)) <= 0.25 * std::abs(y(j, c) - middle);
      if (returns && after <= 3 * before) bridged(j, c) = middle;
    }
  }
  return bridged;
}

// The noise standard deviation of a channel from its third differences (white noise: variance
// 20 sigma^2), by their median absolute value (robust to the decay's own share where it is
// sampled finely): 0.6745 sigma is the median of |N(0, sigma)|.
double ThirdDifferenceNoise(const Eigen::VectorXd& y) {
  const Eigen::Index n = y.size();
  if (n < 8) return 0;
  std::vector<double> third(static_cast<size_t>(n - 3));
  for (Eigen::Index j = 0; j + 3 < n; ++j) {
    third[static_cast<size_t>(j)] = std::abs(y(j + 3) - 3 * y(j + 2) + 3 * y(j + 1) - y(j));
  }
  std::nth_element(third.begin(), third.begin() + third.size() / 2, third.end());
  return third[third.size() / 2] / 0.6745 / std::sqrt(20.0);
}

}  // namespace internal

namespace {

// Each column's level at rest: the median of its first `rest` samples.
std::vector<double> RestLevels(const Eigen::MatrixXd& y, int rest) {
  std::vector<double> levels;
  for (Eigen::Index c = 0; c < y.cols(); ++c) {
    std::vector<double> before(y.col(c).data(), y.col(c).data() + rest);
    std::nth_element(before.begin(), before.begin() + before.size() / 2, before.end());
    levels.push_back(before[before.size() / 2]);
  }
  return levels;
}

}  // namespace

// DetectRelease in all of `record`'s channels.
ReleaseDetection DetectReleaseInChannels(const Measurement& record) {
  ReleaseDetection detection;
  detection.release_time_s = record.start_time_s;
  detection.description = "the record starts in the free decay (no segment at rest before it)";
  const Eigen::MatrixXd y = BridgeGlitches(record.values);
  const int n = static_cast<int>(y.rows());
  const Eigen::Index m = y.cols();
  if (n < 8 || m == 0) return detection;

  Eigen::VectorXd range = (y.colwise().maxCoeff() - y.colwise().minCoeff()).transpose();
  Eigen::VectorXd reference(m);
  for (Eigen::Index c = 0; c < m; ++c) {
    // The first few samples' median: robust to a noisy first sample.
    std::vector<double> head(y.col(c).data(), y.col(c).data() + std::min(n, 5));
    std::nth_element(head.begin(), head.begin() + head.size() / 2, head.end());
    reference(c) = head[head.size() / 2];
    if (!(range(c) > 0)) range(c) = 1;  // a constant channel says nothing; keep it harmless
  }
  const auto deviation = [&](int j) {
    return ((y.row(j).transpose() - reference).cwiseAbs().array() / range.array()).maxCoeff();
  };
  int onset = 0;
  while (onset < n && deviation(onset) <= kOnsetFraction) ++onset;
  if (onset < kMinRestSamples + 2 || onset >= n) return detection;
  // The noise of the segment before the onset (its first half, safely at rest if anything is):
  // the motion is "clearly there" kEarlySigmas above it, or 2 % of the range.
  const int quiet = std::max(2, onset / 2);
  double early_fraction = 0.02;
  double noise_variance = 0;  // in the units of OnsetFit::Cost
  for (Eigen::Index c = 0; c < m; ++c) {
    const Eigen::VectorXd head = y.col(c).head(quiet);
    const double std_dev = std::sqrt((head.array() - head.mean()).square().sum() / (quiet - 1));
    early_fraction = std::max(early_fraction, 6 * std_dev / range(c));
    noise_variance += std::pow(std_dev / range(c), 2);
  }
  int early = 0;
  while (early < onset && deviation(early) <= early_fraction) ++early;
  // The window reaches back to where the release may be. A motion from rest grows as t^2, so
  // the release lies about (onset - early) / (1 - sqrt(early_fraction / kOnsetFraction)) before
  // the onset; where the noise puts the first clear motion near the onset (early_fraction 24 %
  // of the range) that is 50 times onset - early, and 3 times placed the release 94 ms late.
  const double ratio = std::min(0.95, std::sqrt(early_fraction / kOnsetFraction));
  const int back = static_cast<int>(std::ceil(1.5 * (onset - early) / (1 - ratio)));
  const int first = std::max(0, early - std::max({20, 3 * (onset - early), back}));
  // A few samples past the first clear motion: the polynomial holds a fraction of a period, and
  // a jump (rate channels) needs samples after it to be told from a slope.
  const int last = std::min(n - 1, early + 3);
  OnsetFit fit{&y, {}, range, first, last};
  for (const std::string& unit : record.units) fit.rate.push_back(IsRate(unit));
  fit.rate.resize(static_cast<size_t>(m), false);
  // Set off from rest (positions with curvature alone) unless moving off with a velocity fits
  // better by more than noise: 25 is a change of 5 noise standard deviations.
  fit.slope_everywhere = false;
  double cost = 0;
  double t0 = FindOnset(fit, early, noise_variance, &cost);
  fit.slope_everywhere = true;
  double slope_cost = 0;
  const double slope_t0 = FindOnset(fit, early, noise_variance, &slope_cost);
  bool moving_off = false;
  if (cost - slope_cost > 25 * noise_variance) {
    t0 = slope_t0;
    cost = slope_cost;
    moving_off = true;
  }
  // A position that jumps (an impact, a record that starts abruptly after zeros) fits the
  // jump model better by far more than noise: 25 is a change of 5 noise standard deviations.
  fit.jump_everywhere = true;
  double jump_cost = 0;
  const double jump_t0 = FindOnset(fit, early, noise_variance, &jump_cost);
  bool jumps = std::any_of(fit.rate.begin(), fit.rate.end(), [](bool rate) { return rate; });
  if (cost - jump_cost > 25 * noise_variance) {
    t0 = jump_t0;
    jumps = true;
  }
  const int rest = static_cast<int>(std::ceil(t0));  // samples before the release
  if (rest < kMinRestSamples + 1) return detection;
  // A rest segment must be needed: where one smooth cubic from the record's first sample fits
  // the samples up to the onset window's end about as well (within 25 noise variances), the
  // record was moving from its start (a logger started after the release: at 2 kHz, 50 ms
  // into the crane's decay, the first 35 samples moved less than 10 % of the range and were
  // taken for a rest).
  OnsetFit whole = fit;
  whole.first = 0;
  if (SmoothCost(y, range, last) <= whole.Cost(t0) + 25 * noise_variance) return detection;
  // The segment before must really be at rest: within kRestFraction of its own median. A short
  // "rest" at the record's very start may be the first samples of a release from rest that the
  // cubic cannot follow over its window (the crane's load drop recorded from the release: 5
  // samples "at rest" while phi moved 49 noise standard deviations, the release put 45 ms
  // late). Where fewer than kShortRestSamples precede the release, each channel must also stay
  // within 6 noise standard deviations of that median (the noise from the whole record's third
  // differences; a coarsely sampled decay overstates it, which leaves the test lenient).
  const std::vector<double> levels = RestLevels(y, rest);
  for (Eigen::Index c = 0; c < m; ++c) {
    const double level = levels[static_cast<size_t>(c)];
    double bound = kRestFraction * range(c);
    const double noise = ThirdDifferenceNoise(y.col(c));
    // A long rest in a channel whose noise is a few % of its range holds 4-sigma samples beyond
    // a tenth of the range (2 kHz, 4000 samples: the release of a 0.0155 rad swing was missed).
    bound = rest < kShortRestSamples ? std::min(bound, 6 * noise) : std::max(bound, 6 * noise);
    if ((y.col(c).head(rest).array() - level).abs().maxCoeff() > bound) return detection;
  }
  detection.detected = true;
  detection.rest_level = levels;
  detection.from_rest = !jumps && !moving_off;
  detection.rest_samples = rest;
  detection.release_time_s = record.start_time_s + t0 * record.sample_interval_s;
  detection.description = fmt::format("free decay starts at {:.6g} s after {} samples at rest",
                                      detection.release_time_s, rest);
  return detection;
}

namespace {

// DetectRelease's first change from rest, in the channels with a signal.
ReleaseDetection DetectFirstRelease(const Measurement& record) {
  // A channel whose whole range is within a few times its noise (a sensor the test does not
  // excite: the out-of-plane accelerometer of a planar load drop) crosses any fraction of that
  // range at once, and no release was found: a knuckle-boom drop analysed from the record's
  // start, 19 modes, the release taken for a glitch. The onset is looked for in the channels
  // with a signal (a range over kQuietRange times the noise); the levels at rest are all.
  constexpr double kQuietRange = 20;
  std::vector<Eigen::Index> signal;
  for (Eigen::Index c = 0; c < record.values.cols(); ++c) {
    const double range = record.values.col(c).maxCoeff() - record.values.col(c).minCoeff();
    if (range > kQuietRange * ThirdDifferenceNoise(record.values.col(c))) signal.push_back(c);
  }
  if (signal.empty() || static_cast<Eigen::Index>(signal.size()) == record.values.cols()) {
    return DetectReleaseInChannels(record);
  }
  Measurement part = record;
  part.values.resize(record.values.rows(), static_cast<Eigen::Index>(signal.size()));
  part.channels.clear();
  part.units.clear();
  for (size_t k = 0; k < signal.size(); ++k) {
    const auto c = static_cast<size_t>(signal[k]);
    part.values.col(static_cast<Eigen::Index>(k)) = record.values.col(signal[k]);
    part.channels.push_back(record.channels[c]);
    if (c < record.units.size()) part.units.push_back(record.units[c]);
  }
  ReleaseDetection detection = DetectReleaseInChannels(part);
  if (detection.detected) {  // every channel's, glitches bridged as for the detection's own
    detection.rest_level = RestLevels(BridgeGlitches(record.values), detection.rest_samples);
  }
  return detection;
}

// The first sample from `from` on that opens `quiet_samples` samples at rest at a new level:
// every channel within 6 noise standard deviations (from its third differences) of the window's
// median without a drift, and some channel's median that far from its level at rest before
// (`before`; a slow start of the motion is still that rest). -1 if none.
int FindNewRest(const Eigen::MatrixXd& y, const Eigen::VectorXd& noise,
                const std::vector<double>& before, int from, int quiet_samples) {
  const int n = static_cast<int>(y.rows());
  for (int j = from; j + quiet_samples <= n; ++j) {
    bool quiet = true, moved = false;
    for (Eigen::Index c = 0; c < y.cols() && quiet; ++c) {
      std::vector<double> window(y.col(c).data() + j, y.col(c).data() + j + quiet_samples);
      std::nth_element(window.begin(), window.begin() + quiet_samples / 2, window.end());
      const double median = window[static_cast<size_t>(quiet_samples / 2)];
      const auto segment = y.col(c).segment(j, quiet_samples);
      // No drift either: the halves' means agree within 2 noise standard deviations (their
      // difference has 0.45 of one); a slow ramp stays within 6 of a median for 20 samples.
      const double drift =
          segment.tail(quiet_samples / 2).mean() - segment.head(quiet_samples / 2).mean();
      quiet = (segment.array() - median).abs().maxCoeff() <= 6 * noise(c) &&
              std::abs(drift) <= 2 * noise(c);
      moved = moved || std::abs(median - before[static_cast<size_t>(c)]) > 6 * noise(c);
    }
    if (quiet && moved) return j;
  }
  return -1;
}

}  // namespace

namespace internal {

// The most reversals of direction, beyond 10 noise standard deviations (a hysteresis), that a
// channel makes over samples [begin, end): a free decay makes two a period, a step or a ramp
// none. Noise alone over a flat stretch reaches about 4 of its standard deviations either way
// in 10^4 samples (5 in 10^6): a hysteresis of 6 counted a winch's 3 s pull at 2 kHz as swinging
// twice, and its start was taken for the release, 5 s early.
int Reversals(const Eigen::MatrixXd& y, const Eigen::VectorXd& noise, int begin, int end) {
  int most = 0;
  for (Eigen::Index c = 0; c < y.cols(); ++c) {
    const double h = 10 * noise(c);
    if (!(h > 0) || end - begin < 2) continue;
    // The first move beyond h sets the direction; each move back beyond h from the extreme
    // since is a reversal.
    int count = 0, direction = 0;
    const double start = y(begin, c);
    double extreme = start;
    for (int j = begin + 1; j < end; ++j) {
      const double v = y(j, c);
      if (direction == 0) {
        if (std::abs(v - start) > h) {
          direction = v > start ? 1 : -1;
          extreme = v;
        }
      } else if ((v - extreme) * direction > 0) {
        extreme = v;
      } else if (std::abs(v - extreme) > h) {
        ++count;
        direction = -direction;
        extreme = v;
      }
    }
    most = std::max(most, count);
  }
  return most;
}

}  // namespace internal

ReleaseDetection DetectRelease(const Measurement& record) {
  ReleaseDetection detection = DetectFirstRelease(record);
  // A change from rest that no oscillation follows before the structure is at rest again is not
  // the release: a logger's leading zeros before the rest level, a winch's pull and hold before
  // the load drop (a trial's records: the release taken 1.3 and 3.1 s early, and the real one
  // for a glitch). The release is looked for again from that rest on. A slow pull from the
  // record's start is no detected change at all (one cubic follows it): the record's start
  // then stands for it.
  const Eigen::MatrixXd y = BridgeGlitches(record.values);
  const int n = static_cast<int>(y.rows());
  // A rest lasts 0.1 s at least: 20 samples at 2 kHz are 10 ms, which a winch's slow pull
  // passes within its noise, and the pull's start was taken for the release, 5 s early.
  const int quiet_samples =
      std::max(kQuietSamples, static_cast<int>(std::ceil(0.1 / record.sample_interval_s - 1e-9)));
  if (n < 2 * quiet_samples) return detection;
  Eigen::VectorXd noise(y.cols());
  for (Eigen::Index c = 0; c < y.cols(); ++c) noise(c) = ThirdDifferenceNoise(y.col(c));
  int change = detection.detected ? detection.rest_samples : 0;
  std::vector<double> before =
      detection.detected ? detection.rest_level : RestLevels(y, std::min(5, n));
  double passed_s = detection.detected ? detection.release_time_s : record.start_time_s;
  for (int round = 0; round < 6; ++round) {
    const int quiet = FindNewRest(y, noise, before, change, quiet_samples);
    if (quiet < 0 || Reversals(y, noise, change, quiet) > 1) break;
    Measurement rest = record;
    rest.start_time_s = record.start_time_s + quiet * record.sample_interval_s;
    rest.values = record.values.bottomRows(n - quiet);
    ReleaseDetection later = DetectFirstRelease(rest);
    if (later.detected && later.release_time_s > passed_s) {
      later.description += fmt::format(
          " (the change at {:.6g} s before it, which no oscillation followed, is no release)",
          passed_s);
      later.rest_samples += quiet;
      detection = later;
      change = detection.rest_samples;
      before = detection.rest_level;
      passed_s = detection.release_time_s;
    } else {
      // At rest from `quiet` on, and what follows sets off too slowly to be seen as a change
      // (a pull): the next rest at a new level is looked for from there.
      change = quiet;
      const int head = std::min(5, n - quiet);
      before = RestLevels(y.middleRows(quiet, head), head);
      passed_s = rest.start_time_s;
    }
  }
  return detection;
}

double RefineReleaseFromModes(const ModalResult& modes, double coarse_time_s,
                              const std::vector<double>& rest_level) {
  const double tau = modes.sample_interval_s;
  const size_t channels = modes.channels.size();
  if (modes.modes.empty() || channels == 0 || !(tau > 0)) return coarse_time_s;
  std::vector<double> scale(channels, 0.0);
  for (const IdentifiedMode& mode : modes.modes) {
    for (size_t c = 0; c < channels; ++c) {
      scale[c] += mode.amplitude(static_cast<Eigen::Index>(c)) * std::abs(mode.lambda);
    }
  }
  // Sum of squared velocities, each channel relative to its largest possible one.
  const auto velocity_norm = [&](double t) {
    const double s = t - modes.start_time_s;
    double sum = 0;
    for (size_t c = 0; c < channels; ++c) {
      if (!(scale[c] > 0)) continue;
      double v = 0;
      for (const IdentifiedMode& mode : modes.modes) {
        const auto k = static_cast<Eigen::Index>(c);
        const double d = mode.decay_rate_per_s, w = 2 * M_PI * mode.frequency_hz;
        const double angle = w * s + mode.phase_rad(k);
        v += mode.amplitude(k) * std::exp(-d * s) * (-d * std::cos(angle) - w * std::sin(angle));
      }
      sum += std::pow(v / scale[c], 2);
    }
    return sum;
  };
  // How far to look: 3 samples, or an eighth of the period of the fastest mode that carries a
  // tenth of some channel's velocity, whichever is longer. A finely sampled onset is found late
  // by several samples (the motion stays within the noise while it grows as t^2: 6 samples at
  // 2 kHz on the crane), and within an eighth of a period the velocities vanish together only
  // at the release.
  double top_hz = 0;
  for (const IdentifiedMode& mode : modes.modes) {
    for (size_t c = 0; c < channels; ++c) {
      const double share = mode.amplitude(static_cast<Eigen::Index>(c)) * std::abs(mode.lambda);
      if (share >= 0.1 * scale[c]) top_hz = std::max(top_hz, mode.frequency_hz);
    }
  }
  const double reach = top_hz > 0 ? std::max(3 * tau, 0.125 / top_hz) : 3 * tau;
  // The onset of a release from rest comes late, never early (the motion grows out of the noise
  // as t^2): twice the reach before it, once after, on a quarter-sample grid; then a hundredth of
  // a sample about the grid's best point.
  const int coarse_steps = static_cast<int>(std::ceil(12 * reach / tau));
  double best = coarse_time_s, best_value = velocity_norm(coarse_time_s), top_value = best_value;
  int best_step = -1;
  for (int i = 0; i <= coarse_steps; ++i) {
    const double t = coarse_time_s - 2 * reach + 3 * reach * i / coarse_steps;
    const double value = velocity_norm(t);
    top_value = std::max(top_value, value);
    if (value < best_value) best_value = value, best = t, best_step = i;
  }
  // The velocities vanish together inside the reach, far below their size at its ends; a least
  // value at an end, or one not a tenth of the largest, is no release the modes know (a mode the
  // noise hid: at 1e-4 rad on the crane at 2 kHz, the 2.2 Hz mode, and the least value sat at
  // the reach's end, 16 ms early): the onset stands.
  if (best_step == 0 || best_step == coarse_steps || !(best_value < 0.1 * top_value)) {
    return coarse_time_s;
  }
  const double centre = best;
  for (int i = 0; i <= 50; ++i) {
    const double t = centre + (i / 50.0 - 0.5) * 0.5 * tau;
    const double value = velocity_norm(t);
    if (value < best_value) best_value = value, best = t;
  }
  // Released from rest, the modes start from the level at rest: where they do not, they miss
  // part of the motion, and where their velocities vanish together says nothing of the release.
  for (size_t c = 0; c < channels && c < rest_level.size(); ++c) {
    const auto k = static_cast<Eigen::Index>(c);
    const double s = best - modes.start_time_s;
    double y = modes.offset.size() > k ? modes.offset(k) : 0.0, amplitude = 0;
    for (const IdentifiedMode& mode : modes.modes) {
      y += mode.amplitude(k) * std::exp(-mode.decay_rate_per_s * s) *
           std::cos(2 * M_PI * mode.frequency_hz * s + mode.phase_rad(k));
      amplitude += std::abs(mode.amplitude(k));
    }
    if (std::abs(y - rest_level[c]) > 0.1 * amplitude) return coarse_time_s;
  }
  return best;
}

Measurement CutAtRelease(const Measurement& record, double release_time_s,
                         const std::string& origin) {
  const double tau = record.sample_interval_s;
  const double position = (release_time_s - record.start_time_s) / tau;
  const int first = std::max(0, static_cast<int>(std::ceil(position - 1e-6)));
  if (!std::isfinite(release_time_s) || first > record.samples() - 2) {
    throw InputError(
        origin, "release_time_s",
        fmt::format("{} s leaves {} samples of the record ({} .. {} s)", release_time_s,
                    std::max(0, record.samples() - first), record.start_time_s,
                    record.start_time_s + (record.samples() - 1) * tau),
        "a release time at least two samples before the record's end");
  }
  Measurement cut = record;
  cut.values = record.values.bottomRows(record.samples() - first);
  cut.start_time_s = std::max(0.0, (first - position) * tau);
  return cut;
}

}  // namespace mbid::identification
