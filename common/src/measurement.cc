#include "mbid/common/measurement.h"

#include <fmt/format.h>

#include <cctype>
#include <cmath>
#include <set>

#include "mbid/common/error.h"
#include "mbid/common/utf8.h"

namespace mbid {
namespace {

std::string DescribeNonFinite(double value) {
  if (std::isnan(value)) return "NaN";
  return value > 0 ? "+Inf" : "-Inf";
}

}  // namespace

Eigen::VectorXd Measurement::CalcTime() const {
  Eigen::VectorXd time(values.rows());
  // t0 + j * tau per sample (not a running sum) so that files round-trip bit for bit.
  for (Eigen::Index j = 0; j < time.size(); ++j) {
    time[j] = start_time_s + static_cast<double>(j) * sample_interval_s;
  }
  return time;
}

int Measurement::FindChannel(const std::string& channel) const {
  for (size_t i = 0; i < channels.size(); ++i) {
    if (channels[i] == channel) return static_cast<int>(i);
  }
  return -1;
}

void Measurement::Validate(const std::string& origin) const {
  if (values.cols() < 1) {
    throw InputError(origin, "", "the measurement has no channels", "at least one channel");
  }
  if (values.rows() < 2) {
    throw InputError(origin, "", fmt::format("the measurement has {} samples", values.rows()),
                     "at least 2 samples");
  }
  if (channels.size() != static_cast<size_t>(values.cols())) {
    throw InputError(
        origin, "",
        fmt::format("{} channel names for {} value columns", channels.size(), values.cols()),
        "one name per column");
  }
  if (units.size() != channels.size()) {
    throw InputError(origin, "",
                     fmt::format("{} units for {} channels", units.size(), channels.size()),
                     "one unit per channel");
  }
  std::set<std::string> seen;
  for (size_t i = 0; i < channels.size(); ++i) {
    const std::string& name = channels[i];
    // Checked first: the other messages would quote the bad bytes.
    ValidateUtf8(name, origin, fmt::format("channel {} name", i + 1));
    ValidateUtf8(units[i], origin, fmt::format("channel {} unit", i + 1));
    if (name.empty()) {
      throw InputError(origin, fmt::format("channel {}", i), "empty channel name",
                       "a non-empty name");
    }
    if (const std::string problem = ProblemWithChannelName(name); !problem.empty()) {
      throw InputError(origin, name, problem, kChannelNameRule);
    }
    if (!seen.insert(name).second) {
      throw InputError(origin, name, fmt::format("channel '{}' appears twice", name),
                       "unique channel names");
    }
    if (units[i].empty()) {
      throw InputError(origin, name, "empty unit", "a unit such as 'rad'");
    }
  }
  ValidateUtf8(source, origin, "source");
  if (!std::isfinite(sample_interval_s) || sample_interval_s <= 0) {
    throw InputError(origin, "sample_interval_s",
                     fmt::format("sample interval {} s", sample_interval_s),
                     "a positive finite sample interval");
  }
  if (!std::isfinite(start_time_s)) {
    throw InputError(origin, "time", fmt::format("start time {} s", start_time_s),
                     "a finite start time");
  }
  for (Eigen::Index c = 0; c < values.cols(); ++c) {
    for (Eigen::Index j = 0; j < values.rows(); ++j) {
      const double v = values(j, c);
      if (!std::isfinite(v)) {
        throw InputError(origin, channels[c],
                         fmt::format("sample {} (t = {} s) is {}", j,
                                     start_time_s + static_cast<double>(j) * sample_interval_s,
                                     DescribeNonFinite(v)),
                         "finite values");
      }
    }
  }
}

namespace {

// A grid of interval `tau` printed to `resolution` has steps within `resolution` of tau (each
// time rounded or truncated by less than it). A dropped sample makes a step near 2 tau: found
// here when tau > 2 resolution, and where it is not, a step that long is refused as undecidable
// rather than read as a clock off its rate (the least-squares grid absorbs a dropped sample then).
void CheckPrintedSteps(const Eigen::VectorXd& time_s, const std::string& origin,
                       const std::function<std::string(Eigen::Index)>& field_of_sample,
                       double resolution, double tau) {
  const Eigen::Index n = time_s.size();
  // The fitted tau is off by about resolution / n; the last digit's parse by 1e-6 of it.
  const double slack = resolution * (1e-6 + 4.0 / static_cast<double>(n - 1));
  for (Eigen::Index j = 1; j < n; ++j) {
    const double step = time_s[j] - time_s[j - 1];
    if (std::abs(step - tau) > resolution + slack) {
      throw InputError(
          origin, field_of_sample(j),
          fmt::format("non-uniform time: step {:.9g} s from sample {} to {} where the grid's "
                      "interval is {:.9g} s (a dropped or repeated sample?)",
                      step, j - 1, j, tau),
          fmt::format("uniform sampling (steps within the printed resolution {:g} s of the "
                      "interval)",
                      resolution));
    }
  }
  Eigen::Index longest = 1;
  for (Eigen::Index j = 2; j < n; ++j) {
    if (time_s[j] - time_s[j - 1] > time_s[longest] - time_s[longest - 1]) longest = j;
  }
  const double step = time_s[longest] - time_s[longest - 1];
  if (tau < 2 * resolution && step >= 2 * tau - resolution) {
    throw InputError(
        origin, field_of_sample(longest),
        fmt::format("step {:.9g} s from sample {} to {} may be a dropped sample or the "
                    "rounding of a {:.9g} s interval: the time column, printed to {:g} s, "
                    "cannot tell",
                    step, longest - 1, longest, tau, resolution),
        "times printed with more digits, or the record's sample rate stated (`sample_rate_hz` in "
        "its record entry, --sample-rate-hz)");
  }
}

}  // namespace

std::string ProblemWithChannelName(const std::string& name) {
  if (name.empty()) return "empty channel name";
  std::string lower = name;
  for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  // "." and ".." are no HDF5 dataset names (a path's own and its parent's); "Time" is read back
  // as the time column, and blanks at the ends are trimmed by every reader of a CSV header.
  if (lower == "time" || name == "." || name == ".." || std::isspace(name.front()) ||
      std::isspace(name.back()) || name.find_first_of(",/\r\n") != std::string::npos) {
    return fmt::format("invalid channel name '{}'", name);
  }
  return "";
}

double CheckUniformTime(const Eigen::VectorXd& time_s, const std::string& origin,
                        const std::function<std::string(Eigen::Index)>& field_of_sample,
                        double printed_resolution_s, double* fitted_start_s) {
  const Eigen::Index n = time_s.size();
  if (n < 2) {
    throw InputError(origin, field_of_sample(0), fmt::format("{} time samples", n),
                     "at least 2 samples");
  }
  for (Eigen::Index j = 0; j < n; ++j) {
    if (!std::isfinite(time_s[j])) {
      throw InputError(origin, field_of_sample(j),
                       fmt::format("time of sample {} is {}", j, DescribeNonFinite(time_s[j])),
                       "finite times in seconds");
    }
  }
  for (Eigen::Index j = 1; j < n; ++j) {
    if (time_s[j] > time_s[j - 1]) continue;
    const std::string problem =
        time_s[j] == time_s[j - 1]
            ? fmt::format("time {} s of sample {} repeats sample {}", time_s[j], j, j - 1)
            : fmt::format("time decreases from {} s (sample {}) to {} s (sample {})", time_s[j - 1],
                          j - 1, time_s[j], j);
    // A repeat in a column that rises overall is a time printed coarser than its step (200 Hz
    // printed to 0.01 s): the logger's rate reads it.
    const bool coarse = time_s[j] == time_s[j - 1] && time_s[n - 1] > time_s[0];
    throw InputError(origin, field_of_sample(j), problem,
                     coarse ? "strictly increasing time, or, for a time printed coarser than its "
                              "step, the logger's sample rate (sample_rate_hz in the record "
                              "entry, --sample-rate-hz)"
                            : "strictly increasing time");
  }
  const double t0 = time_s[0];
  const double tau = (time_s[n - 1] - t0) / static_cast<double>(n - 1);
  double max_deviation = 0;
  for (Eigen::Index j = 0; j < n; ++j) {
    max_deviation =
        std::max(max_deviation, std::abs(time_s[j] - (t0 + static_cast<double>(j) * tau)));
  }
  if (fitted_start_s != nullptr) *fitted_start_s = t0;
  if (max_deviation < kTimeUniformityTolerance * tau) return tau;
  // Least squares t_j = a + j b over j = 0..n-1 (centred, so the sums stay exact enough).
  const double mean_j = 0.5 * static_cast<double>(n - 1);
  const double mean_t = time_s.mean();
  double sjt = 0, sjj = 0;
  for (Eigen::Index j = 0; j < n; ++j) {
    const double dj = static_cast<double>(j) - mean_j;
    sjt += dj * (time_s[j] - mean_t);
    sjj += dj * dj;
  }
  const double b = sjt / sjj;
  const double a = mean_t - b * mean_j;
  double worst_from_line = 0;
  for (Eigen::Index j = 0; j < n; ++j) {
    worst_from_line =
        std::max(worst_from_line, std::abs(time_s[j] - (a + static_cast<double>(j) * b)));
  }
  // Rounding to the printed digit moves a time by half its place value; allow the whole.
  if (printed_resolution_s > 0 && b > 0 && worst_from_line <= printed_resolution_s) {
    CheckPrintedSteps(time_s, origin, field_of_sample, printed_resolution_s, b);
    if (fitted_start_s != nullptr) *fitted_start_s = a;
    return b;
  }
  // The grid test decides; the step furthest from tau locates the gap or jump for the user.
  Eigen::Index worst = 1;
  double worst_step_deviation = -1;
  for (Eigen::Index j = 1; j < n; ++j) {
    const double d = std::abs((time_s[j] - time_s[j - 1]) - tau);
    if (d > worst_step_deviation) {
      worst_step_deviation = d;
      worst = j;
    }
  }
  throw InputError(
      origin, field_of_sample(worst),
      fmt::format("non-uniform time: step {:.9g} s from sample {} to {} differs from the mean "
                  "step {:.9g} s (relative deviation {:.3g})",
                  time_s[worst] - time_s[worst - 1], worst - 1, worst, tau,
                  worst_step_deviation / tau),
      (printed_resolution_s > 0
           ? fmt::format("uniform sampling (times within the printed resolution {:g} s of a "
                         "uniform grid)",
                         printed_resolution_s)
           : fmt::format("uniform sampling (relative deviation under {:g})",
                         kTimeUniformityTolerance)) +
          // Scattered less than a quarter step about a straight line: stamps with jitter.
          (b > 0 && worst_from_line < 0.25 * b
               ? "; for a logger that samples at a fixed rate and stamps with jitter, its "
                 "rate (sample_rate_hz in the record entry, --sample-rate-hz)"
               : ""));
}

}  // namespace mbid
