// The time base of a record read from a file: its time column (or stated rate) to a start and
// a sample interval in s, with the doubts a column without a unit leaves (docs/records.md).
#include "time_base.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <vector>

#include "mbid/common/error.h"
#include "units.h"

namespace mbid::records::internal {
namespace {

// How round a sample rate is: its trailing decimal zeros first, then a power of two before them
// (2048, 25600 and 51200 Hz are as common on loggers as 1000 and 3000).
int Roundness(long rate) {
  int zeros = 0;
  while (rate % 10 == 0) {
    rate /= 10;
    ++zeros;
  }
  const bool power_of_two = (rate & (rate - 1)) == 0;
  return 2 * zeros + (power_of_two ? 1 : 0);
}

// The integer rate an interval printed to `resolution` (the place value of its last digit)
// most likely rounds from: the roundest one whose interval prints the same, the nearest among
// equally round ones; none when the print is exact to 1e-9 or no round rate fits.
std::optional<double> RoundRate(double interval_s, double resolution_s) {
  if (!(resolution_s > 1e-9 * interval_s) || !(interval_s > 0.5 * resolution_s)) {
    return std::nullopt;
  }
  const double low = 1 / (interval_s + 0.5 * resolution_s);
  const double high = 1 / (interval_s - 0.5 * resolution_s);
  if (!(high - low < 1e6)) return std::nullopt;
  std::optional<long> best;
  for (long rate = static_cast<long>(std::ceil(low)); rate <= static_cast<long>(std::floor(high));
       ++rate) {
    if (rate <= 0) continue;
    if (!best || Roundness(rate) > Roundness(*best) ||
        (Roundness(rate) == Roundness(*best) &&
         std::abs(1.0 / rate - interval_s) < std::abs(1.0 / *best - interval_s))) {
      best = rate;
    }
  }
  if (!best || Roundness(*best) == 0) return std::nullopt;
  return static_cast<double>(*best);
}

// Time stamps that jitter around the stated grid, offsets t_j - j tau: read at the stated rate.
// Their own rate (the least-squares slope) differs from it by what the two clocks disagree,
// which is the time base's uncertainty whichever clock is right.
void JitteredStamps(const Eigen::ArrayXd& offset, double tau, double rate_hz, Measurement* m,
                    ImportReport* report) {
  const Eigen::Index n = offset.size();
  const Eigen::ArrayXd j = Eigen::ArrayXd::LinSpaced(n, 0, static_cast<double>(n - 1));
  const Eigen::ArrayXd dj = j - j.mean();
  const double slope = (dj * (offset - offset.mean())).sum() / dj.square().sum();
  const Eigen::ArrayXd residual = offset - offset.mean() - slope * dj;
  const double scatter = std::sqrt(residual.square().sum() / static_cast<double>(n - 2));
  const double slope_std = scatter / std::sqrt(dj.square().sum());
  m->start_time_s = offset.mean();
  m->sample_interval_s = tau;
  const double jitter = residual.abs().maxCoeff();
  std::string drift;
  if (std::abs(slope) > 4 * slope_std) {
    m->sample_interval_uncertainty =
        std::max(m->sample_interval_uncertainty, (std::abs(slope) + slope_std) / tau);
    drift = fmt::format(
        "; their own rate is {:.9g} Hz, {:.2g} ppm off the stated one, which "
        "every frequency's and decay's standard deviation carries",
        1 / (tau + slope), 1e6 * std::abs(slope) / tau);
  }
  // Not a warning (which makes an identification unreliable): a jitter of the sampling itself
  // would show in the identification's residual, which is judged there.
  report->conversions.push_back(fmt::format(
      "time: samples at j / {} Hz, the stamps scattered by up to {:.3g} s ({:.2g} % of the "
      "interval) around that grid, as a logger that stamps its blocks with jitter writes them{}",
      rate_hz, jitter, 100 * jitter / tau, drift));
}

// Sets the measurement's start time and interval from the file's time base (in seconds).
// A time column printed to `resolution` with a rate the user states: every time must lie within
// that resolution of one grid j / rate (the spread of t_j - j / rate is under one place value
// when each time is rounded or truncated), so that a dropped sample is found even where the
// column alone could not tell it from a clock off its rate (CheckUniformTime).
void StatedRateGrid(const Eigen::VectorXd& time, const std::string& path, const RawTable& table,
                    double rate_hz, double resolution, Measurement* m, ImportReport* report) {
  const double tau = 1.0 / rate_hz;
  const Eigen::ArrayXd offset =
      time.array() - tau * Eigen::ArrayXd::LinSpaced(time.size(), 0, time.size() - 1);
  const double low = offset.minCoeff(), high = offset.maxCoeff();
  const double tolerance = 1e-6 * resolution + 1e-12 * time.cwiseAbs().maxCoeff();  // the parse
  // Samples at the bottom and top of the spread; where the spread is the whole place value, the
  // times are rounding ties, which interleave along a grid, while a dropped (repeated) sample
  // puts all of one side before the other.
  Eigen::Index first_low = -1, last_low = -1, first_high = -1, last_high = -1;
  for (Eigen::Index j = 0; j < offset.size(); ++j) {
    if (offset[j] <= low + tolerance) {
      if (first_low < 0) first_low = j;
      last_low = j;
    }
    if (offset[j] >= high - tolerance) {
      if (first_high < 0) first_high = j;
      last_high = j;
    }
  }
  const bool beyond = high - low > resolution + tolerance;
  if (beyond && time.size() > 2) {
    // Another rate, not a dropped sample: the times lie on a grid of their own (a straight
    // offset within the resolution), whose step is not the stated one. Named at the first
    // sample off the stated grid, with the rate the column shows (it was named at the last
    // sample, as "a dropped or repeated sample").
    const Eigen::Index n = time.size();
    const double step = (time[n - 1] - time[0]) / static_cast<double>(n - 1);
    const Eigen::ArrayXd own =
        time.array() - time[0] - step * Eigen::ArrayXd::LinSpaced(n, 0, static_cast<double>(n - 1));
    if (own.maxCoeff() - own.minCoeff() <= resolution + tolerance) {
      Eigen::Index j = 1;
      while (j < n && std::abs(offset[j] - offset[0]) <= resolution + tolerance) ++j;
      throw InputError(path, SampleField(table, "", std::min(j, n - 1)),
                       fmt::format("the time column steps {:.6g} s ({:.6g} Hz), not the stated "
                                   "{} Hz",
                                   step, 1 / step, rate_hz),
                       "the rate the time column shows, or no stated rate (the time column "
                       "gives it)");
    }
  }
  const bool ties = high - low >= resolution - tolerance;
  const bool apart = last_low < first_high || last_high < first_low;
  // Stamps that scatter by less than half an interval around the grid are a logger's stamping
  // jitter (a PC clock read per block): a dropped or repeated sample moves the offsets by a whole
  // interval, which this spread cannot hold.
  if (beyond && high - low < 0.5 * tau && time.size() > 2) {
    JitteredStamps(offset, tau, rate_hz, m, report);
    return;
  }
  if (beyond && time.size() > 2) {
    // A column whose mean step is not the stated one by far more than any jitter or dropped
    // sample moves it (200 Hz stamps read at a stated 100 Hz were "off the grid by 10 s").
    const double step = (time[time.size() - 1] - time[0]) / static_cast<double>(time.size() - 1);
    if (std::abs(step - tau) > 0.01 * tau) {
      throw InputError(path, table.time_where.empty() ? "sample_rate_hz" : table.time_where,
                       fmt::format("the time column steps {:.6g} s ({:.6g} Hz) on average, not "
                                   "the stated {} Hz",
                                   step, 1 / step, rate_hz),
                       "the rate the time column shows, or no stated rate (the time column "
                       "gives it)");
    }
  }
  if (beyond || (ties && apart)) {
    const Eigen::Index j = last_low < first_high   ? first_high
                           : last_high < first_low ? first_low
                                                   : std::max(first_high, first_low);
    throw InputError(path, SampleField(table, "", j),
                     fmt::format("the time column spreads over {1:.3g} s around the grid of the "
                                 "stated {0} Hz from sample {2} on (a dropped or repeated sample, "
                                 "or another rate?)",
                                 rate_hz, high - low, j),
                     fmt::format("times within their printed resolution {:g} s of j / {} Hz, or "
                                 "stamps that scatter within a band narrower than half an "
                                 "interval around it",
                                 resolution, rate_hz));
  }
  m->start_time_s = offset.mean();
  m->sample_interval_s = tau;
  report->conversions.push_back(
      fmt::format("time: samples at j / {} Hz (the time column agrees within its printed "
                  "resolution {:g} s)",
                  rate_hz, resolution));
}

}  // namespace

// A time without a unit read in s whose step is under 0.1 s (10 Hz; slower steps are said in
// ReadTimeBase) may still count ms of a logger of 10-50 kHz: every frequency then comes out
// 1000 times too low, reliable (a trial's 12.8-20 kHz records: 1.2 and 6.5 Hz as 0.0012 and
// 0.0065 Hz). Such a record swings slowly for the time it states: where every channel that
// swings (four reversals beyond a tenth of its range) has periods over 22 s (0.045 Hz, below any
// machine's structure; a 100 m rope's pendulum is 0.05 Hz), it is said (the median spacing of
// the reversals: a long record's rest around a short decay does not count). A 40 Hz mode of a
// 25.6 kHz ms clock reads as 0.04 Hz, 640 samples per period (a first rule of 1000 missed it).
void SayIfOversampled(const Measurement& m, ImportReport* report) {
  constexpr double kLongestPeriodS = 22;
  constexpr double kSamplesPerReversal = 100;  // the fewest to judge a period by
  // Steps of 0.02-0.1 "s": a ms clock of 10-50 kHz. A finer step read in s is a fast logger in
  // s (2 kHz: the crane's 1.5 Hz mode swings over 1333 samples) or a ms clock faster than any.
  if (!report->time_unit_assumed || m.samples() < 4 * kSamplesPerReversal ||
      m.sample_interval_s * (1 + kTimeUniformityTolerance) >= 0.1 ||
      m.sample_interval_s * (1 + kTimeUniformityTolerance) < 0.02) {
    return;
  }
  double fastest = std::numeric_limits<double>::infinity();  // fewest samples per reversal
  for (Eigen::Index c = 0; c < m.values.cols(); ++c) {
    const auto column = m.values.col(c);
    const double h = 0.1 * (column.maxCoeff() - column.minCoeff());
    if (!(h > 0)) continue;
    // Where each reversal happens (at its extreme): the median spacing is the swing's half
    // period, whatever the record holds besides (a long rest, a decay into the noise).
    std::vector<double> spacing;
    int direction = 0;
    Eigen::Index at = 0, last = -1;
    for (Eigen::Index j = 1; j < column.size(); ++j) {
      const double v = column(j);
      if (direction == 0) {
        if (std::abs(v - column(at)) > h) direction = v > column(at) ? 1 : -1;
        if (direction != 0) at = j;
      } else if ((v - column(at)) * direction > 0) {
        at = j;
      } else if (std::abs(v - column(at)) > h) {
        if (last >= 0) spacing.push_back(static_cast<double>(at - last));
        last = at;
        direction = -direction;
        at = j;
      }
    }
    if (spacing.size() < 3) continue;  // four reversals: two periods
    std::nth_element(spacing.begin(), spacing.begin() + spacing.size() / 2, spacing.end());
    fastest = std::min(fastest, spacing[spacing.size() / 2]);
  }
  if (std::isinf(fastest) || !(2 * fastest * m.sample_interval_s > kLongestPeriodS)) return;
  const double seconds = 2 * fastest * m.sample_interval_s;
  report->warnings.push_back(fmt::format(
      "the time states no unit and is read in s (a step of {:g} s, {:.3g} Hz), and the record "
      "swings over {:.0f} samples per period, {:.3g} s: if the time counts ms (a logger at {:.3g} "
      "kHz), every frequency is 1000 times too low; give `time_unit: ms` in the scenario's "
      "record entry (or --time-unit ms), or `time_unit: s` if the periods are right",
      m.sample_interval_s, 1 / m.sample_interval_s, 2 * fastest, seconds, 1 / m.sample_interval_s));
}

void ReadTimeBase(const RawTable& table, const std::string& path, const ImportOptions& options,
                  const std::string& user_time_unit, Measurement* m, ImportReport* report) {
  if (table.time.empty() && table.interval <= 0) {
    if (!(options.sample_rate_hz > 0) || !std::isfinite(options.sample_rate_hz)) {
      throw InputError(path, table.sample_lines.empty() ? "" : "header",
                       "no time column (named time, t, Zeit, timestamp, datetime or X_Value)",
                       "a time column, or the sample rate of a file without one "
                       "(`sample_rate_hz:` in the scenario's record entry or --sample-rate-hz)");
    }
    m->start_time_s = 0.0;
    m->sample_interval_s = 1.0 / options.sample_rate_hz;
    report->conversions.push_back(
        fmt::format("time: samples at j / {} Hz (no time column)", options.sample_rate_hz));
    return;
  }
  std::string unit = user_time_unit.empty() ? table.time_unit : user_time_unit;
  // mbid's contract: a column named `time` without a unit is in seconds.
  const bool seconds_by_contract =
      unit.empty() && (table.time_name == "time" || table.si_by_contract);
  if (seconds_by_contract) unit = "s";
  // A logger's `time` in ms read as s makes every frequency 1000 times too low: a step of
  // 0.1 s or more (10 Hz or slower, where a ms clock of 10 kHz or slower lands) is said.
  // A format whose time has no unit in the file (MAT, LVM without X_Unit_Label) is read in s.
  const bool format_default = user_time_unit.empty() && table.time_unit_assumed;
  report->time_unit_assumed = seconds_by_contract || format_default;
  const auto say_if_slow = [&] {
    // (0.1 itself: a fitted step of 0.09999999999999999 s is 0.1 s.)
    if (!(seconds_by_contract || format_default) ||
        !(m->sample_interval_s * (1 + kTimeUniformityTolerance) >= 0.1)) {
      return;
    }
    if (format_default) {
      report->warnings.push_back(fmt::format(
          "the file's time ({}) states no unit and is read in s, as the {} format's readers "
          "assume: a step of {:g} s ({:.3g} Hz); if it is in ms, give `time_unit: ms` in the "
          "scenario's record entry (or --time-unit ms)",
          table.time_where.empty() ? "the sample interval" : table.time_where, table.format,
          m->sample_interval_s, 1 / m->sample_interval_s));
      return;
    }
    report->warnings.push_back(fmt::format(
        "the time column '{}' has no unit and is read in s, as mbid's contract says: a step of "
        "{:g} s ({:.3g} Hz); if it is in ms, write '{} [ms]' or '{}_ms', or `time_unit: ms` in "
        "the scenario's record entry",
        table.time_name, m->sample_interval_s, 1 / m->sample_interval_s, table.time_name,
        table.time_name));
  };
  const std::string field =
      table.time_name.empty() ? table.time_where
                              : DescribeColumn({table.time_name, "", table.time_where, {}, {}, {}});
  if (unit.empty()) {
    throw InputError(path, field, fmt::format("the time column '{}' has no unit", table.time_name),
                     fmt::format("a unit: a header '{0} [ms]' or '{0}_ms', a units row, or "
                                 "`time_unit: ms` in the scenario's record entry",
                                 table.time_name));
  }
  const internal::UnitConversion to_s = internal::FindConversion(unit, "s", path, field);
  if (!to_s.identity()) {
    report->conversions.push_back(fmt::format("time: {} -> s (x {:g})", unit, to_s.scale));
  }
  if (table.time.empty()) {
    m->start_time_s = to_s.scale * table.start + to_s.offset;
    m->sample_interval_s = to_s.scale * table.interval;
    const double resolution = to_s.scale * table.interval_resolution;
    if (options.sample_rate_hz > 0) {
      // A stated rate wins where the printed interval allows it.
      if (!(std::abs(1 / options.sample_rate_hz - m->sample_interval_s) <=
            std::max(0.5 * resolution, kTimeUniformityTolerance * m->sample_interval_s))) {
        throw InputError(path, "sample_rate_hz",
                         fmt::format("{} Hz disagrees with the file's sample interval {} {}",
                                     options.sample_rate_hz, table.interval, unit),
                         "no sample rate, or the rate of the file's interval");
      }
      m->sample_interval_s = 1 / options.sample_rate_hz;
    } else {
      // The print bounds the interval, not the rate the logger ran at (51200 / 30 = 1706.67 Hz
      // prints as 0.000586, 51200 / 24 as 0.000469, which the roundest rate reads as 2130 Hz):
      // every reading within those bounds is a guess, unless the print is exactly a whole rate's.
      const double printed = m->sample_interval_s;
      if (const std::optional<double> rate = RoundRate(printed, resolution)) {
        report->conversions.push_back(fmt::format(
            "time: the sample interval {} {} is printed to {:.2g} % (the rate to {:.4g} Hz): read "
            "as 1/{} s, the round rate it rounds from (sample_rate_hz sets another)",
            table.interval, unit, 50 * resolution / printed, 0.5 * resolution / (printed * printed),
            *rate));
        m->sample_interval_s = 1 / *rate;
      }
      // The reading's farthest distance to the printed bounds (the round rate may sit near one).
      const double printed_rate = 1 / printed;
      if (resolution > 0 &&
          !(std::abs(printed_rate - std::round(printed_rate)) < 1e-9 * printed_rate)) {
        const double tau = m->sample_interval_s;
        m->sample_interval_uncertainty =
            std::max(tau - (printed - 0.5 * resolution), printed + 0.5 * resolution - tau) / tau;
      }
    }
    say_if_slow();
    return;
  }
  // Counted from the first stamp before the unit's factor: epoch stamps in ms (1.77e12) scaled
  // to s first keep steps only to 2.4e-7 s, and a logger's exact 1 ms read as 1.00017 ms (refused
  // as a dropped sample). The origin is added back to the start.
  const double origin = table.time.empty() ? 0.0 : table.time.front();
  const double origin_s = to_s.identity() ? origin : to_s.scale * origin + to_s.offset;
  // Epoch seconds printed to 0.01 s (1.77e9) parse to doubles 2.4e-7 s apart: counted from the
  // first, they are put back on the printed digit's grid, which they were printed on.
  const double printed = table.printed_resolution;
  const bool snap =
      printed > 0 && std::abs(origin) * std::numeric_limits<double>::epsilon() > 1e-6 * printed;
  Eigen::VectorXd time(static_cast<Eigen::Index>(table.time.size()));
  for (size_t j = 0; j < table.time.size(); ++j) {
    double since = table.time[j] - origin;
    if (snap) since = std::round(since / printed) * printed;
    time[static_cast<Eigen::Index>(j)] = to_s.identity() ? since : to_s.scale * since;
  }
  if (options.sample_rate_hz > 0 && table.printed_resolution > 0 &&
      (time.array().isFinite().all()) && time.size() > 1 &&
      // Non-decreasing: at 2 kHz a time printed to 1 ms repeats every other value.
      ((time.tail(time.size() - 1) - time.head(time.size() - 1)).array() >= 0).all()) {
    StatedRateGrid(time, path, table, options.sample_rate_hz, table.printed_resolution * to_s.scale,
                   m, report);
    m->start_time_s += origin_s;
    return;
  }
  double start = 0;
  const double tau = CheckUniformTime(
      time, path, [&](Eigen::Index j) { return SampleField(table, "", j); },
      table.printed_resolution * to_s.scale, &start);
  m->start_time_s = origin_s + start;
  m->sample_interval_s = tau;
  if (table.stated_interval_s > 0) {
    // The exact interval, when it agrees with the time column, makes mbid's round trip exact.
    if (!(std::abs(table.stated_interval_s - tau) < kTimeUniformityTolerance * tau)) {
      throw InputError(path, table.stated_interval_where,
                       fmt::format("'# sample_interval_s: {}' disagrees with the time column "
                                   "(step {} s)",
                                   table.stated_interval_s, tau),
                       "the step of the time column");
    }
    m->sample_interval_s = table.stated_interval_s;
  }
  if (options.sample_rate_hz > 0 &&
      !(std::abs(options.sample_rate_hz * tau - 1.0) < kTimeUniformityTolerance)) {
    throw InputError(path, "sample_rate_hz",
                     fmt::format("{} Hz disagrees with the time column (step {} s)",
                                 options.sample_rate_hz, tau),
                     "no sample rate for files with a time column, or the rate of that column");
  }
  say_if_slow();
}

}  // namespace mbid::records::internal
