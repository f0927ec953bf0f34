#include "mbid/identification/spectrum.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace mbid::identification {
namespace {

// A steady sinusoid that completes a whole number of cycles in the record sits on a bin.
Eigen::MatrixXd Sinusoid(double amplitude, double frequency_hz, double tau, int samples) {
  Eigen::MatrixXd y(samples, 1);
  for (int j = 0; j < samples; ++j)
    y(j, 0) = amplitude * std::cos(2 * M_PI * frequency_hz * j * tau);
  return y;
}

TEST(SpectrumTest, SinusoidOnABinShowsItsAmplitude) {
  const double tau = 0.01;
  const int samples = 1024;
  // 25 cycles in 10.24 s.
  const double frequency = 25.0 / (samples * tau);
  for (SpectrumWindow window : {SpectrumWindow::kNone, SpectrumWindow::kHann}) {
    SpectrumOptions options;
    options.window = window;
    options.zero_padding_factor = 1;  // the bin grid is the record's own
    const Spectrum spectrum = CalcSpectrum(Sinusoid(0.3, frequency, tau, samples), tau, options);
    EXPECT_EQ(spectrum.fft_length, 1024);
    EXPECT_EQ(spectrum.frequency_hz.size(), 513);
    EXPECT_NEAR(spectrum.frequency_hz(25), frequency, 1e-12);
    Eigen::Index peak = 0;
    spectrum.amplitude.col(0).maxCoeff(&peak);
    EXPECT_EQ(peak, 25);
    // Rectangular window: exact. Hann: the window is 0 at both ends (N - 1 periodicity), so
    // its sum is (N - 1) / 2, not N / 2; the scaling uses the actual sum: exact to ~1e-3.
    EXPECT_NEAR(spectrum.amplitude(25, 0), 0.3, window == SpectrumWindow::kNone ? 1e-12 : 1e-3);
    ASSERT_EQ(spectrum.peaks.size(), 1u);
    EXPECT_EQ(spectrum.peaks[0].channel, 0);
    EXPECT_NEAR(spectrum.peaks[0].frequency_hz, frequency, 1e-12);
  }
}

TEST(SpectrumTest, ZeroPaddingRoundsUpToAPowerOfTwo) {
  SpectrumOptions options;
  options.zero_padding_factor = 4;
  const Spectrum spectrum = CalcSpectrum(Sinusoid(1.0, 2.0, 0.01, 1000), 0.01, options);
  EXPECT_EQ(spectrum.fft_length, 4096);  // >= 4 x 1000
  EXPECT_NEAR(spectrum.frequency_hz(1), 1.0 / (4096 * 0.01), 1e-15);
}

TEST(SpectrumTest, PeaksBelowTheProminenceThresholdAreIgnored) {
  const double tau = 0.01;
  Eigen::MatrixXd y = Sinusoid(1.0, 5.0, tau, 2000) + Sinusoid(0.2, 12.0, tau, 2000) +
                      Sinusoid(0.01, 20.0, tau, 2000);
  SpectrumOptions options;
  options.min_peak_prominence = 0.05;  // the 0.2 peak passes, the 0.01 one does not
  const Spectrum spectrum = CalcSpectrum(y, tau, options);
  ASSERT_EQ(spectrum.peaks.size(), 2u);
  EXPECT_NEAR(spectrum.peaks[0].frequency_hz, 5.0, 0.02);  // bin spacing 1/(8192 tau) = 0.012
  EXPECT_NEAR(spectrum.peaks[1].frequency_hz, 12.0, 0.02);
  EXPECT_NEAR(spectrum.peaks[1].amplitude, 0.2, 0.01);
}

TEST(SpectrumTest, ProminenceByHand) {
  // Local maxima at 1 (height 3), 3 (5) and 5 (4). Each side is walked until a higher sample
  // or the end, keeping its lowest value; the prominence is the height minus the higher of the
  // two lows. Index 1: left low 0 (end), right low 1 (stops at the 5): 3 - 1 = 2. Index 3:
  // left low 0, right low 0.5 (both ends): 5 - 0.5 = 4.5. Index 5: left low 1 (stops at the
  // 5), right low 0.5 (end): 4 - 1 = 3.
  Eigen::VectorXd a(7);
  a << 0, 3, 1, 5, 1, 4, 0.5;
  std::vector<double> prominence;
  const std::vector<int> peaks = FindPeaks(a, 0.0, &prominence);
  ASSERT_EQ(peaks, (std::vector<int>{1, 3, 5}));
  EXPECT_DOUBLE_EQ(prominence[0], 2.0);
  EXPECT_DOUBLE_EQ(prominence[1], 4.5);
  EXPECT_DOUBLE_EQ(prominence[2], 3.0);
  // Relative threshold 0.5 of the largest value (5): 2.5; peak 1 (2) is dropped.
  EXPECT_EQ(FindPeaks(a, 0.5), (std::vector<int>{3, 5}));
}

// The one-pass FindPeaks against the definition (walking from each maximum to the next higher
// sample) on spectra of every kind: white noise, quantized values with plateaus and ties, and
// the clean decaying spectrum with thousands of side lobes where walking was quadratic. Mins
// and maxes are exact, so the peaks and prominences must be equal to the bit.
TEST(SpectrumTest, OnePassPeaksEqualTheWalkingDefinition) {
  std::mt19937_64 random(11);
  std::normal_distribution<double> normal;
  for (int trial = 0; trial < 30; ++trial) {
    const int n = 50 + 97 * trial;
    Eigen::VectorXd a(n);
    for (int i = 0; i < n; ++i) {
      a[i] = trial % 3 == 0 ? std::abs(normal(random))
             : trial % 3 == 1
                 ? std::round(4 * std::abs(normal(random)))  // ties, plateaus
                 : std::abs(std::sin(0.37 * i)) / (1 + 0.01 * i) + 1e-3 * normal(random);
    }
    for (double threshold : {0.0, 0.01, 0.3}) {
      std::vector<double> p_fast, p_walk;
      EXPECT_EQ(FindPeaks(a, threshold, &p_fast),
                internal::FindPeaksByWalking(a, threshold, &p_walk))
          << trial;
      EXPECT_EQ(p_fast, p_walk) << trial;
    }
  }
  // A long clean ring-down's spectrum: one peak, many lobes.
  const double tau = 1.0 / 51200;
  Eigen::MatrixXd y(1 << 13, 1);
  for (int j = 0; j < y.rows(); ++j)
    y(j, 0) = std::exp(-3.0 * j * tau) * std::sin(2 * M_PI * 151.6 * j * tau);
  SpectrumOptions options;
  const Spectrum spectrum = CalcSpectrum(y, tau, options);
  EXPECT_EQ(FindPeaks(spectrum.amplitude.col(0), 0.0),
            internal::FindPeaksByWalking(spectrum.amplitude.col(0), 0.0));
}

}  // namespace
}  // namespace mbid::identification
