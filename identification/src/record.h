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
  double decimated_start_time_s = 0;  // time of the decimated record's first sample
  double max_frequency_hz = 0;        // the band's upper limit (resolved from 0 = Nyquist)
  int decimation = 1;                 // as used (resolved from 0 = automatic)
  // The highest frequency the low-pass filter passes flat (the Nyquist frequency without
  // decimation): modes above it are at the band's edge.
  double flat_frequency_hz = 0;
};

// The rows of `measurement` in the options' time window: window_start_s <= t_j <= window_end_s,
// with half a sample of slack so that a window given on the sample grid keeps its end samples.
// None when last < first.
struct WindowRows {
  int first = 0;
  int last = -1;
  int count() const { return last - first + 1; }
};
WindowRows FindWindowRows(const Measurement& measurement, const IdentificationOptions& options);

// Applies the options (already checked by Identify, its caller) to the measurement and checks the
// input (see Identify for the errors).
AnalysisRecord PrepareRecord(const Measurement& measurement, const IdentificationOptions& options,
                             const std::string& origin);

// The decimation factor for IdentificationOptions::decimation = 0: the largest that keeps the
// band (max_frequency_hz if > 0, else 1.25 x the highest frequency where some channel's
// spectrum stands 10x above its median, the noise floor) inside the filter's flat part and at
// least 500 samples; 1 if the record is not oversampled.
int ChooseDecimation(const Eigen::MatrixXd& centered, double sample_interval_s,
                     double max_frequency_hz);

// The largest decimation factor whose filter passes `band_hz` flat and leaves at least 500 of
// `samples`; at least 1.
int DecimationForBand(double band_hz, double sample_interval_s, Eigen::Index samples);

// Samples of the decimated record that the method's order needs.
int RequiredSamples(const IdentificationOptions& options, int channels);

}  // namespace mbid::identification
