#pragma once

// Where a fit's residual is not noise: windows of the decimated record whose residual power
// stands above the residual's own level elsewhere (a missed heavily damped mode, a transient, a
// start before the free decay). The whole-record residual check cannot see a few tenths of a
// second of excess in a record of many seconds.

#include <Eigen/Core>
#include <optional>

namespace mbid::identification {

struct ResidualWindows {
  // Per channel: its largest window power over its median window's (the noise's; 0 when the
  // record is too short for 8 windows of 20 samples).
  Eigen::VectorXd channel_ratio;
  // The window whose power summed over channels (each over its median) exceeds
  // chi-square(window samples x channels) with probability false_alarm / windows and is at
  // least twice the median level; none when no window does.
  struct Excess {
    int first_sample = 0;  // in the residual's samples
    int samples = 0;
    double power_ratio = 0;  // the window's power over the median's, mean over channels
  };
  std::optional<Excess> excess;
};

// `values` is the record the residual is of: a window power under 1e-12 of its channel's mean
// square is round-off (a noiseless record), never an excess. With `start_band` > 0 (a full-rate
// residual, not a decimation filter's output; band-limited by BandLimited to that fraction of
// Nyquist, 1 when not) its start is judged in halves of a window too, down to 5 samples: a mode
// gone within a few milliseconds.
ResidualWindows AnalyseResidualWindows(const Eigen::MatrixXd& values,
                                       const Eigen::MatrixXd& residual, double false_alarm,
                                       double start_band = 0);

// The excess of a full-rate `residual` (of `values`) in its first window, judged in the band up
// to `top_hz` (out_of_band.h's BandLimited): what a decimated analysis, whose filter's output
// starts half its length in, cannot see. None when the first window is not the excess.
std::optional<ResidualWindows::Excess> FindExcessAtTheStart(const Eigen::MatrixXd& values,
                                                            const Eigen::MatrixXd& residual,
                                                            double sample_interval_s, double top_hz,
                                                            double false_alarm);

}  // namespace mbid::identification
