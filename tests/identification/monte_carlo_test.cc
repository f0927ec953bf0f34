// Seeded Monte Carlo of the paper's four modes against the Cramer-Rao bound computed in
// signals.h from the Fisher matrix of the signal model.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "mbid/identification/identify.h"
#include "signals.h"

namespace mbid::identification {
namespace {

using testing::CramerRaoBound;
using testing::PaperSignal;
using testing::SignalSpec;

struct MonteCarlo {
  std::vector<double> rmse_decay, rmse_frequency;            // per mode
  std::vector<double> predicted_decay, predicted_frequency;  // mean reported std per mode
  std::vector<int> effective_rank;                           // per trial
};

// Each trial: new noise, identification, the estimate nearest in frequency to each true mode.
MonteCarlo RunMonteCarlo(const SignalSpec& spec, double snr_db,
                         const IdentificationOptions& options, int trials, unsigned seed) {
  const Eigen::MatrixXd clean = testing::Synthesize(spec);
  const Eigen::VectorXd noise_std = testing::NoiseStd(clean, snr_db);
  const size_t modes = spec.modes.size();
  MonteCarlo mc{std::vector<double>(modes),
                std::vector<double>(modes),
                std::vector<double>(modes),
                std::vector<double>(modes),
                {}};
  std::mt19937_64 rng(seed);
  for (int trial = 0; trial < trials; ++trial) {
    const Eigen::MatrixXd noisy = testing::AddNoise(clean, noise_std, &rng);
    const ModalResult result = Identify(testing::MakeRecord(spec, noisy), options);
    mc.effective_rank.push_back(result.effective_rank);
    for (size_t k = 0; k < modes; ++k) {
      const auto& truth = spec.modes[k];
      const IdentifiedMode* nearest = nullptr;
      for (const IdentifiedMode& mode : result.modes) {
        if (nearest == nullptr || std::abs(mode.frequency_hz - truth.frequency_hz) <
                                      std::abs(nearest->frequency_hz - truth.frequency_hz)) {
          nearest = &mode;
        }
      }
      if (nearest == nullptr) {
        ADD_FAILURE() << "no mode identified in trial " << trial;
        continue;
      }
      mc.rmse_decay[k] += std::pow(nearest->decay_rate_per_s - truth.decay_per_s, 2) / trials;
      mc.rmse_frequency[k] += std::pow(nearest->frequency_hz - truth.frequency_hz, 2) / trials;
      mc.predicted_decay[k] += nearest->std_decay_rate_per_s / trials;
      mc.predicted_frequency[k] += nearest->std_frequency_hz / trials;
    }
  }
  for (size_t k = 0; k < modes; ++k) {
    mc.rmse_decay[k] = std::sqrt(mc.rmse_decay[k]);
    mc.rmse_frequency[k] = std::sqrt(mc.rmse_frequency[k]);
  }
  return mc;
}

// The CRLB model has no offset, so the estimator is told there is none (an offset estimated
// with a strongly decaying record adds variance that the bound above does not include).
IdentificationOptions NoOffset(Method method) {
  IdentificationOptions options;
  options.method = method;
  options.offset = OffsetRemoval::kNone;
  options.compute_spectrum = false;
  options.compute_stabilization = false;
  return options;
}

// 150 trials: the relative standard error of an RMSE estimate is 1/sqrt(2 x 150) = 6 %, so the
// issue's 1.3x leaves 4 standard errors above the measured 0.95-1.05 (bench: 0.96-1.03 with
// 500 trials).
TEST(MonteCarloTest, DefaultMethodReachesTheCramerRaoBoundAndReportsIt) {
  const SignalSpec spec = PaperSignal();
  constexpr int kTrials = 150;
  constexpr double kSnrDb = 30;  // issue 4's Table 1 test
  const auto bound = CramerRaoBound(spec, testing::NoiseStd(testing::Synthesize(spec), kSnrDb));
  const MonteCarlo mc = RunMonteCarlo(spec, kSnrDb, NoOffset(Method::kHankelNls), kTrials, 2024);
  for (size_t k = 0; k < spec.modes.size(); ++k) {
    EXPECT_LE(mc.rmse_decay[k] / bound[k].first, 1.3) << "mode " << k;
    EXPECT_LE(mc.rmse_frequency[k] / bound[k].second, 1.3) << "mode " << k;
    // The reported standard deviations (Fisher information at each estimate, refinement.h)
    // against the Monte Carlo spread: within 25 %, i.e. 4 standard errors.
    EXPECT_NEAR(mc.predicted_decay[k] / mc.rmse_decay[k], 1.0, 0.25) << "mode " << k;
    EXPECT_NEAR(mc.predicted_frequency[k] / mc.rmse_frequency[k], 1.0, 0.25) << "mode " << k;
  }
}

double WorstRatioToBound(const MonteCarlo& mc, const SignalSpec& spec, double snr_db) {
  const auto bound = CramerRaoBound(spec, testing::NoiseStd(testing::Synthesize(spec), snr_db));
  double worst = 0;
  for (size_t k = 0; k < spec.modes.size(); ++k) {
    worst = std::max(
        {worst, mc.rmse_decay[k] / bound[k].first, mc.rmse_frequency[k] / bound[k].second});
  }
  return worst;
}

// The paper's least-squares vector AR (p = 40, full rank: noise_floor_factor 0) is biased under
// noise (issue 4: "its known weakness must be visible"): at 30 dB at least one mode is well
// above the bound, and its reported standard deviations cover that. 40 trials: enough to tell 1.5x
// from 1x (the bench measures 2.3-5.4x with 100).
TEST(MonteCarloTest, PaperMethodAsUsuallyAppliedStaysAboveTheBound) {
  const SignalSpec spec = PaperSignal();
  constexpr double kSnrDb = 30;
  IdentificationOptions options = NoOffset(Method::kPronySvd);
  options.max_frequency_hz = 10;  // step 5: the band of the spectrum's peaks (all below 4 Hz)
  options.prony.noise_floor_factor = 0;  // every singular value above round-off
  const MonteCarlo mc = RunMonteCarlo(spec, kSnrDb, options, 40, 77);
  EXPECT_GT(WorstRatioToBound(mc, spec, kSnrDb), 1.5);
  // Its standard deviations say so: the bound at its poles, widened by their distance to the
  // likelihood's maximum (mode_results.cc), against the spread: measured 0.83-0.97 (0.21-0.51
  // with the bound alone); 0.7 is 3 standard errors of a 40-trial RMSE (11 %) below the least.
  for (size_t k = 0; k < spec.modes.size(); ++k) {
    EXPECT_GT(mc.predicted_decay[k] / mc.rmse_decay[k], 0.7) << "mode " << k;
    EXPECT_GT(mc.predicted_frequency[k] / mc.rmse_frequency[k], 0.7) << "mode " << k;
  }
  // Full rank: 2 channels x 40 lags + the constant.
  for (int rank : mc.effective_rank) EXPECT_EQ(rank, 81);
}

// Step 3 with the threshold at the noise level (the default): the effective rank is the model
// order, 2 x 4 modes + 1 constant = 9 (sub-problem 4). The truncated solution (Kumaresan and
// Tufts) is not closer to the bound at p = 40 on these records: worst ratio 5.6 against 5.5 for
// plain least squares (measured; the default method is the one at the bound).
TEST(MonteCarloTest, PaperMethodRankAtTheNoiseLevelGivesTheModelOrder) {
  const SignalSpec spec = PaperSignal();
  constexpr double kSnrDb = 30;
  IdentificationOptions options = NoOffset(Method::kPronySvd);
  options.max_frequency_hz = 10;
  const MonteCarlo truncated = RunMonteCarlo(spec, kSnrDb, options, 40, 77);
  int at_order = 0;
  for (int rank : truncated.effective_rank) at_order += rank == 9 ? 1 : 0;
  // Mode 1 (damping 0.68, the weakest at 30 dB) sits near the noise edge: measured 39 of 40.
  EXPECT_GE(at_order, 36) << "records whose effective rank is 2 x 4 + 1";
}

}  // namespace
}  // namespace mbid::identification
