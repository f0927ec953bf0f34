#include "mbid/identification/identify.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "mbid/common/error.h"
#include "signals.h"

namespace mbid::identification {
namespace {

using testing::CramerRaoBound;
using testing::MakeRecord;
using testing::PaperSignal;
using testing::SignalSpec;
using testing::Synthesize;

// Expects the modes of `result` to be those of `spec`, one to one in ascending frequency.
void ExpectModes(const ModalResult& result, const SignalSpec& spec, double pole_tolerance,
                 double amplitude_tolerance, double phase_tolerance) {
  ASSERT_EQ(result.modes.size(), spec.modes.size());
  for (size_t k = 0; k < spec.modes.size(); ++k) {
    const IdentifiedMode& mode = result.modes[k];
    const auto& truth = spec.modes[k];
    const std::complex<double> lambda(-truth.decay_per_s, 2 * M_PI * truth.frequency_hz);
    EXPECT_LE(std::abs(mode.lambda - lambda) / std::abs(lambda), pole_tolerance) << "mode " << k;
    for (size_t c = 0; c < spec.channels.size(); ++c) {
      EXPECT_NEAR(mode.amplitude(c), truth.amplitude[c], amplitude_tolerance * truth.amplitude[c])
          << "mode " << k << " channel " << c;
      EXPECT_NEAR(std::remainder(mode.phase_rad(c) - truth.phase_rad[c], 2 * M_PI), 0.0,
                  phase_tolerance)
          << "mode " << k << " channel " << c;
    }
  }
}

// Three modes, two channels, a constant offset in one: the noiseless record is exactly the
// model, so the poles are exact up to round-off (1e-8 relative, issue 4) and amplitudes and
// phases to 1e-6 (issue 4).
SignalSpec ThreeModes() {
  SignalSpec spec;
  spec.channels = {"a", "b"};
  spec.sample_interval_s = 0.005;  // 200 Hz: well above the highest mode
  spec.samples = 1500;             // 7.5 s: the slowest mode decays to e^-1.5
  spec.modes = {{0.8, 0.2, {1.0, 0.3}, {0.4, -2.0}},
                {2.5, 1.5, {0.2, 0.5}, {-1.0, 1.2}},
                {7.3, 4.0, {0.05, 0.4}, {2.9, 0.1}}};
  spec.offset = {0.1, -0.02};
  return spec;
}

TEST(IdentifyTest, NoiselessDampedSinusoidsAreExact) {
  const SignalSpec spec = ThreeModes();
  IdentificationOptions options;
  for (Method method : {Method::kHankelNls}) {
    options.method = method;
    const ModalResult result = Identify(MakeRecord(spec, Synthesize(spec)), options);
    ExpectModes(result, spec, 1e-8, 1e-6, 1e-6);
    EXPECT_TRUE(result.reliable) << (result.reasons.empty() ? "" : result.reasons.front());
    EXPECT_EQ(result.release, "record start");              // the record starts in the decay
    for (int c = 0; c < 2; ++c) {                           // 2 channels
      EXPECT_NEAR(result.offset(c), spec.offset[c], 1e-9);  // round-off of the linear fit
      EXPECT_GT(result.correlation(c), 1 - 1e-12);          // reconstruction is the record
    }
  }
}

// One mode at -3 dB SNR (the noise's power twice the signal's over the 100 Hz record): in the
// analysed band (decimated by 4, the filter passes about a quarter of the noise) K is 0.84
// (measured) against the default min_correlation 0.9, the residual at the noise level (1.3
// times the estimated one). The result is unreliable, and the reason says that the channel's
// noise, not the modes, keeps K low.
TEST(IdentifyTest, ANoiseLimitedCorrelationIsCalledSo) {
  SignalSpec spec;
  spec.channels = {"x"};
  spec.sample_interval_s = 0.01;
  spec.samples = 2000;
  spec.modes = {{1.5, 0.05, {1.0}, {0.3}}};
  const Eigen::MatrixXd clean = Synthesize(spec);
  std::mt19937_64 rng(7);
  const Eigen::MatrixXd noisy = testing::AddNoise(clean, testing::NoiseStd(clean, -3.0), &rng);
  const ModalResult result = Identify(MakeRecord(spec, noisy), {});
  ASSERT_EQ(result.modes.size(), 1u);
  EXPECT_NEAR(result.modes[0].frequency_hz, 1.5, 0.01);  // still found, within 0.7%
  EXPECT_LT(result.correlation(0), 0.9);
  EXPECT_FALSE(result.reliable);
  ASSERT_FALSE(result.reasons.empty());
  EXPECT_NE(result.reasons[0].find("too little signal"), std::string::npos) << result.reasons[0];
  EXPECT_EQ(result.reasons[0].find("do not explain"), std::string::npos) << result.reasons[0];
}

// Beside a channel that correlates, a channel of pure noise (a sensor on a part that does not
// move, or a dead one with noise) says nothing against the modes: it is named in a warning, not
// as a reason (a trial's 20 of 20 such records were unreliable). Alone, as above, it is a reason.
TEST(IdentifyTest, APureNoiseChannelBesideAGoodOneIsAWarning) {
  SignalSpec spec;
  spec.channels = {"x", "quiet"};
  spec.sample_interval_s = 0.01;
  spec.samples = 2000;
  spec.modes = {{1.5, 0.05, {1.0, 0.0}, {0.3, 0.0}}};
  const Eigen::MatrixXd noisy = testing::SynthesizeNoisy(spec, Eigen::Vector2d(2e-3, 2e-3), 7);
  const ModalResult result = Identify(MakeRecord(spec, noisy), {});
  ASSERT_EQ(result.modes.size(), 1u);
  EXPECT_NEAR(result.modes[0].frequency_hz, 1.5, 1e-3);
  EXPECT_TRUE(result.reliable) << ::testing::PrintToString(result.reasons);
  EXPECT_TRUE(testing::Mentions(result.warnings, "in channel quiet is below min_correlation"))
      << ::testing::PrintToString(result.warnings);
}

// One channel x: 1.5 Hz at 5 % damping, 8 s at 100 Hz, 40 dB (seeded): reliable as recorded.
SignalSpec OneDecaySpec() {
  SignalSpec spec;
  spec.channels = {"x"};
  spec.sample_interval_s = 0.01;
  spec.samples = 800;
  spec.modes = {{1.5, 0.47, {1.0}, {0.0}}};
  return spec;
}

Eigen::MatrixXd OneDecay() {
  const Eigen::MatrixXd clean = Synthesize(OneDecaySpec());
  std::mt19937_64 rng(11);
  return testing::AddNoise(clean, testing::NoiseStd(clean, 40.0), &rng);
}

TEST(IdentifyTest, AClippedChannelMakesTheResultUnreliable) {
  // OneDecay() held at 60 % of its first peak (a logger at the end of its range) and analysed
  // as recorded (skip_clipped false): the flattened peaks bring modes of their own.
  const SignalSpec spec = OneDecaySpec();
  const Eigen::MatrixXd noisy = OneDecay();
  const ModalResult as_recorded = Identify(MakeRecord(spec, noisy), {});
  EXPECT_TRUE(as_recorded.reliable) << ::testing::PrintToString(as_recorded.reasons);
  const double rail = 0.6 * noisy.maxCoeff();
  IdentificationOptions keep;
  keep.skip_clipped = false;
  const ModalResult clipped = Identify(MakeRecord(spec, noisy.cwiseMin(rail)), keep);
  EXPECT_FALSE(clipped.reliable);
  ASSERT_FALSE(clipped.reasons.empty());
  EXPECT_NE(clipped.reasons[0].find("channel x stays at its largest value"), std::string::npos)
      << clipped.reasons[0];
  EXPECT_NE(clipped.reasons[0].find("(clipped)"), std::string::npos) << clipped.reasons[0];
}

TEST(IdentifyTest, AClippedStartIsSkipped) {
  // The same record by default: its peaks (every 2/3 s) are above the rail at 0 and 2/3 s
  // (e^(-0.47 * 2/3) = 0.73) and below it from 4/3 s on (0.53), so the decay after the clipped
  // peak at 2/3 s is analysed, about 90 % of the record.
  const SignalSpec spec = OneDecaySpec();
  const Eigen::MatrixXd noisy = OneDecay();
  const double rail = 0.6 * noisy.maxCoeff();
  const ModalResult result = Identify(MakeRecord(spec, noisy.cwiseMin(rail)), {});
  EXPECT_TRUE(result.reliable) << ::testing::PrintToString(result.reasons);
  EXPECT_GT(result.start_time_s, 2.0 / 3.0);
  EXPECT_LT(result.start_time_s, 4.0 / 3.0);
  EXPECT_TRUE(std::any_of(result.warnings.begin(), result.warnings.end(), [](const std::string& w) {
    return w.find("channel x stays at its largest value") != std::string::npos &&
           w.find("the analysis starts after the last clipped sample") != std::string::npos;
  })) << ::testing::PrintToString(result.warnings);
  ASSERT_EQ(result.modes.size(), 1u);
  // The true pole within 4 standard deviations (40 dB of noise: a fraction of a percent).
  EXPECT_NEAR(result.modes[0].frequency_hz, 1.5, 4 * result.modes[0].std_frequency_hz);
  EXPECT_NEAR(result.modes[0].decay_rate_per_s, 0.47, 4 * result.modes[0].std_decay_rate_per_s);

  // Held at 5 % of its first peak, the decay is inside the rail only from about 6.4 s on
  // (ln 20 / 0.47): under half the record would be left, so nothing is skipped; unreliable.
  const ModalResult deep = Identify(MakeRecord(spec, noisy.cwiseMin(0.05 * noisy.maxCoeff())), {});
  EXPECT_FALSE(deep.reliable);
  EXPECT_TRUE(std::none_of(deep.warnings.begin(), deep.warnings.end(), [](const std::string& w) {
    return w.find("the analysis starts after the last clipped sample") != std::string::npos;
  })) << ::testing::PrintToString(deep.warnings);
  ASSERT_FALSE(deep.reasons.empty());
  EXPECT_NE(deep.reasons[0].find("(clipped)"), std::string::npos) << deep.reasons[0];
}

TEST(IdentifyTest, AGlitchMakesTheResultUnreliable) {
  // OneDecay() (reliable as recorded) with one sample half the release amplitude off, as an
  // electrical glitch makes it: the reason names its time.
  const SignalSpec spec = OneDecaySpec();
  Eigen::MatrixXd noisy = OneDecay();
  noisy(300, 0) += 0.5;
  const ModalResult result = Identify(MakeRecord(spec, noisy), {});
  EXPECT_FALSE(result.reliable);
  ASSERT_FALSE(result.reasons.empty());
  EXPECT_NE(result.reasons[0].find("channel x jumps off its course at 3 s ("), std::string::npos)
      << result.reasons[0];
  // 20 times the release amplitude: still no release (the record starts in the decay), and the
  // glitch is named.
  noisy(300, 0) += 19.5;
  const ModalResult large = Identify(MakeRecord(spec, noisy), {});
  EXPECT_EQ(large.release_time_s, 0.0);
  EXPECT_FALSE(large.reliable);
  ASSERT_FALSE(large.reasons.empty());
  EXPECT_NE(large.reasons[0].find("channel x jumps off its course at 3 s ("), std::string::npos)
      << large.reasons[0];
  // Noise alone but for a glitch: when nothing survives, the failure names the glitch.
  Eigen::MatrixXd noise = OneDecay() - Synthesize(spec);
  noise(300, 0) += 0.5;
  try {
    const ModalResult none = Identify(MakeRecord(spec, noise), {});
    EXPECT_FALSE(none.reliable);  // if a mode is fitted to it, it is not believed
  } catch (const NumericalError& e) {
    EXPECT_NE(std::string(e.what()).find("no modes found"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("channel x jumps off its course at 3 s"),
              std::string::npos)
        << e.what();
  }
}

// An aerial platform's load drop (200 Hz, 6 s): its 0.96 Hz luffing mode in all four channels,
// its 1.08 Hz slew mode in the turret's gyro alone, its 6.7 Hz mode in all but the gyro.
SignalSpec PlatformWithAGyroMode() {
  SignalSpec spec;
  spec.channels = {"incl", "acc_y", "acc_z", "gyro"};
  spec.sample_interval_s = 0.005;  // 200 Hz, 6 s
  spec.samples = 1201;
  spec.modes = {{0.9595, 0.109, {1.0, 1.0, 1.0, 1.0}, {0.0, 0.1, 0.2, 0.3}},
                {1.0805, 0.159, {0.0, 0.0, 0.0, 0.35}, {0.0, 0.0, 0.0, 1.0}},
                {6.697, 4.43, {0.1, 0.3, 0.3, 0.0}, {0.0, 0.5, 1.0, 0.0}}};
  return spec;
}

TEST(IdentifyTest, AModeSeenByOneChannelOfFourIsFound) {
  // An aerial platform's load drop (6 coordinates): its 1.08 Hz slew mode shows in the
  // turret's gyro alone, 12 % above the 0.96 Hz luffing mode that all four channels see. In the
  // summed Hankel matrix it brings one channel's energy against four channels' noise and stays
  // under the signal order; the gyro's residual (5 times its noise) is searched alone.
  const SignalSpec spec = PlatformWithAGyroMode();
  const Eigen::MatrixXd clean = Synthesize(spec);
  std::mt19937_64 rng(5);
  Eigen::VectorXd noise(4);
  noise << 1e-3, 5e-3, 5e-3, 0.03;  // 60, 46, 46 and 30 dB below the release amplitude
  const ModalResult result = Identify(MakeRecord(spec, testing::AddNoise(clean, noise, &rng)), {});
  ASSERT_EQ(result.modes.size(), 3u);
  EXPECT_TRUE(result.reliable) << ::testing::PrintToString(result.reasons);
  // Within 3 standard deviations of the truth (the gyro at 30 dB).
  EXPECT_NEAR(result.modes[1].frequency_hz, 1.0805, 3 * result.modes[1].std_frequency_hz);
  EXPECT_NEAR(result.modes[1].decay_rate_per_s, 0.159, 3 * result.modes[1].std_decay_rate_per_s);
  EXPECT_NEAR(result.modes[0].decay_rate_per_s, 0.109, 3 * result.modes[0].std_decay_rate_per_s);
}

TEST(IdentifyTest, AModeFoundInOneChannelLeavesTheResidualCheckInPlace) {
  // The platform's record with a 20 -> 30 Hz sweep of 4 times the noise in the inclinometer
  // (a hydraulic pump's whine): no sum of decaying modes. The gyro's mode is found alone; the
  // inclinometer's residual must still be weighed against the record's noise (the estimate that
  // found the extra mode once lost that level, and the check passed unnoticed).
  const SignalSpec spec = PlatformWithAGyroMode();
  Eigen::MatrixXd clean = Synthesize(spec);
  for (int j = 0; j < spec.samples; ++j) {
    const double t = j * spec.sample_interval_s;
    clean(j, 0) += 4e-3 * std::sin(2 * M_PI * (20 * t + 5.0 / 6.0 * t * t));
  }
  std::mt19937_64 rng(5);
  Eigen::VectorXd noise(4);
  noise << 1e-3, 5e-3, 5e-3, 0.03;
  const ModalResult result = Identify(MakeRecord(spec, testing::AddNoise(clean, noise, &rng)), {});
  EXPECT_FALSE(result.reliable);
  EXPECT_TRUE(std::any_of(result.reasons.begin(), result.reasons.end(), [](const std::string& r) {
    return r.find("the residual in channel incl is") != std::string::npos;
  })) << ::testing::PrintToString(result.reasons);
}

TEST(IdentifyTest, NoiselessPaperMethodFindsThePoles) {
  // The paper's method on the same record: with the effective rank at the signal order (7 =
  // 2 x 3 modes + the constant) the minimum-norm prediction puts the extra roots inside the unit
  // circle and the signal roots exactly on the poles. Truncating at a rank is less exact than
  // the refinement: 1e-6 (measured ~1e-9).
  const SignalSpec spec = ThreeModes();
  IdentificationOptions options;
  options.method = Method::kPronySvd;
  options.prony.order = 10;             // p: 20 roots for 3 modes and a constant
  options.prony.rank_tolerance = 1e-8;  // round-off of the noiseless regression matrix is ~1e-13
  const ModalResult result = Identify(MakeRecord(spec, Synthesize(spec)), options);
  EXPECT_EQ(result.effective_rank, 7);  // 2 x 3 modes + constant
  ExpectModes(result, spec, 1e-6, 1e-5, 1e-5);
}

// The defects of the paper's method on a noiseless record, each fixed: at the default
// p = 40 (80 roots for 3 modes), whether step 3 truncates at the round-off rank or not, the 77
// roots that are not modes carry round-off amplitudes (~1e-12 of the record) that the residual
// of a noiseless fit (round-off too) once called significant. They are never significant now.
TEST(IdentifyTest, PaperMethodNeverCallsRoundOffAMode) {
  const SignalSpec spec = ThreeModes();
  for (const double noise_floor_factor : {1.5, 0.0}) {
    IdentificationOptions options;
    options.method = Method::kPronySvd;
    options.prony.noise_floor_factor = noise_floor_factor;
    const ModalResult result = Identify(MakeRecord(spec, Synthesize(spec)), options);
    ExpectModes(result, spec, 1e-6, 1e-5, 1e-5);  // as NoiselessPaperMethodFindsThePoles
    for (const IdentifiedMode& mode : result.modes) EXPECT_TRUE(mode.significant);
  }
}

// Step 3's threshold must not depend on the unit the record is written in: the column of ones
// (B0) is scaled to the data, so micro-radians and kilo-radians give the same effective rank and
// the same poles.
TEST(IdentifyTest, PaperMethodIsIndependentOfTheRecordsUnit) {
  const SignalSpec spec = ThreeModes();
  IdentificationOptions options;
  options.method = Method::kPronySvd;
  options.prony.order = 10;
  std::vector<ModalResult> results;
  for (const double unit : {1e-6, 1.0, 1e3}) {
    Measurement record = MakeRecord(spec, Synthesize(spec));
    record.values *= unit;
    results.push_back(Identify(record, options));
  }
  for (const ModalResult& result : results) {
    EXPECT_EQ(result.effective_rank, 7);  // 2 x 3 modes + the constant
    ASSERT_EQ(result.modes.size(), 3u);
    for (size_t k = 0; k < 3; ++k) {
      // Round-off of a rank-7 truncation of differently scaled but equal data: 1e-9.
      EXPECT_NEAR(std::abs(result.modes[k].lambda - results[1].modes[k].lambda) /
                      std::abs(results[1].modes[k].lambda),
                  0.0, 1e-9);
    }
  }
}

// max_modes is exact and the warning counts the candidates it chose from.
TEST(IdentifyTest, PaperMethodKeepsExactlyMaxModes) {
  const SignalSpec spec = ThreeModes();
  IdentificationOptions options;
  options.method = Method::kPronySvd;
  options.prony.noise_floor_factor = 0;  // full rank: many candidate roots in the band
  options.drop_insignificant = false;    // keep what max_modes keeps, significant or not
  options.max_modes = 2;
  const ModalResult result = Identify(MakeRecord(spec, Synthesize(spec)), options);
  ASSERT_EQ(result.modes.size(), 2u);
  bool counted = false;
  for (const std::string& warning : result.warnings) {
    counted = counted || warning.find("kept the 2 most significant of") != std::string::npos;
  }
  EXPECT_TRUE(counted);
  // The two largest modes of the record (amplitudes 1.0 and 0.5 against 0.4 at 7.3 Hz).
  EXPECT_NEAR(result.modes[0].frequency_hz, 0.8, 1e-6);
  EXPECT_NEAR(result.modes[1].frequency_hz, 2.5, 1e-6);
}

// Ten seeded records of the paper's four modes (Table 1 amplitudes, 100 Hz, 10 s) at 30 dB SNR
// per channel. Issue 4 asks for every frequency within 1 % and every decay within 10 %. The
// Cramer-Rao bound of mode 1's frequency at 30 dB is itself 1.07 % (computed below), so for
// that one mode "within 1 %" holds for the mean of the ten estimates (standard deviation
// 0.34 %), and each single estimate is held to 4 sigma of the bound.
TEST(IdentifyTest, PaperTableOneAt30Db) {
  const SignalSpec spec = PaperSignal();
  const Eigen::MatrixXd clean = Synthesize(spec);
  const Eigen::VectorXd noise_std = testing::NoiseStd(clean, 30);
  const auto bound = CramerRaoBound(spec, noise_std);
  EXPECT_NEAR(bound[0].second / spec.modes[0].frequency_hz, 0.0107, 0.0005);  // as stated above
  std::mt19937_64 rng(4);  // seeded: deterministic
  constexpr int kRecords = 10;
  std::vector<double> mean_frequency(4, 0.0);
  for (int record = 0; record < kRecords; ++record) {
    const Eigen::MatrixXd noisy = testing::AddNoise(clean, noise_std, &rng);
    const ModalResult result = Identify(MakeRecord(spec, noisy), IdentificationOptions());
    ASSERT_EQ(result.modes.size(), 4u) << "four modes, no spurious one, record " << record;
    for (size_t k = 0; k < 4; ++k) {
      const auto& truth = spec.modes[k];
      const IdentifiedMode& mode = result.modes[k];
      EXPECT_NEAR(mode.decay_rate_per_s, truth.decay_per_s, 0.10 * truth.decay_per_s);
      EXPECT_NEAR(mode.frequency_hz, truth.frequency_hz,
                  k == 0 ? 4 * bound[0].second : 0.01 * truth.frequency_hz);
      EXPECT_TRUE(mode.significant);
      mean_frequency[k] += mode.frequency_hz / kRecords;
    }
    // The paper reports K >= 0.88 on its real record; a noise level of 30 dB leaves ~0.999.
    for (int c = 0; c < 2; ++c) EXPECT_GT(result.correlation(c), 0.99);
    // A record the modes explain: nothing to flag.
    EXPECT_TRUE(result.reliable) << (result.reasons.empty() ? "" : result.reasons.front());
  }
  for (size_t k = 0; k < 4; ++k) {
    EXPECT_NEAR(mean_frequency[k], spec.modes[k].frequency_hz, 0.01 * spec.modes[k].frequency_hz);
  }
}

// Expects each identified pole within `sigmas` Cramer-Rao standard deviations of the truth.
void ExpectWithinBound(const ModalResult& result, const SignalSpec& spec,
                       const Eigen::VectorXd& noise_std, double sigmas) {
  const auto bound = CramerRaoBound(spec, noise_std);
  ASSERT_EQ(result.modes.size(), spec.modes.size());
  for (size_t k = 0; k < spec.modes.size(); ++k) {
    EXPECT_NEAR(result.modes[k].frequency_hz, spec.modes[k].frequency_hz, sigmas * bound[k].second)
        << "mode " << k;
    EXPECT_NEAR(result.modes[k].decay_rate_per_s, spec.modes[k].decay_per_s,
                sigmas * bound[k].first)
        << "mode " << k;
  }
}

// Two modes 1 % apart in frequency (Fourier resolution of the 10 s record is 0.1 Hz, five times
// their 0.02 Hz spacing), seen with different mixing in two channels, at 40 dB.
TEST(IdentifyTest, CloselySpacedModes) {
  SignalSpec spec;
  spec.channels = {"a", "b"};
  spec.sample_interval_s = 0.01;
  spec.samples = 1000;
  spec.modes = {{2.00, 0.30, {1.0, 0.5}, {0.2, 1.0}}, {2.02, 0.30, {0.8, 1.0}, {-1.3, 2.4}}};
  const Eigen::MatrixXd clean = Synthesize(spec);
  const Eigen::VectorXd noise_std = testing::NoiseStd(clean, 40);
  std::mt19937_64 rng(11);  // seeded: deterministic
  const ModalResult result = Identify(MakeRecord(spec, testing::AddNoise(clean, noise_std, &rng)),
                                      IdentificationOptions());
  // 4 sigma: a single record; the probability of a larger deviation is 6e-5.
  ExpectWithinBound(result, spec, noise_std, 4);
}

// A mode with damping ratio 0.8 (decays by e^-1 in 0.1 s, less than a period) beside a lightly
// damped one, at 40 dB; both must be found and kept (issue 4).
TEST(IdentifyTest, HeavilyDampedModeIsKept) {
  const double zeta = 0.8;
  const double omega_n = 2 * M_PI * 2.0;  // 2 Hz undamped
  SignalSpec spec;
  spec.channels = {"a"};
  spec.sample_interval_s = 0.005;  // 200 Hz: 20 samples per e-fold of the heavy mode
  spec.samples = 1000;             // 5 s
  spec.modes = {{omega_n * std::sqrt(1 - zeta * zeta) / (2 * M_PI), zeta * omega_n, {1.0}, {0.5}},
                {3.0, 0.5, {0.3}, {-1.0}}};
  const Eigen::MatrixXd clean = Synthesize(spec);
  const Eigen::VectorXd noise_std = testing::NoiseStd(clean, 40);
  std::mt19937_64 rng(5);  // seeded: deterministic
  const ModalResult result = Identify(MakeRecord(spec, testing::AddNoise(clean, noise_std, &rng)),
                                      IdentificationOptions());
  ExpectWithinBound(result, spec, noise_std, 4);  // 4 sigma as above
  ASSERT_EQ(result.modes.size(), 2u);
  EXPECT_NEAR(result.modes[0].damping_ratio, zeta, 0.02);  // 4 sigma of the bound is ~0.01
}

// An undamped 2 Hz sine, 10 s at 100 Hz, with noise of 0.3 of its amplitude: the decay rate's
// standard deviation (about 0.005 1/s) holds 0, and the estimate falls on either side. A
// negative one within its std passed as determined (the rule asked std < decay only for
// positive decays; a trial's -0.02 +- 0.016 1/s was "reliable"); its sign is not determined.
TEST(IdentifyTest, ADecayOfEitherSignWithinItsStdIsUndetermined) {
  SignalSpec spec;
  spec.channels = {"a"};
  spec.sample_interval_s = 0.01;
  spec.samples = 1000;
  spec.modes = {{2.0, 0.0, {1.0}, {0.3}}};
  const Eigen::MatrixXd clean = Synthesize(spec);
  int negative = 0;
  for (std::uint64_t seed = 1; seed <= 8; ++seed) {
    std::mt19937_64 rng(seed);
    const ModalResult result = Identify(
        MakeRecord(spec, testing::AddNoise(clean, Eigen::VectorXd::Constant(1, 0.3), &rng)),
        IdentificationOptions());
    ASSERT_EQ(result.modes.size(), 1u) << "seed " << seed;
    const IdentifiedMode& mode = result.modes[0];
    if (mode.decay_rate_per_s < 0) ++negative;
    if (std::abs(mode.decay_rate_per_s) < mode.std_decay_rate_per_s) {
      EXPECT_FALSE(result.reliable) << "seed " << seed << ": " << mode.decay_rate_per_s;
      EXPECT_TRUE(testing::Mentions(result.reasons, "the decay rate of the mode at"))
          << "seed " << seed << ": " << ::testing::PrintToString(result.reasons);
    }
  }
  EXPECT_GE(negative, 2);  // measured: 3 of 8 (the sign is a coin)
}

// A trial's case: one sensor logged in two channels (the second 1.1 times the first): 2 and
// 5.5 Hz, noise 0.02. Their noise is one noise, which the standard deviations (computed for
// independent channels) take for two: z rms 1.6 over 30 seeds (3.4 with 8 copies), all
// "reliable". The residuals' correlation says so; independent noise in the same two channels
// leaves them reliable.
TEST(IdentifyTest, NoiseSharedByChannelsIsSaid) {
  SignalSpec spec;
  spec.channels = {"a", "b"};
  spec.sample_interval_s = 0.01;
  spec.samples = 2000;
  spec.modes = {{2.0, 0.15, {1.0, 1.1}, {0.0, 0.0}}, {5.5, 0.3, {0.5, 0.55}, {0.0, 0.0}}};
  const Eigen::MatrixXd clean = Synthesize(spec);
  std::mt19937_64 rng(4);
  IdentificationOptions options;
  options.release = ReleaseMode::kNone;
  const Eigen::MatrixXd independent = testing::AddNoise(clean, Eigen::Vector2d(0.02, 0.022), &rng);
  const ModalResult apart = Identify(MakeRecord(spec, independent), options);
  EXPECT_TRUE(apart.reliable) << ::testing::PrintToString(apart.reasons);
  Eigen::MatrixXd copies = independent;
  copies.col(1) = 1.1 * copies.col(0);
  const ModalResult shared = Identify(MakeRecord(spec, copies), options);
  EXPECT_FALSE(shared.reliable);
  EXPECT_TRUE(testing::Mentions(shared.reasons, "the residuals of channels a and b are correlated"))
      << ::testing::PrintToString(shared.reasons);
}

// A sine growing at 0.05 1/s (by e^0.5 over 10 s), 60 dB above the noise: identified to its
// std, and said to grow, which no free decay of a passive machine does.
TEST(IdentifyTest, AGrowingModeIsSaidToGrow) {
  SignalSpec spec;
  spec.channels = {"a"};
  spec.sample_interval_s = 0.01;
  spec.samples = 1000;
  spec.modes = {{2.0, -0.05, {1.0}, {0.3}}};
  const ModalResult result = Identify(
      MakeRecord(spec, testing::SynthesizeNoisy(spec, Eigen::VectorXd::Constant(1, 1e-3), 1)),
      IdentificationOptions());
  ASSERT_EQ(result.modes.size(), 1u);
  EXPECT_NEAR(result.modes[0].decay_rate_per_s, -0.05, 4 * result.modes[0].std_decay_rate_per_s);
  EXPECT_TRUE(testing::Mentions(result.warnings, "the mode at 2 Hz grows"))
      << ::testing::PrintToString(result.warnings);
}

// ---- options --------------------------------------------------------------------------

TEST(IdentifyTest, TimeWindowAndChannelSelection) {
  SignalSpec spec = ThreeModes();
  Measurement record = MakeRecord(spec, Synthesize(spec));
  record.start_time_s = 2.0;  // the window is in the record's own time
  IdentificationOptions options;
  options.channels = {"b"};
  options.window_start_s = 3.0;  // skips 1 s = 200 samples
  options.window_end_s = 8.0;    // 5 s after the start; the record ends at 9.495 s
  const ModalResult result = Identify(record, options);
  ASSERT_EQ(result.channels, std::vector<std::string>{"b"});
  EXPECT_EQ(result.samples, 1001);  // 5 s at 200 Hz, both ends included
  EXPECT_DOUBLE_EQ(result.start_time_s, 3.0);
  ASSERT_EQ(result.modes.size(), 3u);
  // Amplitudes and phases refer to the window's first sample, 1 s into the signal: each mode's
  // amplitude has decayed by exp(-decay * 1 s) and its phase advanced by omega * 1 s.
  for (size_t k = 0; k < 3; ++k) {
    const auto& truth = spec.modes[k];
    const double t = 1.0;
    EXPECT_NEAR(result.modes[k].amplitude(0), truth.amplitude[1] * std::exp(-truth.decay_per_s * t),
                1e-6 * truth.amplitude[1]);  // noiseless: round-off only
    EXPECT_NEAR(std::remainder(result.modes[k].phase_rad(0) - truth.phase_rad[1] -
                                   2 * M_PI * truth.frequency_hz * t,
                               2 * M_PI),
                0.0, 1e-6);
  }
}

TEST(IdentifyTest, OffsetRemovalOptions) {
  const SignalSpec spec = ThreeModes();  // offsets 0.1 and -0.02
  const Measurement record = MakeRecord(spec, Synthesize(spec));
  IdentificationOptions options;
  options.offset = OffsetRemoval::kFit;  // estimated with the modes: exact
  EXPECT_NEAR(Identify(record, options).offset(0), 0.1, 1e-9);
  // kMean subtracts the window mean, which also contains the modes' mean: the record is then
  // no longer a sum of decaying modes, so the poles are only approximate and the reported
  // offset is the mean itself.
  options.offset = OffsetRemoval::kMean;
  const ModalResult mean = Identify(record, options);
  EXPECT_DOUBLE_EQ(mean.offset(0), record.values.col(0).mean());
  // kNone: the constant is an unmodelled component; it cannot be a mode (a real pole at 0 Hz).
  options.offset = OffsetRemoval::kNone;
  const ModalResult none = Identify(record, options);
  EXPECT_EQ(none.offset(0), 0.0);
  for (const IdentifiedMode& mode : none.modes) EXPECT_GT(mode.frequency_hz, 0.1);
}

TEST(IdentifyTest, DecimationKeepsThePoles) {
  // The paper's signal sampled at 400 Hz and decimated by 4 to 100 Hz: the filter maps each
  // mode z^j to H(z) z^j, so poles stay exact on noiseless data; amplitudes come from the
  // full-rate record.
  SignalSpec spec = PaperSignal();
  spec.sample_interval_s = 0.0025;
  spec.samples = 4000;
  IdentificationOptions options;
  options.decimation = 4;
  const ModalResult result = Identify(MakeRecord(spec, Synthesize(spec)), options);
  EXPECT_EQ(result.samples, 4000);
  EXPECT_EQ(result.decimation, 4);
  ExpectModes(result, spec, 1e-7, 1e-5, 1e-5);  // measured ~1e-10; filter round-off
}

TEST(IdentifyTest, StabilizationDataMarksTheTruePolesStable) {
  const SignalSpec spec = ThreeModes();
  const ModalResult result = Identify(MakeRecord(spec, Synthesize(spec)), IdentificationOptions());
  ASSERT_FALSE(result.stabilization.empty());
  // At the signal order (7: three pairs and the constant) every true pole is present and
  // stable (it reappears at order 9).
  const auto at_order = std::find_if(result.stabilization.begin(), result.stabilization.end(),
                                     [](const StabilizationOrder& o) { return o.order == 7; });
  ASSERT_NE(at_order, result.stabilization.end());
  for (const auto& truth : spec.modes) {
    const std::complex<double> lambda(-truth.decay_per_s, 2 * M_PI * truth.frequency_hz);
    bool found = false;
    for (size_t i = 0; i < at_order->lambda.size(); ++i) {
      if (std::abs(at_order->lambda[i] - lambda) < 1e-6 * std::abs(lambda)) {
        found = true;
        EXPECT_TRUE(at_order->stable[i]);
      }
    }
    EXPECT_TRUE(found) << truth.frequency_hz << " Hz";
  }
  EXPECT_EQ(result.effective_rank, 7);
}

TEST(IdentifyTest, InsignificantModesAreFlaggedWhenKept) {
  // A third mode 1e-5 of the others' amplitude, below the noise: with drop_insignificant off it
  // may be kept, but only flagged.
  SignalSpec spec = ThreeModes();
  spec.modes[2].amplitude = {1e-6, 1e-6};
  const Eigen::MatrixXd clean = Synthesize(spec);
  std::mt19937_64 rng(3);  // seeded: deterministic
  const Eigen::MatrixXd noisy = testing::AddNoise(clean, Eigen::Vector2d(1e-3, 1e-3), &rng);
  IdentificationOptions options;
  options.drop_insignificant = false;
  options.hankel.noise_floor_factor = 1.0;  // let noise into the candidates on purpose
  const ModalResult result = Identify(MakeRecord(spec, noisy), options);
  int flagged = 0;
  for (const IdentifiedMode& mode : result.modes) {
    flagged += mode.significant ? 0 : 1;
    EXPECT_EQ(mode.significant, mode.significance >= result.significance_threshold);
    if (std::abs(mode.frequency_hz - 0.8) > 0.05 && std::abs(mode.frequency_hz - 2.5) > 0.05) {
      EXPECT_FALSE(mode.significant) << mode.frequency_hz << " Hz";
    }
  }
  EXPECT_GT(flagged, 0);  // this seed lets noise modes through: the check above is not vacuous
}

TEST(IdentifyTest, SignChangingSequenceIsNotRefinedAsAMode) {
  // One 2 Hz mode plus 0.2 (-0.95)^j in channel a: a real negative discrete pole, a sequence
  // that changes sign at every sample. It is no oscillation the samples resolve (its sine column
  // vanishes), so it is no candidate mode: refined as one, it took 82 Levenberg-Marquardt
  // iterations (a weakly determined pole, linear convergence) before the significance test
  // dropped it; the one true mode alone converges in a few (4 measured, 10 allowed).
  SignalSpec spec;
  spec.channels = {"a", "b"};
  spec.sample_interval_s = 0.01;
  spec.samples = 1000;
  spec.modes = {{2.0, 0.5, {1.0, 0.5}, {0.3, 1.3}}};
  Eigen::MatrixXd values = Synthesize(spec);
  for (int j = 0; j < spec.samples; ++j) values(j, 0) += 0.2 * std::pow(-0.95, j);
  std::mt19937_64 rng(1);  // seeded: deterministic
  values = testing::AddNoise(values, Eigen::Vector2d(1e-3, 1e-3), &rng);
  IdentificationOptions options;
  options.release = ReleaseMode::kNone;
  const ModalResult result = Identify(MakeRecord(spec, values), options);
  ASSERT_EQ(result.modes.size(), 1u);
  const std::complex<double> truth(-0.5, 2 * M_PI * 2.0);
  // The sign-changing part is nearly orthogonal to the mode: the pole stays within 1e-3
  // (7e-5 measured; the noise alone gives about 3e-5).
  EXPECT_LE(std::abs(result.modes[0].lambda - truth) / std::abs(truth), 1e-3);
  EXPECT_LE(result.iterations, 10);
  // What the modes leave unexplained in channel a is 20x its noise: flagged, not hidden.
  EXPECT_FALSE(result.reliable);
}

// ---- bad input ------------------------------------------------------------------------

template <typename Error>
Error Catch(const Measurement& record, const IdentificationOptions& options) {
  try {
    Identify(record, options, "record.h5");
  } catch (const Error& e) {
    return e;
  } catch (const std::exception& e) {
    ADD_FAILURE() << "another exception: " << e.what();
    throw;
  }
  ADD_FAILURE() << "nothing thrown";
  throw std::logic_error("nothing thrown");
}

// The noiseless three modes scaled by 1e-50 and 1e50 are found as at scale 1 (the poles do not
// depend on the scale); at 1e-200 and 1e80 the analysis left a double's range: "no modes found",
// with a "-nan" in the reason at 1e-200; now a wrong unit said as such (exit 2).
TEST(IdentifyTest, ValuesBeyondWhatSquaresHoldAreRefusedAndOthersScaleFree) {
  const SignalSpec spec = ThreeModes();
  for (const double scale : {1e-50, 1e50}) {
    const ModalResult result =
        Identify(MakeRecord(spec, scale * Synthesize(spec)), IdentificationOptions());
    SignalSpec scaled = spec;
    for (auto& mode : scaled.modes) {
      for (double& a : mode.amplitude) a *= scale;
    }
    ExpectModes(result, scaled, 1e-8, 1e-6, 1e-6);
  }
  for (const double scale : {1e-200, 1e-70, 1e70, 1e80}) {
    const InputError error =
        Catch<InputError>(MakeRecord(spec, scale * Synthesize(spec)), IdentificationOptions());
    EXPECT_EQ(error.field(), "channel a");
    EXPECT_NE(error.expected().find("between 1e-60 and 1e60"), std::string::npos);
  }
}

TEST(IdentifyTest, NonFiniteSampleNamesChannelAndSample) {
  const SignalSpec spec = ThreeModes();
  Measurement record = MakeRecord(spec, Synthesize(spec));
  record.values(17, 1) = std::numeric_limits<double>::quiet_NaN();
  const InputError nan = Catch<InputError>(record, IdentificationOptions());
  EXPECT_EQ(nan.source(), "record.h5");
  EXPECT_EQ(nan.field(), "b");
  EXPECT_NE(nan.problem().find("sample 17"), std::string::npos) << nan.what();
  EXPECT_NE(nan.problem().find("NaN"), std::string::npos) << nan.what();
  record.values(17, 1) = std::numeric_limits<double>::infinity();
  EXPECT_NE(Catch<InputError>(record, IdentificationOptions()).problem().find("infinite"),
            std::string::npos);
}

// A dead sensor among live ones is left out with a warning (it stopped the whole analysis with
// exit 2); named on purpose, or alone, it is an input error.
TEST(IdentifyTest, AConstantChannelIsLeftOutUnlessItIsNamedOrAlone) {
  const SignalSpec spec = ThreeModes();
  Measurement record = MakeRecord(spec, Synthesize(spec));
  record.values.col(0).setConstant(0.25);
  const ModalResult without_a = Identify(record, IdentificationOptions(), "record.h5");
  EXPECT_EQ(without_a.channels, std::vector<std::string>{"b"});
  EXPECT_TRUE(testing::Mentions(without_a.warnings, "channel a is constant (0.25 in every"));
  EXPECT_EQ(without_a.modes.size(), spec.modes.size());  // channel b sees all three
  IdentificationOptions named;
  named.channels = {"a", "b"};
  const InputError constant = Catch<InputError>(record, named);
  EXPECT_EQ(constant.field(), "a");
  EXPECT_NE(constant.problem().find("constant"), std::string::npos) << constant.what();
  record.values.col(1).setZero();
  record.values.col(0).setZero();
  const InputError zero = Catch<InputError>(record, IdentificationOptions());
  EXPECT_NE(zero.problem().find("zero"), std::string::npos) << zero.what();
}

TEST(IdentifyTest, TooFewSamplesForTheOrder) {
  SignalSpec spec = ThreeModes();
  spec.samples = 100;
  IdentificationOptions options;
  options.method = Method::kPronySvd;  // p = 40, 2 channels: (2 + 1) 40 + 1 = 121 samples needed
  const InputError error = Catch<InputError>(MakeRecord(spec, Synthesize(spec)), options);
  EXPECT_EQ(error.field(), "samples");
  EXPECT_NE(error.expected().find("at least 121"), std::string::npos) << error.what();
  // The Hankel matrix needs 24; a window of 10 samples leaves too few.
  options.method = Method::kHankelNls;
  options.window_end_s = 0.045;  // 10 samples at 200 Hz
  EXPECT_EQ(Catch<InputError>(MakeRecord(spec, Synthesize(spec)), options).field(), "samples");
}

TEST(IdentifyTest, BandAboveNyquistIsAnInputError) {
  const SignalSpec spec = ThreeModes();  // 200 Hz: Nyquist 100 Hz
  IdentificationOptions options;
  options.max_frequency_hz = 120;
  const InputError error = Catch<InputError>(MakeRecord(spec, Synthesize(spec)), options);
  EXPECT_EQ(error.field(), "max_frequency_hz");
  EXPECT_NE(error.problem().find("Nyquist"), std::string::npos) << error.what();
  // Decimation by 4 lowers the Nyquist frequency to 25 Hz.
  options.max_frequency_hz = 30;
  options.decimation = 4;
  EXPECT_EQ(Catch<InputError>(MakeRecord(spec, Synthesize(spec)), options).field(),
            "max_frequency_hz");
}

TEST(IdentifyTest, UnknownChannelAndBadOptions) {
  const SignalSpec spec = ThreeModes();
  const Measurement record = MakeRecord(spec, Synthesize(spec));
  IdentificationOptions options;
  options.channels = {"psi"};
  const InputError channel = Catch<InputError>(record, options);
  EXPECT_EQ(channel.field(), "channels");
  EXPECT_NE(channel.expected().find("a, b"), std::string::npos) << channel.what();

  options = IdentificationOptions();
  options.max_damping_ratio = 1.5;
  std::string message;
  EXPECT_FALSE(options.IsValid(&message));
  EXPECT_NE(message.find("max_damping_ratio"), std::string::npos) << message;
  const InputError invalid = Catch<InputError>(record, options);
  EXPECT_EQ(invalid.source(), "identification options");
  EXPECT_EQ(invalid.field(), "max_damping_ratio");
  EXPECT_TRUE(IdentificationOptions().IsValid());
}

TEST(IdentifyTest, PureNoiseFindsNoModes) {
  SignalSpec spec = PaperSignal();
  std::mt19937_64 rng(9);  // seeded: deterministic
  for (Method method : {Method::kHankelNls, Method::kPronySvd}) {
    IdentificationOptions options;
    options.method = method;
    for (int record = 0; record < 5; ++record) {  // a few draws, each must fail the same way
      const Eigen::MatrixXd noise =
          testing::AddNoise(Eigen::MatrixXd::Zero(spec.samples, 2), Eigen::Vector2d(1, 2), &rng);
      const NumericalError error = Catch<NumericalError>(MakeRecord(spec, noise), options);
      EXPECT_EQ(error.stage(), "identification");
      EXPECT_EQ(error.reason().rfind("no modes found: ", 0), 0u) << error.what();
    }
  }
}

// Less than a cycle of a slow oscillation in the record (a trial's 0.02 Hz sine trend over
// 20 s, 0.4 of a cycle) fits as a "mode" as well as a trend: it came out as a reliable 0.021 Hz
// mode in 6 of 20 records. A mode that completes less than a cycle in the analysed record is
// said so, and the result is unreliable; the two true modes are still found.
TEST(IdentifyTest, AModeOfLessThanACycleInTheRecordIsNotReliable) {
  testing::SignalSpec spec;
  spec.channels = {"a", "b", "c"};
  spec.sample_interval_s = 0.02;  // 50 Hz, 20 s
  spec.samples = 1000;
  const double half_pi = M_PI / 2;
  spec.modes = {{0.8, 0.1005, {1.0, 0.5, -0.3}, {0, 0, 0}},
                {2.9, 0.2734, {0.3, -0.6, 0.8}, {0, 0, 0}},
                {0.02, 0.0, {0.05, 0.05, 0.05}, {-half_pi, -half_pi, -half_pi}}};  // the trend
  Eigen::MatrixXd values = testing::SynthesizeNoisy(spec, Eigen::VectorXd::Constant(3, 2e-3), 5);
  values.rowwise() += Eigen::RowVector3d(5.0, -3.0, 0.7);  // the sensors' zero offsets
  IdentificationOptions whole;
  whole.release = ReleaseMode::kNone;  // the record is the decay from its first sample
  const ModalResult result = Identify(testing::MakeRecord(spec, values), whole);
  EXPECT_FALSE(result.reliable);
  EXPECT_TRUE(testing::Mentions(result.reasons, "of a cycle in the analysed"))
      << ::testing::PrintToString(result.reasons);
  int found = 0;
  for (const IdentifiedMode& mode : result.modes) {
    found += std::abs(mode.frequency_hz - 0.8) < 0.01 || std::abs(mode.frequency_hz - 2.9) < 0.01;
  }
  EXPECT_EQ(found, 2);
}

// The refinement admits growth by e over the record at most (a decay of -1 / its duration): a
// component that grows faster ends at that bound, where its standard deviation means nothing
// (a numerically differentiated channel's end made a 31 Hz "mode" there, reliable, in trial
// records). A tone growing by e^2 over 20 s beside a decaying mode: said, not reliable.
TEST(IdentifyTest, AModeAtTheFitsGrowthLimitIsNotReliable) {
  testing::SignalSpec spec;
  spec.channels = {"x", "y"};
  spec.sample_interval_s = 0.01;  // 100 Hz, 20 s
  spec.samples = 2000;
  spec.modes = {{1.7, 0.107, {1.0, 0.5}, {0.0, 0.3}}, {31.0, -0.1, {0.02, 0.01}, {0.5, 1.0}}};
  IdentificationOptions whole;
  whole.release = ReleaseMode::kNone;
  const ModalResult result =
      Identify(testing::MakeRecord(
                   spec, testing::SynthesizeNoisy(spec, Eigen::VectorXd::Constant(2, 2e-3), 3)),
               whole);
  EXPECT_FALSE(result.reliable);
  EXPECT_TRUE(testing::Mentions(result.reasons, "grows at the fit's limit"))
      << ::testing::PrintToString(result.reasons);
}

}  // namespace
}  // namespace mbid::identification
