// identification.remove_drift (issue 13): a linear sensor drift fitted with the modes. On a
// closed-form decay with a known drift, the modes come out within their standard deviations of
// the truth with the option and biased without it (by more than those standard deviations).
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <random>

#include "mbid/identification/identify.h"
#include "mbid/identification/modal_result.h"

namespace mbid::identification {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDrift = 4e-4;  // rad/s: 4e-3 rad over the 10 s, 40 % of the low mode's start

struct TrueMode {
  double frequency_hz, decay_rate_per_s, amplitude;
};
constexpr TrueMode kModes[2] = {{0.8, 0.3, 0.01}, {3.1, 1.0, 0.005}};

// Two modes, an offset of 2e-3 rad, the drift, noise 1e-4 rad; 10 s at 50 Hz.
Measurement DriftingRecord(int seed) {
  Measurement record;
  record.channels = {"psi"};
  record.units = {"rad"};
  record.sample_interval_s = 0.02;
  record.values.resize(500, 1);
  std::mt19937_64 rng(static_cast<unsigned>(seed));
  std::normal_distribution<double> noise(0.0, 1e-4);
  for (int j = 0; j < 500; ++j) {
    const double t = j * 0.02;
    double y = 2e-3 + kDrift * t + noise(rng);
    for (const TrueMode& m : kModes) {
      y += m.amplitude * std::exp(-m.decay_rate_per_s * t) * std::cos(2 * kPi * m.frequency_hz * t);
    }
    record.values(j, 0) = y;
  }
  return record;
}

// The largest distance of an identified mode from the truth, in its standard deviations, over
// frequency and decay of both modes; infinity when the two modes are not found.
double WorstNormalizedError(const ModalResult& result) {
  double worst = 0;
  for (const TrueMode& truth : kModes) {
    const IdentifiedMode* nearest = nullptr;
    for (const IdentifiedMode& mode : result.modes) {
      if (nearest == nullptr || std::abs(mode.frequency_hz - truth.frequency_hz) <
                                    std::abs(nearest->frequency_hz - truth.frequency_hz)) {
        nearest = &mode;
      }
    }
    if (nearest == nullptr || std::abs(nearest->frequency_hz - truth.frequency_hz) > 0.2) {
      return std::numeric_limits<double>::infinity();
    }
    worst = std::max(
        worst, std::abs(nearest->frequency_hz - truth.frequency_hz) / nearest->std_frequency_hz);
    worst = std::max(worst, std::abs(nearest->decay_rate_per_s - truth.decay_rate_per_s) /
                                nearest->std_decay_rate_per_s);
  }
  return worst;
}

TEST(DriftTest, RemovingTheDriftLeavesTheModesWithinTheirStandardDeviations) {
  IdentificationOptions options;
  options.release = ReleaseMode::kNone;  // the record is the free decay
  options.compute_stabilization = false;
  IdentificationOptions removing = options;
  removing.remove_drift = true;
  int biased = 0;
  for (int seed = 1; seed <= 5; ++seed) {
    const Measurement record = DriftingRecord(seed);
    const ModalResult with = Identify(record, removing);
    // 4 standard deviations on each of 4 quantities: a chance failure in about 1 in 4000.
    EXPECT_LT(WorstNormalizedError(with), 4.0) << "seed " << seed;
    // The drift itself: a line's slope over 10 s at 1e-4 noise has a std of about 2e-6 rad/s;
    // what the modes take of it is smaller than 5 % of it.
    ASSERT_EQ(with.drift_per_s.size(), 1);
    EXPECT_NEAR(with.drift_per_s(0), kDrift, 0.05 * kDrift) << "seed " << seed;
    const ModalResult without = Identify(record, options);
    EXPECT_EQ(without.drift_per_s.size(), 0);
    // Without the option the modes absorb the drift: the low mode's frequency is off by more
    // than 4 of the standard deviations the drift-free fit reaches. Its own standard deviation,
    // inflated by the drift taken for noise, hides that bias; the residual does not (the result
    // is flagged unreliable).
    ASSERT_EQ(without.modes.size(), 2u) << "seed " << seed;
    ASSERT_EQ(with.modes.size(), 2u) << "seed " << seed;
    if (std::abs(without.modes[0].frequency_hz - kModes[0].frequency_hz) >
        4 * with.modes[0].std_frequency_hz) {
      ++biased;
    }
    EXPECT_FALSE(without.reliable) << "seed " << seed;
    EXPECT_TRUE(with.reliable) << "seed " << seed;
  }
  EXPECT_EQ(biased, 5);
}

TEST(DriftTest, TheDriftIsInTheJson) {
  IdentificationOptions options;
  options.release = ReleaseMode::kNone;
  options.remove_drift = true;
  const nlohmann::json json = ModalResultToJson(Identify(DriftingRecord(1), options));
  ASSERT_TRUE(json.contains("drift_per_s"));
  EXPECT_NEAR(json["drift_per_s"]["psi"].get<double>(), kDrift, 0.05 * kDrift);
  IdentificationOptions plain;
  plain.release = ReleaseMode::kNone;
  EXPECT_FALSE(ModalResultToJson(Identify(DriftingRecord(1), plain)).contains("drift_per_s"));
}

}  // namespace
}  // namespace mbid::identification
