#pragma once

#include <Eigen/Core>
#include <complex>
#include <optional>
#include <string>
#include <vector>

#include "mbid/identification/options.h"

namespace mbid::identification {

// A mode's frequency and damping ratio against its amplitude, point by point, each with one
// standard deviation.
struct BackboneCurve {
  std::vector<double> time_s;     // window centres, in the record's time
  std::vector<double> amplitude;  // the mode's amplitude at the centre, in its largest channel
  std::vector<double> frequency_hz, damping_ratio;
  std::vector<double> std_frequency_hz, std_damping_ratio;
};

// How one mode's frequency and damping change as it decays: a weakly nonlinear joint softens or
// stiffens with amplitude, and a constant-pole fit then splits the mode into two or three close
// poles. Estimated in sliding windows of 8 periods (half overlapping), each fitted with one
// damped sinusoid by the refinement, its standard deviations from the Fisher information (the
// inherited curve); and, as a second estimator, from the Hilbert transform's instantaneous
// amplitude and phase (hilbert_backbone.h).
struct Backbone : BackboneCurve {
  // The windows' frequencies scatter more than their standard deviations allow:
  // chi-square / (windows - 1) of their spread about the weighted mean above 4.
  bool amplitude_dependent = false;
  double spread_chi_square_per_dof = 0;
  std::optional<BackboneCurve> hilbert;  // unset when the mode is too short for it
};

// `mode_alone`: samples x channels of the record with every other mode subtracted; the record's
// samples are t = start_time_s + j tau. `lambda` starts each window's fit; `channel_weights` as
// RefineModalModel's (inverse noise levels). Windows whose fit fails or leaves the mode
// undetermined (frequency std above 5 %) are skipped; the backbone ends at the first window
// where the mode's amplitude is below twice the window's residual standard deviation (the mode
// has sunk into the noise). The Hilbert estimate is made on the mode's largest channel.
Backbone CalcBackbone(const Eigen::MatrixXd& mode_alone, double sample_interval_s,
                      double start_time_s, std::complex<double> lambda,
                      const Eigen::VectorXd& channel_weights, const RefinementOptions& options);

// "1.3286 to 1.3294 Hz, 0.06 %": the windows' lowest and highest frequency, printed to as many
// digits as tell them apart, and the drift relative to the highest.
std::string DescribeDrift(const BackboneCurve& backbone);

}  // namespace mbid::identification
