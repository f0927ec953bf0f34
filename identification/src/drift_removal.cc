#include "mbid/identification/drift_removal.h"

#include <cmath>

#include "mbid/identification/identify.h"

namespace mbid::identification {

ModalResult IdentifyRemovingDrift(const Measurement& measurement,
                                  const IdentificationOptions& options, const std::string& origin) {
  IdentificationOptions inner = options;
  inner.remove_drift = false;
  ModalResult result = Identify(measurement, inner, origin);
  const std::string release = result.release;
  if (inner.release == ReleaseMode::kDetect) {
    // The drift is fitted on the decay the first identification found.
    inner.release = ReleaseMode::kGiven;
    inner.release_time_s = result.release_time_s;
  }
  Measurement corrected = measurement;
  const Eigen::VectorXd t_all = measurement.CalcTime();
  Eigen::VectorXd drift = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(result.channels.size()));
  for (int pass = 0; pass < 2; ++pass) {
    const double tau = measurement.sample_interval_s;
    const Eigen::Index first = std::lround((result.start_time_s - measurement.start_time_s) / tau);
    const Eigen::Index n = result.samples;
    // Time from the first analysed sample, centred for the line's fit.
    const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(n, 0.0, (n - 1) * tau);
    const Eigen::VectorXd centred = t.array() - t.mean();
    for (size_t c = 0; c < result.channels.size(); ++c) {
      const int column = corrected.FindChannel(result.channels[c]);
      const Eigen::Index k = static_cast<Eigen::Index>(c);
      // What the modes leave: the record less the reconstruction's modes (its offset kept out).
      const Eigen::VectorXd left =
          corrected.values.col(column).segment(first, n) -
          (result.reconstruction.col(k).array() - result.offset(k)).matrix();
      const double slope = centred.dot(left) / centred.squaredNorm();
      drift(k) += slope;
      corrected.values.col(column).array() -= slope * (t_all.array() - result.start_time_s);
    }
    result = Identify(corrected, inner, origin);
  }
  result.release = release;
  result.drift_per_s = drift;
  return result;
}

}  // namespace mbid::identification
