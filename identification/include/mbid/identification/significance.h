#pragma once

#include <Eigen/Core>

#include "mbid/identification/modal_fit.h"

namespace mbid::identification {

// Per mode of a linear amplitude fit (modal_fit.h): the increase of each channel's residual
// sum of squares, divided by that channel's residual variance, if the mode's two amplitudes
// were removed with the poles held, summed over channels:
//   sum_c beta_kc^T [(Phi^T Phi)^-1]_kk^-1 beta_kc / sigma_c^2.
// This is the Wald statistic of "mode k is absent": chi-square with 2 degrees of freedom per
// channel under that hypothesis. For well separated modes it is the mode's energy over the
// noise variance; unlike the energy it stays small for spurious poles whose large amplitudes
// cancel each other. A noiseless record gets a very large (finite) value (the variance floor of
// AmplitudeFit).
Eigen::VectorXd CalcSignificance(const AmplitudeFit& fit);

// The significance that pure white noise exceeds with probability `false_alarm` per record:
// x with P(chi-square(2 m) > x) = false_alarm / (10 samples), a Bonferroni bound over the
// about 10 * samples distinguishable (frequency, decay) cells a mode fitted to noise can choose
// from (samples / 2 frequencies times about 20 decays). About 38 for 2 x 1000 samples at 1e-3,
// 53 for 2 x 1e6.
double CalcSignificanceThreshold(int samples, int channels, double false_alarm);

// x with P(chi-square(2 m) > x) = probability: a single test's threshold, without the
// Bonferroni factor of CalcSignificanceThreshold.
double CalcChiSquareThreshold(int m, double probability);

}  // namespace mbid::identification
