#include "mbid/identification/hilbert_backbone.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <unsupported/Eigen/FFT>
#include <vector>

namespace mbid::identification {
namespace {

// The band-pass's gain (of the real signal's positive frequencies) at `f` for a mode at `f0`:
// 1 from 0.6 to 1.4 f0, raised-cosine edges to 0 at 0.4 and 1.6 f0.
double BandGain(double f, double f0) {
  const double x = f / f0;
  if (x <= 0.4 || x >= 1.6) return 0;
  if (x >= 0.6 && x <= 1.4) return 1;
  const double edge = x < 0.6 ? (x - 0.4) / 0.2 : (1.6 - x) / 0.2;  // 0 .. 1 into the band
  return 0.5 * (1 - std::cos(M_PI * edge));
}

// Least-squares line y = c + s t over t centred on its mean: the slope, its standard deviation
// and the value at the centre. The variance per sample is the larger of the residuals' and
// `noise_variance` (what the band's noise alone gives), counted `correlation` times (the samples
// per independent one): a window holds only a few independent samples, too few for its residuals
// alone.
struct Line {
  double centre_value = 0, slope = 0, std_slope = 0;
};

Line FitLine(const std::vector<double>& y, int first, int count, double tau, double correlation,
             double noise_variance) {
  const double mid = 0.5 * (count - 1);
  double sy = 0, sty = 0, stt = 0;
  for (int i = 0; i < count; ++i) {
    const double t = (i - mid) * tau;
    sy += y[static_cast<size_t>(first + i)];
    sty += t * y[static_cast<size_t>(first + i)];
    stt += t * t;
  }
  Line line;
  line.centre_value = sy / count;
  line.slope = sty / stt;
  double residual = 0;
  for (int i = 0; i < count; ++i) {
    const double t = (i - mid) * tau;
    residual += std::pow(y[static_cast<size_t>(first + i)] - line.centre_value - line.slope * t, 2);
  }
  const double variance = std::max(residual / std::max(1, count - 2), noise_variance);
  line.std_slope = std::sqrt(variance * correlation / stt);
  return line;
}

}  // namespace

BackboneCurve CalcHilbertBackbone(const Eigen::VectorXd& mode_alone, double sample_interval_s,
                                  double start_time_s, double frequency_hz, double noise_std) {
  BackboneCurve curve;
  const double tau = sample_interval_s;
  const int n = static_cast<int>(mode_alone.size());
  const double period_s = 1 / frequency_hz;
  const int window = std::max(16, static_cast<int>(std::lround(4 * period_s / tau)));
  const int edge = static_cast<int>(std::lround(3 * period_s / tau));
  if (n < window + 2 * edge || !(frequency_hz > 0)) return curve;

  // The analytic signal of the band: twice the positive frequencies in the band, nothing else.
  int nfft = 1;
  while (nfft < 2 * n) nfft *= 2;
  std::vector<double> input(static_cast<size_t>(nfft), 0.0);
  for (int j = 0; j < n; ++j) input[static_cast<size_t>(j)] = mode_alone[j];
  Eigen::FFT<double> fft;
  std::vector<std::complex<double>> spectrum;
  fft.fwd(spectrum, input);
  const double df = 1 / (nfft * tau);
  double gain_squares = 0;  // sum over bins of the analytic band's squared gain
  for (int k = 0; k < nfft; ++k) {
    const double gain = k > 0 && 2 * k < nfft ? 2 * BandGain(k * df, frequency_hz) : 0.0;
    spectrum[static_cast<size_t>(k)] *= gain;
    gain_squares += gain * gain;
  }
  std::vector<std::complex<double>> analytic;
  fft.inv(analytic, spectrum);  // scaled by 1 / nfft

  // White noise of variance s^2 gives the analytic band s^2 sum_k G_k^2 / nfft per sample.
  const double noise_variance = noise_std * noise_std * gain_squares / nfft;
  const double noise_level = std::sqrt(noise_variance);
  // The band's equivalent bandwidth (Hz): independent complex samples per second.
  const double bandwidth_hz = 0.25 * gain_squares * df;
  const double correlation = std::max(1.0, 1 / (bandwidth_hz * tau));

  std::vector<double> phase(static_cast<size_t>(n)), log_amplitude(static_cast<size_t>(n));
  std::vector<double> amplitude(static_cast<size_t>(n));
  for (int j = 0; j < n; ++j) {
    const std::complex<double> z = analytic[static_cast<size_t>(j)];
    amplitude[static_cast<size_t>(j)] = std::abs(z);
    log_amplitude[static_cast<size_t>(j)] = std::log(std::max(std::abs(z), 1e-300));
    phase[static_cast<size_t>(j)] = std::arg(z);
    if (j > 0) {
      // Unwrapped: the step from the sample before, brought into (-pi, pi].
      const double step = phase[static_cast<size_t>(j)] - phase[static_cast<size_t>(j - 1)];
      phase[static_cast<size_t>(j)] =
          phase[static_cast<size_t>(j - 1)] + std::remainder(step, 2 * M_PI);
    }
  }

  for (int first = edge; first + window <= n - edge; first += window / 2) {
    const double lowest =
        *std::min_element(amplitude.begin() + first, amplitude.begin() + first + window);
    if (!(lowest > 10 * noise_level)) break;  // the mode sinks into the noise from here on
    // Complex noise of variance s^2 on z = a e^{i phi} moves phi and ln a each by s^2 / (2 a^2).
    double inverse_square = 0;
    for (int j = first; j < first + window; ++j) {
      inverse_square += 1 / std::pow(amplitude[static_cast<size_t>(j)], 2);
    }
    const double per_sample = 0.5 * noise_variance * inverse_square / window;
    const Line phase_line = FitLine(phase, first, window, tau, correlation, per_sample);
    const Line amplitude_line = FitLine(log_amplitude, first, window, tau, correlation, per_sample);
    const double omega = phase_line.slope;
    const double decay = -amplitude_line.slope;
    if (!(omega > 0)) continue;
    const double magnitude = std::hypot(omega, decay);
    curve.time_s.push_back(start_time_s + (first + 0.5 * (window - 1)) * tau);
    curve.amplitude.push_back(std::exp(amplitude_line.centre_value));
    curve.frequency_hz.push_back(omega / (2 * M_PI));
    curve.std_frequency_hz.push_back(phase_line.std_slope / (2 * M_PI));
    curve.damping_ratio.push_back(decay / magnitude);
    curve.std_damping_ratio.push_back(amplitude_line.std_slope / magnitude);
  }
  return curve;
}

}  // namespace mbid::identification
