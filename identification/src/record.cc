#include "record.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "internal.h"
#include "mbid/common/error.h"
#include "mbid/identification/spectrum.h"
#include "methods/method.h"

namespace mbid::identification {
namespace {

constexpr char kOptionsSource[] = "identification options";
// Half-length of the decimation filter in output samples. A Blackman-windowed sinc of
// 2 * 20 q + 1 taps with its cutoff at 0.9 of the new Nyquist frequency is flat up to 0.76 of it
// and below -74 dB from 1.04 of it: aliasing reaches only the top 4 % of the new band, and the
// noise stays white over most of it (a shorter filter colours the noise enough for the Hankel
// noise floor to let noise poles through).
constexpr int kFilterHalfLength = 20;

std::string JoinNames(const std::vector<std::string>& names) {
  std::string joined;
  for (const auto& name : names) joined += (joined.empty() ? "" : ", ") + name;
  return joined;
}

// Zero-phase low-pass FIR (cutoff 0.9 of the new Nyquist, Blackman window, unit DC gain) and
// downsampling by q, in "valid" mode: output n is centred on input n q + H.
Eigen::MatrixXd Decimate(const Eigen::MatrixXd& values, int q) {
  if (q == 1) return values;
  const int half = kFilterHalfLength * q;
  const double cutoff = 0.9 * 0.5 / q;  // cycles per input sample
  Eigen::VectorXd taps(2 * half + 1);
  for (int i = -half; i <= half; ++i) {
    const double x = 2 * cutoff * i;
    const double sinc = i == 0 ? 1.0 : std::sin(M_PI * x) / (M_PI * x);
    const double phase = M_PI * (i + half) / half;  // 0..2 pi over the filter
    const double blackman = 0.42 - 0.5 * std::cos(phase) + 0.08 * std::cos(2 * phase);
    taps(i + half) = sinc * blackman;
  }
  taps /= taps.sum();
  const int samples = static_cast<int>(values.rows());
  const int outputs = samples > 2 * half ? (samples - 1 - 2 * half) / q + 1 : 0;
  Eigen::MatrixXd decimated(outputs, values.cols());
  for (Eigen::Index c = 0; c < values.cols(); ++c) {
    for (int n = 0; n < outputs; ++n) {
      decimated(n, c) = taps.dot(values.col(c).segment(n * q, 2 * half + 1));
    }
  }
  return decimated;
}

// The decimation filter is flat to this fraction of the new Nyquist frequency (see above).
constexpr double kFlatFraction = 0.76;

}  // namespace

int ChooseDecimation(const Eigen::MatrixXd& centered, double sample_interval_s,
                     double max_frequency_hz) {
  const Eigen::Index samples = centered.rows();
  // Decimating fewer than 2000 samples would leave under 1000: not worth the filter's edges.
  if (samples < 2000) return 1;
  double band_hz = max_frequency_hz;
  if (band_hz <= 0) {
    SpectrumOptions options;
    options.zero_padding_factor = 1;  // the floor and the top, not fine peak positions
    options.min_peak_prominence = 1;  // no peak list needed
    double top_hz = 0;
    // A fast-decaying high mode is gone from most of a long record and sinks into the whole
    // record's noise floor; the record's beginning shows it. So the top is the highest over the
    // first 2048, 16384, ... samples and the whole.
    for (Eigen::Index length = 2048;; length *= 8) {
      const Eigen::Index used = std::min(length, samples);
      const Spectrum spectrum = CalcSpectrum(centered.topRows(used), sample_interval_s, options);
      for (Eigen::Index c = 0; c < spectrum.amplitude.cols(); ++c) {
        const Eigen::VectorXd amplitude = spectrum.amplitude.col(c);
        std::vector<double> sorted(amplitude.data(), amplitude.data() + amplitude.size());
        std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
        // White noise's Hann spectrum is Rayleigh distributed: 10x its median is 12 standard
        // deviations, which no noise bin reaches (probability e^-69 per bin).
        const double floor = sorted[sorted.size() / 2];
        for (Eigen::Index b = amplitude.size() - 1; b > 0; --b) {
          if (amplitude(b) > 10 * floor) {
            top_hz = std::max(top_hz, spectrum.frequency_hz(b));
            break;
          }
        }
      }
      if (used == samples) break;
    }
    if (top_hz <= 0) return 1;
    band_hz = 1.25 * top_hz;
  }
  return DecimationForBand(band_hz, sample_interval_s, samples);
}

int DecimationForBand(double band_hz, double sample_interval_s, Eigen::Index samples) {
  const double nyquist_hz = 0.5 / sample_interval_s;
  const int by_band = static_cast<int>(std::floor(kFlatFraction * nyquist_hz / band_hz));
  const int by_length = static_cast<int>(samples / 500);
  return std::max(1, std::min(by_band, by_length));
}

int RequiredSamples(const IdentificationOptions& options, int channels) {
  return FindMethod(options.method.name())->required_samples(options, channels);
}

WindowRows FindWindowRows(const Measurement& measurement, const IdentificationOptions& options) {
  const double tau = measurement.sample_interval_s;
  const double t0 = measurement.start_time_s;
  WindowRows window;
  window.last = measurement.samples() - 1;
  while (window.first < measurement.samples() &&
         t0 + window.first * tau < options.window_start_s - 0.5 * tau) {
    ++window.first;
  }
  while (window.last >= window.first && t0 + window.last * tau > options.window_end_s + 0.5 * tau) {
    --window.last;
  }
  return window;
}

AnalysisRecord PrepareRecord(const Measurement& measurement, const IdentificationOptions& options,
                             const std::string& origin) {
  const double tau = measurement.sample_interval_s;
  if (!(std::isfinite(tau) && tau > 0)) {
    throw InputError(origin, "sample_interval_s", fmt::format("{} s", tau),
                     "a positive finite sample interval");
  }
  if (measurement.values.cols() != static_cast<Eigen::Index>(measurement.channels.size())) {
    throw InputError(origin, "channels",
                     fmt::format("{} names for {} columns", measurement.channels.size(),
                                 measurement.values.cols()),
                     "one name per channel");
  }

  // Channel selection.
  std::vector<int> columns;
  const std::vector<std::string>& wanted =
      options.channels.empty() ? measurement.channels : options.channels;
  AnalysisRecord record;
  for (const std::string& name : wanted) {
    const int column = measurement.FindChannel(name);
    if (column < 0) {
      throw InputError(origin, "channels", fmt::format("no channel '{}' in the record", name),
                       "one of " + JoinNames(measurement.channels));
    }
    if (std::find(columns.begin(), columns.end(), column) != columns.end()) {
      throw InputError(kOptionsSource, "channels", fmt::format("'{}' is selected twice", name),
                       "each channel at most once");
    }
    columns.push_back(column);
    record.channels.push_back(name);
    record.units.push_back(
        column < static_cast<int>(measurement.units.size()) ? measurement.units[column] : "");
  }
  if (columns.empty()) {
    throw InputError(origin, "channels", "the record has no channels", "at least one channel");
  }

  const double t0 = measurement.start_time_s;
  const WindowRows window = FindWindowRows(measurement, options);
  const int first = window.first;
  const int count = window.count();
  record.sample_interval_s = tau;
  record.start_time_s = t0 + first * tau;
  // The window's channels as recorded (checked below, after the sample count).
  record.values.resize(std::max(count, 0), static_cast<Eigen::Index>(columns.size()));
  for (size_t c = 0; c < columns.size(); ++c) {
    record.values.col(c) = measurement.values.col(columns[c]).segment(first, record.values.rows());
  }
  int q = options.decimation;
  if (q == 0) {
    // Chosen with the offset removed (a constant dominates the lowest bin only).
    q = count > 0 && record.values.allFinite()
            ? ChooseDecimation(record.values.rowwise() - record.values.colwise().mean(), tau,
                               options.max_frequency_hz)
            : 1;
  }
  record.decimation = q;
  const int required = RequiredSamples(options, static_cast<int>(columns.size()));
  const int decimated_count =
      count > 2 * kFilterHalfLength * q ? (count - 1 - 2 * kFilterHalfLength * q) / q + 1 : 0;
  const int available = q == 1 ? count : decimated_count;
  if (available < required) {
    const std::string order =
        FindMethod(options.method.name())->requirement(options, static_cast<int>(columns.size()));
    throw InputError(
        origin, "samples",
        fmt::format("{} samples {}{}", std::max(count, 0),
                    count > 0 ? fmt::format("from {:.6g} s to {:.6g} s", t0 + first * tau,
                                            t0 + window.last * tau)
                              : fmt::format("in the window from {:.6g} s", options.window_start_s),
                    q == 1 ? "" : fmt::format(", {} after decimation by {}", available, q)),
        fmt::format("at least {} for {}", required, order));
  }

  for (size_t c = 0; c < columns.size(); ++c) {
    const auto column = record.values.col(c);
    for (int j = 0; j < count; ++j) {
      if (!std::isfinite(column(j))) {
        throw InputError(
            origin, record.channels[c],
            fmt::format("sample {} (t = {} s) is {}", first + j, t0 + (first + j) * tau,
                        std::isnan(column(j)) ? "NaN" : "infinite"),
            "finite values");
      }
    }
    if (column.maxCoeff() == column.minCoeff()) {
      throw InputError(origin, record.channels[c],
                       column(0) == 0
                           ? std::string("every sample in the window is zero")
                           : fmt::format("constant: every sample in the window is {} {}", column(0),
                                         c < record.units.size() ? record.units[c] : ""),
                       "a record that varies (a free decay)");
    }
  }

  // Band against the Nyquist frequency of the record the poles are estimated on.
  record.decimated_interval_s = tau * q;
  const double nyquist_hz = 0.5 / record.decimated_interval_s;
  record.flat_frequency_hz = q == 1 ? nyquist_hz : kFlatFraction * nyquist_hz;
  record.max_frequency_hz = options.max_frequency_hz == 0 ? nyquist_hz : options.max_frequency_hz;
  if (record.max_frequency_hz > nyquist_hz) {
    throw InputError(origin, "max_frequency_hz",
                     fmt::format("{} Hz is above the Nyquist frequency {} Hz of the record "
                                 "(sample interval {} s, decimation {})",
                                 options.max_frequency_hz, nyquist_hz, tau, q),
                     fmt::format("at most {} Hz, or a higher sample rate", nyquist_hz));
  }
  if (options.min_frequency_hz >= nyquist_hz) {
    throw InputError(origin, "min_frequency_hz",
                     fmt::format("{} Hz is not below the Nyquist frequency {} Hz of the record",
                                 options.min_frequency_hz, nyquist_hz),
                     fmt::format("below {} Hz", nyquist_hz));
  }

  record.mean = options.offset == OffsetRemoval::kNone
                    ? Eigen::VectorXd::Zero(record.values.cols())
                    : Eigen::VectorXd(record.values.colwise().mean().transpose());
  record.centered = record.values.rowwise() - record.mean.transpose();
  record.decimated = Decimate(record.centered, q);
  // "Valid" filtering: output n is centred on input n q + H.
  record.decimated_start_time_s = record.start_time_s + (q == 1 ? 0 : kFilterHalfLength * q) * tau;
  return record;
}

}  // namespace mbid::identification
