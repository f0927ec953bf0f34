#pragma once

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

namespace mbid {

// A uniformly sampled multichannel record: y_j = y(t0 + j * tau), j = 0..N-1 (method.md, the
// record below eq. 2). Values are SI (radians for angles); one column per channel.
struct Measurement {
  std::vector<std::string> channels;  // in file order
  std::vector<std::string> units;     // one per channel, e.g. "rad"
  double start_time_s = 0.0;
  double sample_interval_s = 0.0;  // tau
  Eigen::MatrixXd values;          // samples x channels
  std::string source = "import";   // "simulation" | "import" | ...
  // Relative half-width within which `sample_interval_s` is known, where a file prints it to few
  // digits (an LVM's Delta_X 0.000586 for 1706.67 Hz: 8.5e-4); 0 when exact. Every frequency and
  // decay rate read from the record carries it.
  double sample_interval_uncertainty = 0.0;

  int samples() const { return static_cast<int>(values.rows()); }
  // Made by mbid itself (`mbid simulate` or synthetic modes): it starts at the excitation and has
  // no sensor zero error, unlike a record imported from a test.
  bool made_by_mbid() const { return source == "simulation" || source == "synthetic"; }
  int channel_count() const { return static_cast<int>(values.cols()); }
  Eigen::VectorXd CalcTime() const;
  // Index of `channel`, or -1.
  int FindChannel(const std::string& channel) const;

  // Throws InputError naming `origin` (usually the file) unless: at least two samples, at least
  // one channel, names and units match the columns, names unique and non-empty, a positive
  // finite sample interval, and every value finite (the error names the channel and sample).
  // Names must also be writable to both file formats (ProblemWithChannelName).
  void Validate(const std::string& origin) const;
};

// Why `name` cannot be a channel of mbid's HDF5 and CSV files ("" when it can): empty, "time"
// in any case, "." or "..", blanks at either end, or with ',', '/' or a line break. The expected
// part of an error is kChannelNameRule.
std::string ProblemWithChannelName(const std::string& name);
inline constexpr char kChannelNameRule[] =
    "a name other than 'time' (in any case), '.' or '..', without blanks at its ends, ',', '/' "
    "or line breaks";

// Largest deviation of a sample time from the uniform grid t0 + j * tau, relative to tau, that
// a measurement file may have (docs/interfaces).
inline constexpr double kTimeUniformityTolerance = 1e-6;

// Checks a time column (seconds): at least two samples, all finite, strictly increasing, and
// uniform: |t_j - (t_0 + j * tau)| < kTimeUniformityTolerance * tau for tau = (t_{N-1} - t_0) /
// (N - 1). Returns tau. Errors are InputErrors with source `origin` and the field
// `field_of_sample(j)` of the offending sample j (e.g. "line 12" or "/measurement/time").
// A time column printed with few digits (`printed_resolution_s`, the place value of its last
// digit, > 0) is accepted when every time lies within that resolution of a uniform grid; tau
// and the start time (`fitted_start_s`, if given) are then the grid's least-squares fit, far
// more accurate than any one printed value.
double CheckUniformTime(const Eigen::VectorXd& time_s, const std::string& origin,
                        const std::function<std::string(Eigen::Index)>& field_of_sample,
                        double printed_resolution_s = 0.0, double* fitted_start_s = nullptr);

}  // namespace mbid
