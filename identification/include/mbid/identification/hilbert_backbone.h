#pragma once

#include <Eigen/Core>

#include "mbid/identification/backbone.h"

namespace mbid::identification {

// A mode's backbone from its analytic signal, the second estimator beside the sliding-window
// fits (backbone.h). `mode_alone` is one channel with every other mode subtracted, its samples
// at t = start_time_s + j tau, with white noise of `noise_std` per sample (0 if unknown). It is
// band-passed around `frequency_hz` (gain 1 from 0.6 to 1.4 times it, raised-cosine edges down
// to 0.4 and up to 1.6 times it, zero-padded against wrap-around) and made analytic by Eigen's
// FFT (as the spectrum): z = a e^{i phi}. In windows of 4 periods (half overlapping), a straight
// line fitted to the unwrapped phase gives the angular frequency and one fitted to ln a the decay
// rate. Their standard deviations take the larger of the fits' residuals and what the band's
// noise gives (s_z^2 / (2 a^2) per sample in phase and in ln a), counted over the independent
// samples the band leaves (one per 1 / bandwidth). The first and last 3 periods (the band-pass's
// transients) are left out, and the estimate ends where the amplitude in a window falls below
// 10 times the band's noise level. Empty when no window remains.
BackboneCurve CalcHilbertBackbone(const Eigen::VectorXd& mode_alone, double sample_interval_s,
                                  double start_time_s, double frequency_hz, double noise_std);

}  // namespace mbid::identification
