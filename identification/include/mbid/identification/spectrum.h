#pragma once

#include <Eigen/Core>
#include <vector>

#include "mbid/identification/options.h"

namespace mbid::identification {

// A local maximum of one channel's amplitude spectrum.
struct SpectrumPeak {
  int channel = 0;          // column of the analysed record
  double frequency_hz = 0;  // of the bin (no interpolation between bins)
  double amplitude = 0;     // as in Spectrum::amplitude
  double prominence = 0;    // topographic prominence, same units as amplitude
};

// Step 1 of method.md (the paper's Fig. 2): the one-sided FFT amplitude spectrum per channel.
// Scaled so that a steady sinusoid of amplitude A on a bin shows a peak of height A, whatever
// the window and padding: |X_k| * 2 / sum(window) (bin 0 without the factor 2).
struct Spectrum {
  Eigen::VectorXd frequency_hz;     // bins 0..nfft/2, spacing 1 / (nfft tau)
  Eigen::MatrixXd amplitude;        // bins x channels, units of the channel
  std::vector<SpectrumPeak> peaks;  // every channel's peaks, by channel then frequency
  int fft_length = 0;
};

// The spectrum of each column of `values` (samples x channels; the mean is not removed here),
// with its peaks (FindPeaks with options.min_peak_prominence). Uses Eigen's FFT module.
Spectrum CalcSpectrum(const Eigen::MatrixXd& values, double sample_interval_s,
                      const SpectrumOptions& options);

// Indices of the local maxima of `amplitude` (not at either end) whose topographic prominence
// is at least min_relative_prominence times the largest value; `prominence` (if given) gets
// each one's prominence. Ascending index.
// O(n): one pass each way for the lowest value before a higher sample.
std::vector<int> FindPeaks(const Eigen::VectorXd& amplitude, double min_relative_prominence,
                           std::vector<double>* prominence = nullptr);

namespace internal {
// The same by walking from every maximum to the next higher sample: O(n^2) on clean spectra.
// The definition FindPeaks is tested against, and the anchor of its benchmark.
std::vector<int> FindPeaksByWalking(const Eigen::VectorXd& amplitude,
                                    double min_relative_prominence,
                                    std::vector<double>* prominence = nullptr);
}  // namespace internal

}  // namespace mbid::identification
