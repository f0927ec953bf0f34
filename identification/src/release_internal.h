#pragma once

// What release.cc's detection shares with next_excitation.cc.

#include <Eigen/Core>

namespace mbid::identification::internal {

// Samples a segment at rest must hold to end a change that no free decay followed (and 0.1 s).
inline constexpr int kQuietSamples = 20;

// The record with its glitches bridged (outliers.h): a sample that jumps off a channel's course
// and back is no release and no rest's end.
Eigen::MatrixXd BridgeGlitches(const Eigen::MatrixXd& y);

// The noise standard deviation of a channel from its third differences.
double ThirdDifferenceNoise(const Eigen::VectorXd& y);

// The most reversals of direction, beyond 10 noise standard deviations, that a channel makes
// over samples [begin, end): a free decay makes two a period, a step or a ramp none.
int Reversals(const Eigen::MatrixXd& y, const Eigen::VectorXd& noise, int begin, int end);

}  // namespace mbid::identification::internal
