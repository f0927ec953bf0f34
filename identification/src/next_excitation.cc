// A second excitation after the free decay came to rest (release.h: FindNextExcitation).
#include <fmt/format.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <deque>
#include <optional>
#include <vector>

#include "mbid/identification/release.h"
#include "release_internal.h"

namespace mbid::identification {

namespace {

using internal::kQuietSamples;

// The first sample from `begin` on that opens a window at rest as long as a quarter of the time
// since `begin` (at least kQuietSamples): every channel within a band of 12 noise standard
// deviations without a drift, after some channel has moved over 16 of them since `begin`. A
// quarter of the decay's time spans more than a period of any mode damped below 0.1 that took
// that long to die out, so no crest of a slow swing and no node of two beating modes (each far
// shorter than half their beat) passes for a rest. -1 if none; *length is the window's.
int FindRestAfterMotion(const Eigen::MatrixXd& y, const Eigen::VectorXd& noise, int begin,
                        int* length, int cap) {
  const int n = static_cast<int>(y.rows());
  const Eigen::Index m = y.cols();
  Eigen::MatrixXd sum = Eigen::MatrixXd::Zero(n + 1, m);
  for (int j = 0; j < n; ++j) sum.row(j + 1) = sum.row(j) + y.row(j);
  // The window [a, end) only moves right at both ends: its extremes in monotone deques.
  std::vector<std::deque<int>> high(static_cast<size_t>(m)), low(static_cast<size_t>(m));
  Eigen::VectorXd seen_max = y.row(begin).transpose(), seen_min = seen_max;
  bool moved = false;
  int end = begin;
  for (int a = begin; a < n; ++a) {
    *length = std::max(kQuietSamples, std::min((a - begin) / 4, cap));
    if (a + *length > n) return -1;
    for (; end < a + *length; ++end) {
      for (Eigen::Index c = 0; c < m; ++c) {
        auto& h = high[static_cast<size_t>(c)];
        auto& l = low[static_cast<size_t>(c)];
        while (!h.empty() && y(h.back(), c) <= y(end, c)) h.pop_back();
        while (!l.empty() && y(l.back(), c) >= y(end, c)) l.pop_back();
        h.push_back(end);
        l.push_back(end);
      }
    }
    bool quiet = moved;
    for (Eigen::Index c = 0; c < m && quiet; ++c) {
      // A rest is inside the motion that died out to it, in the middle half of its range: a
      // clipped crest held at the rail (the logger's end of range) is at its edge.
      const double middle = 0.5 * (seen_max(c) + seen_min(c));
      const double half_range = 0.5 * (seen_max(c) - seen_min(c));
      auto& h = high[static_cast<size_t>(c)];
      auto& l = low[static_cast<size_t>(c)];
      while (h.front() < a) h.pop_front();
      while (l.front() < a) l.pop_front();
      const int half = *length / 2;
      const double drift = (sum(a + *length, c) - sum(a + *length - half, c)) / half -
                           (sum(a + half, c) - sum(a, c)) / half;
      const double level = (sum(a + *length, c) - sum(a, c)) / *length;
      quiet = y(h.front(), c) - y(l.front(), c) <= 12 * noise(c) &&
              std::abs(drift) <= 2 * noise(c) &&
              (half_range <= 8 * noise(c) || std::abs(level - middle) <= 0.5 * half_range);
    }
    if (quiet) return a;
    seen_max = seen_max.cwiseMax(y.row(a).transpose());
    seen_min = seen_min.cwiseMin(y.row(a).transpose());
    moved = moved || ((seen_max - seen_min).array() > 16 * noise.array()).any();
  }
  return -1;
}

}  // namespace

std::optional<NextExcitation> FindNextExcitation(const Measurement& record, double release_time_s) {
  const Eigen::MatrixXd y = internal::BridgeGlitches(record.values);
  const int n = static_cast<int>(y.rows());
  const Eigen::Index m = y.cols();
  const double tau = record.sample_interval_s;
  const int begin = std::clamp(
      static_cast<int>(std::ceil((release_time_s - record.start_time_s) / tau - 1e-6)), 0, n);
  if (n - begin < 4 * kQuietSamples || m == 0) return std::nullopt;
  Eigen::VectorXd noise(m);
  for (Eigen::Index c = 0; c < m; ++c) {
    noise(c) = internal::ThirdDifferenceNoise(y.col(c).segment(begin, n - begin));
  }
  int length = 0;
  // At most 10 s: over a minute's decay a quarter of it outlasted the rest before a reload (a
  // re-audit's drops at 0.5-10 kHz), and 10 s are half a period of a 0.05 Hz pendulum: no crest
  // rests that long.
  const int cap = std::max(kQuietSamples, static_cast<int>(10.0 / tau));
  const int rest = FindRestAfterMotion(y, noise, begin, &length, cap);
  if (rest < 0) return std::nullopt;
  const Eigen::VectorXd level = y.middleRows(rest, length).colwise().mean().transpose();
  const auto off = [&](int j, double band) {
    return ((y.row(j).transpose() - level).array().abs() > band * noise.array()).any();
  };
  int away = rest + length;
  while (away < n && !off(away, 8)) ++away;
  if (away == n) return std::nullopt;
  // An excitation, not a sensor's drift: it swings (two reversals), or moves within the rest's
  // length by a tenth of the decay's own range (a reload, a step), at least 20 noise std.
  const Eigen::ArrayXd range = (y.middleRows(begin, rest - begin).colwise().maxCoeff() -
                                y.middleRows(begin, rest - begin).colwise().minCoeff())
                                   .transpose()
                                   .array();
  const Eigen::ArrayXd step = (0.1 * range).max(20 * noise.array());
  bool quick = false;
  for (int j = away; j < std::min(n, away + length) && !quick; ++j) {
    quick = ((y.row(j).transpose() - level).array().abs() > step).any();
  }
  // The swing within the rest's length, not over the rest of the record: a sensor's random-walk
  // drift wanders past 10 noise std both ways over a minute (a re-audit's record was cut so).
  if (!quick && internal::Reversals(y, noise, away, std::min(n, away + length)) < 2) {
    return std::nullopt;
  }
  int start = away;
  while (start > rest + length && off(start - 1, 3)) --start;
  NextExcitation next;
  next.rest_s = record.start_time_s + rest * tau;
  next.time_s = record.start_time_s + start * tau;
  next.description = fmt::format(
      "the structure is at rest again from {:.6g} s and set off again at {:.6g} s: a second "
      "excitation (a reload and release, a knock) or a change of a sensor (a re-zero, hum "
      "switching on) that is no part of this free decay",
      next.rest_s, next.time_s);
  return next;
}

}  // namespace mbid::identification
