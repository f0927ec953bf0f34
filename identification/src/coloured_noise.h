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

// Per mode of `modes`: its significance with each channel's share (amplitude^2 / residual
// variance) divided by how far the residual's power near the mode's frequency stands above its
// mean over the band, where it stands significantly above it. The near band: 2 to 8 half-power
// bandwidths (at least the record's resolution) either side, widened to 64 bins, without the
// bins within 2 bandwidths of any mode. `residual` is samples x channels at `sample_interval_s`;
// `residual_variance` per channel.
std::vector<double> CalcLocalSignificance(const Eigen::MatrixXd& residual, double sample_interval_s,
                                          const Eigen::VectorXd& residual_variance,
                                          const std::vector<IdentifiedMode>& modes);

}  // namespace mbid::identification
