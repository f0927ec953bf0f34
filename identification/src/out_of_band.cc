#include "out_of_band.h"

#include <algorithm>
#include <complex>
#include <unsupported/Eigen/FFT>
#include <vector>

#include "mbid/identification/spectrum.h"

namespace mbid::identification {

// Squared amplitude spectrum of `segment` mirrored (its periodic extension continuous).
Eigen::MatrixXd MirroredPower(const Eigen::MatrixXd& segment, double sample_interval_s,
                              Eigen::VectorXd* frequency_hz) {
  Eigen::MatrixXd mirrored(2 * segment.rows(), segment.cols());
  mirrored.topRows(segment.rows()) = segment.colwise().reverse();
  mirrored.bottomRows(segment.rows()) = segment;
  SpectrumOptions options;
  options.window = SpectrumWindow::kNone;
  options.zero_padding_factor = 1;
  options.min_peak_prominence = 1;  // no peak list needed
  const Spectrum spectrum = CalcSpectrum(mirrored, sample_interval_s, options);
  *frequency_hz = spectrum.frequency_hz;
  return spectrum.amplitude.array().square();
}

Eigen::MatrixXd BandLimited(const Eigen::MatrixXd& values, double sample_interval_s,
                            double top_hz) {
  const Eigen::Index n = values.rows();
  Eigen::MatrixXd limited(n, values.cols());
  // Padded with zeros to a power of two (a length with a large prime factor costs the FFT
  // quadratic time): the zeros meet the mirror at the record's end, never at its start.
  Eigen::Index length = 1;
  while (length < 2 * n) length *= 2;
  Eigen::FFT<double> fft;
  fft.SetFlag(Eigen::FFT<double>::HalfSpectrum);
  std::vector<double> mirrored(static_cast<size_t>(length));
  std::vector<std::complex<double>> spectrum;
  for (Eigen::Index c = 0; c < values.cols(); ++c) {
    std::fill(mirrored.begin(), mirrored.end(), 0.0);
    for (Eigen::Index j = 0; j < n; ++j) {
      mirrored[static_cast<size_t>(n - 1 - j)] = values(j, c);
      mirrored[static_cast<size_t>(n + j)] = values(j, c);
    }
    fft.fwd(spectrum, mirrored);
    for (size_t b = 0; b < spectrum.size(); ++b) {
      if (static_cast<double>(b) / (static_cast<double>(length) * sample_interval_s) > top_hz) {
        spectrum[b] = 0;
      }
    }
    fft.inv(mirrored, spectrum);
    for (Eigen::Index j = 0; j < n; ++j) limited(j, c) = mirrored[static_cast<size_t>(n + j)];
  }
  return limited;
}

namespace {

constexpr Eigen::Index kLongestSegment = 2048;
constexpr Eigen::Index kBandBins = 32;
// Two bands at least, so that a band above the analysed one exists.
constexpr Eigen::Index kShortestSegment = 2 * kBandBins;
constexpr double kPowerRatio = 10;
constexpr double kRoundOff = 1e-12;

}  // namespace

double FindDecayingContentTop(const Eigen::MatrixXd& values, const Eigen::MatrixXd& residual,
                              double sample_interval_s) {
  double top_hz = 0;
  // A short record's halves: a burst at the start is as plain there, and the two halves' noise
  // as alike (the bands keep their 32 bins whatever the segment's length). Shorter segments too:
  // a burst of a few milliseconds (200 Hz at 20 % damping on a 1 kHz record) spreads over a
  // hundred bins of 2048 samples' spectrum and stands out of none of its bands.
  for (Eigen::Index segment = std::min(kLongestSegment, residual.rows() / 2);
       segment >= kShortestSegment; segment /= 2) {
    Eigen::VectorXd frequency_hz;
    const Eigen::MatrixXd start =
        MirroredPower(residual.topRows(segment), sample_interval_s, &frequency_hz);
    const Eigen::MatrixXd end =
        MirroredPower(residual.bottomRows(segment), sample_interval_s, &frequency_hz);
    const Eigen::VectorXd total =
        MirroredPower(values.topRows(segment), sample_interval_s, &frequency_hz).colwise().sum();
    for (Eigen::Index c = 0; c < residual.cols(); ++c) {
      for (Eigen::Index b = 1; b + kBandBins <= start.rows(); b += kBandBins) {
        const double at_start = start.col(c).segment(b, kBandBins).sum();
        const double at_end = end.col(c).segment(b, kBandBins).sum();
        if (at_start > kPowerRatio * at_end && at_start > kRoundOff * total(c)) {
          top_hz = std::max(top_hz, frequency_hz(b + kBandBins - 1));
        }
      }
    }
  }
  return top_hz;
}

}  // namespace mbid::identification
