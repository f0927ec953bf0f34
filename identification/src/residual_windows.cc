#include "residual_windows.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "estimate.h"
#include "mbid/identification/significance.h"
#include "out_of_band.h"

namespace mbid::identification {

ResidualWindows AnalyseResidualWindows(const Eigen::MatrixXd& values,
                                       const Eigen::MatrixXd& residual, double false_alarm) {
  const int n = static_cast<int>(residual.rows());
  const Eigen::Index channels = residual.cols();
  ResidualWindows result;
  result.channel_ratio = Eigen::VectorXd::Zero(channels);
  // Windows of 2 % of the record, at least 20 samples: short enough for a mode decaying within
  // a tenth of the record, long enough for a power estimate.
  const int length = std::max(20, n / 50);
  const int windows = n / length;
  if (windows < 8 || channels == 0) return result;
  Eigen::MatrixXd power(windows, channels);
  for (Eigen::Index c = 0; c < channels; ++c) {
    for (int w = 0; w < windows; ++w) {
      power(w, c) = residual.col(c).segment(w * length, length).squaredNorm() / length;
    }
    // The median window's power is the noise's: robust to the few windows that are not noise.
    std::vector<double> sorted(power.col(c).data(), power.col(c).data() + windows);
    std::nth_element(sorted.begin(), sorted.begin() + windows / 2, sorted.end());
    // A noiseless record's round-off is no excess: AssessReliability's floor.
    const double level = std::max(sorted[static_cast<size_t>(windows / 2)],
                                  std::pow(RoundOffNoiseStd(values, c), 2));
    if (level > 0) {
      power.col(c) /= level;
    } else {
      power.col(c).setZero();  // an exact fit: nothing to judge
    }
    result.channel_ratio(c) = power.col(c).maxCoeff();
  }
  const int dof = length * static_cast<int>(channels);
  const double threshold =
      CalcChiSquareThreshold((dof + 1) / 2, false_alarm / windows) / static_cast<double>(dof);
  Eigen::Index worst = 0;
  const double ratio = power.rowwise().mean().maxCoeff(&worst);
  if (ratio > std::max(2.0, threshold)) {
    result.excess = ResidualWindows::Excess{static_cast<int>(worst) * length, length, ratio};
  }
  return result;
}

std::optional<ResidualWindows::Excess> FindExcessAtTheStart(const Eigen::MatrixXd& values,
                                                            const Eigen::MatrixXd& residual,
                                                            double sample_interval_s, double top_hz,
                                                            double false_alarm) {
  const ResidualWindows windows =
      AnalyseResidualWindows(values, BandLimited(residual, sample_interval_s, top_hz), false_alarm);
  if (!windows.excess || windows.excess->first_sample != 0) return std::nullopt;
  return windows.excess;
}

}  // namespace mbid::identification
