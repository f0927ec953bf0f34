#pragma once

// Outliers: single samples (or two) that jump far off a channel's course and back, as an
// electrical glitch of a sensor or logger or a knock on the sensor makes them. A free decay
// bends by little from one sample to the next; such a jump is broadband, so the identification
// spends modes on it and the updating bends the fit towards it. Both say so instead.

#include <Eigen/Core>
#include <string>
#include <vector>

namespace mbid {

struct Outlier {
  Eigen::Index sample = 0;  // index of the sample furthest off
  double ratio = 0;         // its second difference over the local spread of second differences
};

// Samples whose second difference y[j+1] - 2 y[j] + y[j-1] exceeds 30 times the median absolute
// second difference of the 32 samples around it (those next to it left out; at least the step
// of a quantized channel), and whose course is back three and four samples away (second
// differences there under a tenth of it): white noise reaches 7 times with a 6-sigma sample, a
// smoothly sampled decay about 3 times, and a mode near the sampling rate that decays within a
// few samples bends the course beyond (down to 30 % damping at 5 samples per period; at 50 % it
// is called a glitch). Adjacent samples are one outlier. Channels under 16 samples are not
// judged.
std::vector<Outlier> FindOutliers(const Eigen::Ref<const Eigen::VectorXd>& values);

// "channel psi jumps off its course at 3 s (41 times its local spread), and at 1 more sample: a
// glitch of the sensor or logger, or a knock"
std::string OutlierReason(const std::string& channel, const std::vector<Outlier>& outliers,
                          double sample_interval_s, double start_time_s);

}  // namespace mbid
