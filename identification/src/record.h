#pragma once

// The part of a measurement that is analysed: time window, channel selection, input checks,
// offset removal and decimation (IdentificationOptions' record options).

#include <Eigen/Core>
#include <string>
#include <vector>

#include "mbid/common/measurement.h"
#include "mbid/identification/options.h"

namespace mbid::identification {

struct AnalysisRecord {
  std::vector<std::string> channels;
  std::vector<std::string> units;
  double sample_interval_s = 0;
  double start_time_s = 0;   // time of the first analysed sample
  Eigen::MatrixXd values;    // samples x channels, as recorded
  Eigen::VectorXd mean;      // per channel; zero for OffsetRemoval::kNone
  Eigen::MatrixXd centered;  // values - mean
  // Poles are estimated on this one: `centered` low-pass filtered and downsampled by the
  // decimation factor (equal to `centered` for decimation 1).
  Eigen::MatrixXd decimated;
  double decimated_interval_s = 0;
  double max_frequency_hz = 0;  // the band's upper limit (resolved from 0 = Nyquist)
};

// Applies the options to the measurement and checks the input (see Identify for the errors).
AnalysisRecord PrepareRecord(const Measurement& measurement, const IdentificationOptions& options,
                             const std::string& origin);

// Samples of the decimated record that the method's order needs.
int RequiredSamples(const IdentificationOptions& options, int channels);

}  // namespace mbid::identification
