// Backbones on request (identification.backbone: always | clusters | never) and the Hilbert
// transform's estimate of one (issue 13), on closed-form synthetic decays.
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <random>

#include "mbid/identification/hilbert_backbone.h"
#include "mbid/identification/identify.h"
#include "mbid/identification/modal_result.h"

namespace mbid::identification {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kTau = 0.002;     // 500 Hz
constexpr int kSamples = 4000;     // 8 s
constexpr double kF0 = 10.0;       // Hz, the small-amplitude frequency
constexpr double kDuffing = 0.03;  // f(a) = f0 (1 + k a^2): 3 % stiffer at a = 1
constexpr double kDecay = 0.5;     // 1/s: a(t) = e^{-0.5 t}

double DuffingFrequency(double amplitude) { return kF0 * (1 + kDuffing * amplitude * amplitude); }

// A hardening mode, f(a) = f0 (1 + k a^2) with a(t) = e^{-beta t}: the phase is the integral of
// 2 pi f(a(t)), summed sample by sample (exact to the trapezoid's O(tau^2 f')); noise 1e-4 (80 dB
// below the start, 45 dB at the end).
Measurement DuffingRecord() {
  Measurement record;
  record.channels = {"a"};
  record.units = {"rad"};
  record.sample_interval_s = kTau;
  record.values.resize(kSamples, 1);
  std::mt19937_64 rng(13);
  std::normal_distribution<double> noise(0.0, 1e-4);
  double phase = 0;
  for (int j = 0; j < kSamples; ++j) {
    const double amplitude = std::exp(-kDecay * j * kTau);
    record.values(j, 0) = amplitude * std::cos(phase) + noise(rng);
    const double next = std::exp(-kDecay * (j + 1) * kTau);
    phase += kPi * (DuffingFrequency(amplitude) + DuffingFrequency(next)) * kTau;
  }
  return record;
}

// Two linear modes (2 and 7 Hz, decays 0.3 and 0.9 1/s) in two channels, noise 1e-4.
Measurement LinearRecord() {
  Measurement record;
  record.channels = {"a", "b"};
  record.units = {"rad", "rad"};
  record.sample_interval_s = 0.01;
  record.values.resize(1500, 2);
  std::mt19937_64 rng(5);
  std::normal_distribution<double> noise(0.0, 1e-4);
  for (int j = 0; j < 1500; ++j) {
    const double t = j * 0.01;
    const double m1 = 0.02 * std::exp(-0.3 * t) * std::cos(2 * kPi * 2 * t);
    const double m2 = 0.01 * std::exp(-0.9 * t) * std::cos(2 * kPi * 7 * t + 0.5);
    record.values(j, 0) = m1 + m2 + noise(rng);
    record.values(j, 1) = 0.5 * m1 - m2 + noise(rng);
  }
  return record;
}

TEST(HilbertBackboneTest, FollowsADuffingBackboneInClosedForm) {
  const Measurement record = DuffingRecord();
  const BackboneCurve curve =
      CalcHilbertBackbone(record.values.col(0), kTau, 0.0, DuffingFrequency(0.5), 1e-4);
  // 8 s less 3 periods at each end in 0.4 s windows, half overlapping: 37; the noise stops it
  // earlier only below an amplitude of 10 times the band's noise (about 5e-4 here).
  ASSERT_GE(curve.frequency_hz.size(), 30u);
  for (size_t i = 0; i < curve.frequency_hz.size(); ++i) {
    const double t = curve.time_s[i];
    // The amplitude at the window's centre is e^{-beta t}: the mean of ln a over the window is
    // exactly the value at the centre; the noise's share is below 1e-3 of it.
    EXPECT_NEAR(curve.amplitude[i], std::exp(-kDecay * t), 1e-3 * std::exp(-kDecay * t) + 1e-4)
        << i;
    // The frequency against the curve at the estimated amplitude. The window's phase slope is a
    // weighted mean of f over 0.4 s, where the drift term f0 k a^2 (at most 0.3 Hz) changes by
    // e^{-2 beta t}: its curvature moves the mean by (2 beta W)^2 / 24 = 0.7 % of the term,
    // 0.002 Hz. Allowed: that plus 4 standard deviations.
    const double truth = DuffingFrequency(curve.amplitude[i]);
    EXPECT_NEAR(curve.frequency_hz[i], truth, 0.002 + 4 * curve.std_frequency_hz[i])
        << i << " at amplitude " << curve.amplitude[i];
    EXPECT_GT(curve.std_frequency_hz[i], 0) << i;
    // Damping ratio beta / |lambda| with the frequency of the moment: to 1 % (ln a is a straight
    // line of slope -beta; the noise's share is smaller) plus 4 standard deviations.
    const double omega = 2 * kPi * truth;
    const double zeta = kDecay / std::hypot(omega, kDecay);
    EXPECT_NEAR(curve.damping_ratio[i], zeta, 0.01 * zeta + 4 * curve.std_damping_ratio[i]) << i;
  }
  // The estimate does follow the drift: from the first window to the last the frequency falls
  // by most of the 3 % the curve gives between a = 1 and 0.
  EXPECT_GT(curve.frequency_hz.front() - curve.frequency_hz.back(), 0.5 * kF0 * kDuffing);
}

TEST(HilbertBackboneTest, StandardDeviationsMatchTheScatterOfANoisyLinearMode) {
  // A linear mode (10 Hz, decay 0.2/s) at a noise of 1e-2 of its start: over 20 records the
  // windows' frequencies scatter about the truth as their standard deviations say, to a factor
  // of 2 either way (the correlation count of the band is approximate).
  double sum_squares = 0;
  int count = 0;
  for (int seed = 0; seed < 20; ++seed) {
    std::mt19937_64 rng(static_cast<unsigned>(seed));
    std::normal_distribution<double> noise(0.0, 1e-2);
    Eigen::VectorXd x(kSamples);
    for (int j = 0; j < kSamples; ++j) {
      const double t = j * kTau;
      x[j] = std::exp(-0.2 * t) * std::cos(2 * kPi * 10 * t) + noise(rng);
    }
    const BackboneCurve curve = CalcHilbertBackbone(x, kTau, 0.0, 10.0, 1e-2);
    for (size_t i = 0; i < curve.frequency_hz.size(); ++i) {
      sum_squares += std::pow((curve.frequency_hz[i] - 10.0) / curve.std_frequency_hz[i], 2);
      ++count;
    }
  }
  ASSERT_GT(count, 100);
  const double normalized_rms = std::sqrt(sum_squares / count);
  EXPECT_GT(normalized_rms, 0.5);
  EXPECT_LT(normalized_rms, 2.0);
}

TEST(BackboneOptionTest, DuffingModeHasBothEstimatesInTheResultAndItsJson) {
  const ModalResult result = Identify(DuffingRecord(), IdentificationOptions());
  // The default (clusters): the drifting mode is merged and carries its backbone, with the
  // Hilbert estimate beside the sliding windows.
  ASSERT_EQ(result.modes.size(), 1u);
  ASSERT_TRUE(result.modes[0].backbone.has_value());
  const Backbone& backbone = *result.modes[0].backbone;
  EXPECT_TRUE(backbone.amplitude_dependent);
  ASSERT_TRUE(backbone.hilbert.has_value());
  for (size_t i = 0; i < backbone.frequency_hz.size(); ++i) {
    // The sliding windows (8 periods, 0.8 s): curvature 2.7 % of the 0.3 Hz term, 0.008 Hz.
    EXPECT_NEAR(backbone.frequency_hz[i], DuffingFrequency(backbone.amplitude[i]),
                0.008 + 4 * backbone.std_frequency_hz[i])
        << i;
  }
  const nlohmann::json json = ModalResultToJson(result);
  const nlohmann::json& hilbert = json["modes"][0]["backbone"]["hilbert"];
  EXPECT_EQ(hilbert["frequency_hz"].size(), backbone.hilbert->frequency_hz.size());
  EXPECT_EQ(hilbert["std_damping_ratio"].size(), backbone.hilbert->frequency_hz.size());
}

TEST(BackboneOptionTest, AlwaysGivesEveryModeItsBackboneAndNeverNone) {
  const Measurement record = LinearRecord();
  IdentificationOptions options;
  // Default: a linear record's modes have no backbone (the behaviour before the option).
  const ModalResult plain = Identify(record, options);
  ASSERT_EQ(plain.modes.size(), 2u);
  for (const IdentifiedMode& mode : plain.modes) EXPECT_FALSE(mode.backbone.has_value());

  options.backbone = BackboneMode::kAlways;
  const ModalResult always = Identify(record, options);
  ASSERT_EQ(always.modes.size(), 2u);
  const double truth[2] = {2.0, 7.0};
  for (size_t k = 0; k < 2; ++k) {
    // The same modes as without backbones.
    EXPECT_EQ(always.modes[k].frequency_hz, plain.modes[k].frequency_hz) << k;
    ASSERT_TRUE(always.modes[k].backbone.has_value()) << k;
    const Backbone& b = *always.modes[k].backbone;
    ASSERT_GE(b.frequency_hz.size(), 3u) << k;
    // A linear mode: its windows agree with one frequency (the option does not invent drift).
    EXPECT_FALSE(b.amplitude_dependent) << k << " chi2/dof " << b.spread_chi_square_per_dof;
    ASSERT_TRUE(b.hilbert.has_value()) << k;
    for (size_t i = 0; i < b.hilbert->frequency_hz.size(); ++i) {
      // The damped frequency is the record's (decay 0.3 and 0.9 1/s leave it within 1e-3 Hz);
      // within 5 standard deviations.
      EXPECT_NEAR(b.hilbert->frequency_hz[i], truth[k], 1e-3 + 5 * b.hilbert->std_frequency_hz[i])
          << k << " " << i;
    }
  }
  const nlohmann::json json = ModalResultToJson(always);
  EXPECT_TRUE(json["modes"][1].contains("backbone"));

  // never: the drifting mode is not merged, so its cluster of close poles stays (and the result
  // says the modes are too close to tell apart), without backbones.
  options.backbone = BackboneMode::kNever;
  const ModalResult never = Identify(DuffingRecord(), options);
  EXPECT_GE(never.modes.size(), 2u);
  for (const IdentifiedMode& mode : never.modes) EXPECT_FALSE(mode.backbone.has_value());
  EXPECT_FALSE(never.reliable);
}

TEST(BackboneOptionTest, NamesRoundTrip) {
  for (const char* name : {"clusters", "always", "never"}) {
    BackboneMode mode = BackboneMode::kNever;
    ASSERT_TRUE(ParseBackboneMode(name, &mode)) << name;
    EXPECT_EQ(BackboneModeName(mode), name);
  }
  BackboneMode mode = BackboneMode::kAlways;
  EXPECT_FALSE(ParseBackboneMode("sometimes", &mode));
  EXPECT_EQ(mode, BackboneMode::kAlways);
}

TEST(BackboneDriftTest, ADriftOfAFewPartsInTenThousandIsPrintedSoItShows) {
  BackboneCurve curve;
  // 1.32913 .. 1.32941 Hz: equal to 4 digits ("1.329 to 1.329 Hz" told the user nothing), apart
  // at 5; the drift is 0.00028 / 1.32941 = 0.021 %.
  curve.frequency_hz = {1.32941, 1.32930, 1.32913};
  EXPECT_EQ(DescribeDrift(curve), "1.3291 to 1.3294 Hz, 0.021 %");
  // A drift that four digits show keeps four.
  curve.frequency_hz = {16.12, 15.9};
  EXPECT_EQ(DescribeDrift(curve), "15.9 to 16.12 Hz, 1.4 %");
}

}  // namespace
}  // namespace mbid::identification
