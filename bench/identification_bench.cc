// Accuracy and cost of the modal identification (issue 4) on the paper's four modes (Table 1
// amplitudes, 2 channels, 100 Hz, 10 s; tests/identification/signals.h).
//
// Before the timings, one run prints for 20 and 30 dB SNR per channel (200 seeded trials,
// --accuracy_trials=N to change, 0 to skip) the RMSE of frequency and decay of each mode over
// the Cramer-Rao bound of the signal model, for the default method (hankel-nls), the paper's
// method (prony-svd, p = 40) and the anchor: a straightforward multichannel matrix pencil with
// a full Eigen SVD (BDCSVD) of the stacked Hankel matrix (L = N/3 columns, the true order given).
// The timings: one identification of 2 x 1000 samples by each, and the default method on 10 s
// records of 1e3..1e6 samples (sampled faster, decimated back to 100 Hz).

#include <benchmark/benchmark.h>

#include <Eigen/QR>
#include <cmath>
#include <complex>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "mbid/common/eigen_decompositions.h"
#include "mbid/common/error.h"
#include "mbid/identification/identify.h"
#include "mbid/identification/spectrum.h"
#include "signals.h"

namespace {

using mbid::identification::IdentificationOptions;
using mbid::identification::Identify;
using mbid::identification::Method;
using mbid::identification::OffsetRemoval;
using mbid::testing::SignalSpec;

constexpr unsigned kSeed = 20261122;

// The anchor: stacked Hankel matrix of every channel, full SVD, shift invariance of the leading
// `order` right singular vectors. Returns the continuous poles with Im > 0.
std::vector<std::complex<double>> MatrixPencil(const Eigen::MatrixXd& y, double tau, int order) {
  const int n = static_cast<int>(y.rows());
  const int m = static_cast<int>(y.cols());
  const int l = n / 3;
  Eigen::MatrixXd hankel(m * (n - l), l + 1);
  for (int c = 0; c < m; ++c) {
    for (int i = 0; i < n - l; ++i) hankel.row(c * (n - l) + i) = y.col(c).segment(i, l + 1);
  }
  Eigen::BDCSVD<Eigen::MatrixXd> svd(hankel, Eigen::ComputeThinV);
  const Eigen::MatrixXd v = svd.matrixV().leftCols(order);
  const Eigen::MatrixXd z = v.topRows(l).colPivHouseholderQr().solve(v.bottomRows(l));
  Eigen::EigenSolver<Eigen::MatrixXd> eigen(z, false);
  std::vector<std::complex<double>> lambda;
  for (int i = 0; i < order; ++i) {
    const std::complex<double> pole = std::log(eigen.eigenvalues()(i)) / tau;
    if (pole.imag() > 0) lambda.push_back(pole);
  }
  return lambda;
}

enum class Estimator { kDefault, kDefaultWithOffset, kPaper, kAnchor };

const char* Name(Estimator estimator) {
  switch (estimator) {
    case Estimator::kDefault:
      return "hankel-nls";
    case Estimator::kDefaultWithOffset:
      return "hankel-nls, offset fitted";
    case Estimator::kPaper:
      return "prony-svd (p = 40)";
    case Estimator::kAnchor:
      return "matrix pencil (anchor)";
  }
  return "";
}

IdentificationOptions OptionsFor(Estimator estimator) {
  IdentificationOptions options;
  options.compute_spectrum = false;
  options.compute_stabilization = false;
  // The bound's model has no offset; "offset fitted" shows what estimating one costs.
  options.offset =
      estimator == Estimator::kDefaultWithOffset ? OffsetRemoval::kFit : OffsetRemoval::kNone;
  if (estimator == Estimator::kPaper) {
    options.method = Method::kPronySvd;
    options.max_frequency_hz = 10;  // step 5: the band of the spectrum's peaks (all below 4 Hz)
  }
  return options;
}

// Poles (lambda, Im > 0) from one noisy record; empty if the method found nothing.
std::vector<std::complex<double>> Estimate(Estimator estimator, const SignalSpec& spec,
                                           const Eigen::MatrixXd& noisy) {
  if (estimator == Estimator::kAnchor) {
    return MatrixPencil(noisy, spec.sample_interval_s, 2 * static_cast<int>(spec.modes.size()));
  }
  std::vector<std::complex<double>> lambda;
  try {
    for (const auto& mode :
         Identify(mbid::testing::MakeRecord(spec, noisy), OptionsFor(estimator)).modes) {
      lambda.push_back(mode.lambda);
    }
  } catch (const mbid::NumericalError&) {
  }
  return lambda;
}

void PrintAccuracy(int trials) {
  const SignalSpec spec = mbid::testing::PaperSignal();
  const Eigen::MatrixXd clean = mbid::testing::Synthesize(spec);
  const size_t modes = spec.modes.size();
  std::printf("\n## RMSE / Cramer-Rao bound, %d trials, paper's four modes, 2 x 1000 samples\n\n",
              trials);
  std::printf("| SNR | method | wrong mode count | ");
  for (size_t k = 0; k < modes; ++k) std::printf("mode %zu f | mode %zu decay | ", k + 1, k + 1);
  std::printf("\n|---|---|---|");
  for (size_t k = 0; k < modes; ++k) std::printf("---|---|");
  std::printf("\n");
  for (double snr_db : {20.0, 30.0}) {
    const Eigen::VectorXd noise_std = mbid::testing::NoiseStd(clean, snr_db);
    const auto bound = mbid::testing::CramerRaoBound(spec, noise_std);
    for (Estimator estimator : {Estimator::kDefault, Estimator::kDefaultWithOffset,
                                Estimator::kPaper, Estimator::kAnchor}) {
      std::mt19937_64 rng(kSeed);  // the same records for every method
      std::vector<double> se_frequency(modes), se_decay(modes);
      int wrong = 0;
      for (int trial = 0; trial < trials; ++trial) {
        const Eigen::MatrixXd noisy = mbid::testing::AddNoise(clean, noise_std, &rng);
        const auto lambda = Estimate(estimator, spec, noisy);
        if (lambda.size() != modes) ++wrong;
        for (size_t k = 0; k < modes; ++k) {
          // The estimate nearest in frequency stands for true mode k (a missed mode counts
          // with the error of its nearest neighbour).
          const double f = spec.modes[k].frequency_hz;
          double best_f = 0, best_d = 0, best = 1e300;
          for (const auto& pole : lambda) {
            const double distance = std::abs(pole.imag() / (2 * M_PI) - f);
            if (distance < best) {
              best = distance;
              best_f = pole.imag() / (2 * M_PI);
              best_d = -pole.real();
            }
          }
          se_frequency[k] += (best_f - f) * (best_f - f) / trials;
          se_decay[k] += std::pow(best_d - spec.modes[k].decay_per_s, 2) / trials;
        }
      }
      std::printf("| %.0f dB | %s | %d | ", snr_db, Name(estimator), wrong);
      for (size_t k = 0; k < modes; ++k) {
        std::printf("%.2f | %.2f | ", std::sqrt(se_frequency[k]) / bound[k].second,
                    std::sqrt(se_decay[k]) / bound[k].first);
      }
      std::printf("\n");
      std::fflush(stdout);
    }
  }
  std::printf("\n");
}

// One noisy record of the paper's signal at 30 dB, `samples` samples over 10 s.
struct Record {
  SignalSpec spec;
  mbid::Measurement measurement;
};

Record MakeRecord(int samples) {
  Record record;
  record.spec = mbid::testing::PaperSignal();
  record.spec.samples = samples;
  record.spec.sample_interval_s = 10.0 / samples;
  const Eigen::MatrixXd clean = mbid::testing::Synthesize(record.spec);
  std::mt19937_64 rng(kSeed);
  record.measurement = mbid::testing::MakeRecord(
      record.spec, mbid::testing::AddNoise(clean, mbid::testing::NoiseStd(clean, 30), &rng));
  return record;
}

void BM_Identify(benchmark::State& state, Method method, bool extras) {
  const Record record = MakeRecord(1000);
  IdentificationOptions options =
      OptionsFor(method == Method::kPronySvd ? Estimator::kPaper : Estimator::kDefaultWithOffset);
  options.compute_spectrum = extras;
  options.compute_stabilization = extras;
  for (auto _ : state) benchmark::DoNotOptimize(Identify(record.measurement, options));
}
BENCHMARK_CAPTURE(BM_Identify, hankel_nls, Method::kHankelNls, false)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Identify, hankel_nls_with_spectrum_and_stabilization, Method::kHankelNls, true)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Identify, prony_svd, Method::kPronySvd, false)->Unit(benchmark::kMillisecond);

void BM_MatrixPencilAnchor(benchmark::State& state) {
  const Record record = MakeRecord(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    benchmark::DoNotOptimize(
        MatrixPencil(record.measurement.values, record.spec.sample_interval_s, 8));
  }
}
BENCHMARK(BM_MatrixPencilAnchor)->Arg(1000)->Unit(benchmark::kMillisecond);

// 10 s of the paper's signal at 100 * (samples / 1000) Hz, decimated back to 100 Hz; defaults
// otherwise (offset fitted; with `extras` the spectrum, zero-padded 4x, and the stabilization
// data, both on the full-rate record).
void BM_Scaling(benchmark::State& state, bool extras) {
  const int samples = static_cast<int>(state.range(0));
  const Record record = MakeRecord(samples);
  IdentificationOptions options;
  options.decimation = samples / 1000;
  options.compute_spectrum = extras;
  options.compute_stabilization = extras;
  size_t modes = 0;
  for (auto _ : state) modes = Identify(record.measurement, options).modes.size();
  state.counters["modes"] = static_cast<double>(modes);
}
// The spectrum's peak search on a clean 51.2 kHz ring-down (151.6 Hz, decay 3/s): one peak and
// thousands of side lobes. Arg: samples. The walking definition is the anchor (O(n^2) here).
Eigen::VectorXd CleanRingDownSpectrum(int samples) {
  const double tau = 1.0 / 51200;
  Eigen::MatrixXd y(samples, 1);
  for (int j = 0; j < samples; ++j) {
    y(j, 0) = std::exp(-3.0 * j * tau) * std::sin(2 * M_PI * 151.6 * j * tau);
  }
  return mbid::identification::CalcSpectrum(y, tau, mbid::identification::SpectrumOptions{})
      .amplitude.col(0);
}

void BM_FindPeaks(benchmark::State& state, bool walking) {
  const Eigen::VectorXd amplitude = CleanRingDownSpectrum(static_cast<int>(state.range(0)));
  std::vector<int> peaks;
  for (auto _ : state) {
    peaks = walking ? mbid::identification::internal::FindPeaksByWalking(amplitude, 0.01)
                    : mbid::identification::FindPeaks(amplitude, 0.01);
    benchmark::DoNotOptimize(peaks.data());
  }
  state.counters["bins"] = static_cast<double>(amplitude.size());
  state.counters["peaks"] = static_cast<double>(peaks.size());
}
// The high-rate case: an impact ring-down at 51.2 kHz with three modes (151.6, 420 and
// 980 Hz) and 1e-3 noise, identified with the defaults (spectrum, stabilization, the band and
// decimation chosen from the spectrum) against the full-rate path of before (decimation 1, the
// anchor). Arg: samples. Counters: modes found and the decimation used.
void BM_HighRate(benchmark::State& state, bool automatic_band) {
  SignalSpec spec;
  spec.channels = {"a"};
  spec.sample_interval_s = 1.0 / 51200;
  spec.samples = static_cast<int>(state.range(0));
  spec.modes = {
      {151.6, 3.0, {1.0}, {0.3}}, {420.0, 8.0, {0.5}, {-1.0}}, {980.0, 20.0, {0.3}, {2.0}}};
  std::mt19937_64 rng(kSeed);
  const Eigen::MatrixXd values = mbid::testing::AddNoise(mbid::testing::Synthesize(spec),
                                                         Eigen::VectorXd::Constant(1, 1e-3), &rng);
  const mbid::Measurement record = mbid::testing::MakeRecord(spec, values);
  IdentificationOptions options;
  if (!automatic_band) options.decimation = 1;
  size_t modes = 0;
  int decimation = 0;
  for (auto _ : state) {
    try {
      const auto result = Identify(record, options);
      modes = result.modes.size();
      decimation = result.decimation;
    } catch (const mbid::NumericalError&) {
      modes = 0;  // "no modes found": counted as such
    }
  }
  state.counters["modes"] = static_cast<double>(modes);
  state.counters["decimation"] = decimation;
}
BENCHMARK_CAPTURE(BM_HighRate, automatic_band, true)
    ->Arg(100000)
    ->Arg(1000000)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);
BENCHMARK_CAPTURE(BM_HighRate, full_rate_anchor, false)
    ->Arg(100000)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);

BENCHMARK_CAPTURE(BM_FindPeaks, one_pass, false)
    ->Arg(1 << 14)
    ->Arg(1 << 16)
    ->Arg(100000)
    ->Arg(1000000)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_FindPeaks, walking_anchor, true)
    ->Arg(1 << 14)
    ->Arg(1 << 16)
    ->Arg(100000)
    ->Unit(benchmark::kMillisecond);

BENCHMARK_CAPTURE(BM_Scaling, defaults, true)
    ->Arg(1000)
    ->Arg(10000)
    ->Arg(100000)
    ->Arg(1000000)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Scaling, without_spectrum_and_stabilization, false)
    ->Arg(1000)
    ->Arg(10000)
    ->Arg(100000)
    ->Arg(1000000)
    ->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) {
  int trials = 200;
  for (int i = 1; i < argc; ++i) {
    if (std::strncmp(argv[i], "--accuracy_trials=", 18) == 0) {
      trials = std::atoi(argv[i] + 18);
      for (int j = i; j + 1 < argc; ++j) argv[j] = argv[j + 1];
      --argc;
      --i;
    }
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  if (trials > 0) PrintAccuracy(trials);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
