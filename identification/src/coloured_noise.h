#pragma once

// Noise that is not white (ambient vibration of a site, a sensor's low-frequency noise) has more
// power near some frequencies than its variance says. The significance test weighs a mode
// against the variance, so a bump of such noise passes it as a mode: a trial's AR(1) noise
// (coefficient 0.9) gave 1-4 extra modes between 0.3 and 2.4 Hz in 12 records of 30, reported
// reliable. Weighed against the residual's own level near its frequency, such a mode falls
// below the threshold; a mode of the structure stands far above either.

#include <Eigen/Core>
#include <vector>

#include "mbid/identification/modal_result.h"

namespace mbid::identification {

// How much more noise a mode sees near its frequency than the variance says: each channel's
// residual power 2 to 8 half-power bandwidths (at least the record's resolution) either side,
// widened to 64 bins, without the bins within 2 bandwidths of any mode, over its mean over the
// band, where it stands significantly above it (else 1); the channels combined as their shares
// of the mode's information (amplitude^2 / residual variance) combine. A mode's significance is
// divided by it, and its variances multiplied (the Cramer-Rao bound of a damped sinusoid in
// noise of spectral density S near it scales with S, not with the variance). `residual` is
// samples x channels at `sample_interval_s`; `residual_variance` per channel. 1 per mode where
// the record is too short to tell (fewer than 256 samples).
std::vector<double> CalcLocalNoiseRatio(const Eigen::MatrixXd& residual, double sample_interval_s,
                                        const Eigen::VectorXd& residual_variance,
                                        const std::vector<IdentifiedMode>& modes);

}  // namespace mbid::identification
