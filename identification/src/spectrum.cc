#include "mbid/identification/spectrum.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <unsupported/Eigen/FFT>

namespace mbid::identification {
namespace {

int NextPowerOfTwo(long long n) {
  int power = 1;
  while (power < n) power *= 2;
  return power;
}

}  // namespace

namespace {

// For each sample, the lowest value between it and the nearest strictly higher sample towards
// the start (or the start itself), itself included: one pass with a stack of ever higher
// samples, each carrying the lowest value since the previous one. Every sample is pushed and
// popped once, so the pass is O(n) where walking from each maximum was O(n^2) on the many small
// side lobes of a clean spectrum.
template <typename At>
std::vector<double> CalcLowestTowardsStart(int n, At at) {
  struct Entry {
    double height;
    double lowest;  // since the entry below it on the stack (exclusive), itself included
  };
  std::vector<Entry> stack;
  std::vector<double> lowest(static_cast<size_t>(n));
  for (int j = 0; j < n; ++j) {
    const double height = at(j);
    double low = height;
    while (!stack.empty() && stack.back().height <= height) {
      low = std::min(low, stack.back().lowest);
      stack.pop_back();
    }
    lowest[static_cast<size_t>(j)] = low;
    stack.push_back({height, low});
  }
  return lowest;
}

}  // namespace

std::vector<int> FindPeaks(const Eigen::VectorXd& amplitude, double min_relative_prominence,
                           std::vector<double>* prominence) {
  std::vector<int> peaks;
  if (prominence != nullptr) prominence->clear();
  const int n = static_cast<int>(amplitude.size());
  if (n < 3) return peaks;
  const double threshold = min_relative_prominence * amplitude.maxCoeff();
  const std::vector<double> left = CalcLowestTowardsStart(n, [&](int j) { return amplitude(j); });
  const std::vector<double> right =
      CalcLowestTowardsStart(n, [&](int j) { return amplitude(n - 1 - j); });
  for (int i = 1; i + 1 < n; ++i) {
    const double height = amplitude(i);
    // A plateau counts once, at its left end.
    if (!(height > amplitude(i - 1) && height >= amplitude(i + 1))) continue;
    const double p =
        height - std::max(left[static_cast<size_t>(i)], right[static_cast<size_t>(n - 1 - i)]);
    if (p > 0 && p >= threshold) {
      peaks.push_back(i);
      if (prominence != nullptr) prominence->push_back(p);
    }
  }
  return peaks;
}

namespace internal {

std::vector<int> FindPeaksByWalking(const Eigen::VectorXd& amplitude,
                                    double min_relative_prominence,
                                    std::vector<double>* prominence) {
  std::vector<int> peaks;
  if (prominence != nullptr) prominence->clear();
  const int n = static_cast<int>(amplitude.size());
  if (n < 3) return peaks;
  const double threshold = min_relative_prominence * amplitude.maxCoeff();
  for (int i = 1; i + 1 < n; ++i) {
    const double height = amplitude(i);
    if (!(height > amplitude(i - 1) && height >= amplitude(i + 1))) continue;
    double left_min = height;
    for (int j = i - 1; j >= 0 && amplitude(j) <= height; --j) {
      left_min = std::min(left_min, amplitude(j));
    }
    double right_min = height;
    for (int j = i + 1; j < n && amplitude(j) <= height; ++j) {
      right_min = std::min(right_min, amplitude(j));
    }
    const double p = height - std::max(left_min, right_min);
    if (p > 0 && p >= threshold) {
      peaks.push_back(i);
      if (prominence != nullptr) prominence->push_back(p);
    }
  }
  return peaks;
}

}  // namespace internal

Spectrum CalcSpectrum(const Eigen::MatrixXd& values, double sample_interval_s,
                      const SpectrumOptions& options) {
  const int samples = static_cast<int>(values.rows());
  Spectrum spectrum;
  spectrum.fft_length =
      NextPowerOfTwo(static_cast<long long>(samples) * std::max(1, options.zero_padding_factor));
  const int nfft = spectrum.fft_length;
  const int bins = nfft / 2 + 1;
  spectrum.frequency_hz =
      Eigen::VectorXd::LinSpaced(bins, 0.0, (bins - 1) / (nfft * sample_interval_s));
  spectrum.amplitude.resize(bins, values.cols());

  std::vector<double> window(samples, 1.0);
  if (options.window == SpectrumWindow::kHann && samples > 1) {
    for (int j = 0; j < samples; ++j) {
      window[j] = 0.5 - 0.5 * std::cos(2.0 * M_PI * j / (samples - 1));
    }
  }
  double window_sum = 0;
  for (double w : window) window_sum += w;

  Eigen::FFT<double> fft;
  fft.SetFlag(Eigen::FFT<double>::HalfSpectrum);
  std::vector<double> input(nfft, 0.0);
  std::vector<std::complex<double>> output;
  for (Eigen::Index c = 0; c < values.cols(); ++c) {
    std::fill(input.begin(), input.end(), 0.0);
    for (int j = 0; j < samples; ++j) input[j] = values(j, c) * window[j];
    fft.fwd(output, input);
    for (int k = 0; k < bins; ++k) {
      const double scale = (k == 0 || 2 * k == nfft) ? 1.0 : 2.0;
      spectrum.amplitude(k, c) = scale * std::abs(output[k]) / window_sum;
    }
    std::vector<double> prominence;
    const std::vector<int> peaks =
        FindPeaks(spectrum.amplitude.col(c), options.min_peak_prominence, &prominence);
    for (size_t i = 0; i < peaks.size(); ++i) {
      spectrum.peaks.push_back({static_cast<int>(c), spectrum.frequency_hz(peaks[i]),
                                spectrum.amplitude(peaks[i], c), prominence[i]});
    }
  }
  return spectrum;
}

}  // namespace mbid::identification
