#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace mbid {

// A uniformly sampled multichannel record: y_j = y(t0 + j * tau), j = 0..N-1 (method.md, the
// record below eq. 2). Values are SI (radians for angles); one column per channel.
struct Measurement {
  std::vector<std::string> channels;  // in file order
  std::vector<std::string> units;     // one per channel, e.g. "rad"
  double start_time_s = 0.0;
  double sample_interval_s = 0.0;     // tau
  Eigen::MatrixXd values;             // samples x channels
  std::string source = "import";      // "simulation" | "import" | ...

  int samples() const { return static_cast<int>(values.rows()); }
  int channel_count() const { return static_cast<int>(values.cols()); }
  Eigen::VectorXd CalcTime() const;
  // Index of `channel`, or -1.
  int FindChannel(const std::string& channel) const;

  // Throws InputError naming `origin` (usually the file) unless: at least two samples, at least
  // one channel, names and units match the columns, names unique and non-empty, a positive
  // finite sample interval, and every value finite (the error names the channel and sample).
  void Validate(const std::string& origin) const;
};

}  // namespace mbid
