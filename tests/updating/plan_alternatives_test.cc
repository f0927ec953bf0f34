// Planning at alternative minima (updating/plan_alternatives.h) on the torsional oscillator
// (J = 2 kg m^2, c = 800 N m/rad, d = 8 N m s/rad), released from rest: the separation of the
// best from an alternative against the closed-form free decay, which candidate cannot tell them
// apart, and the worst score over the minima.
#include "mbid/updating/plan_alternatives.h"

#include <gtest/gtest.h>

#include <cmath>

#include "oscillator_fixture.h"

namespace mbid::updating {
namespace {

using testing::MakeOscillator;

constexpr double kInertia = 2.0;

// The closed-form free decay from rest at theta0 (underdamped).
double Angle(double t, double theta0, double c, double d) {
  const double a = d / (2 * kInertia);
  const double omega = std::sqrt(c / kInertia - a * a);
  return theta0 * std::exp(-a * t) * (std::cos(omega * t) + a / omega * std::sin(omega * t));
}

// sum_j ((theta_best(t_j) - theta_alternative(t_j)) / noise)^2 over 2 s at 100 Hz.
double ClosedFormSeparation(double theta0, double noise, double d_alternative) {
  double sum = 0;
  for (int j = 0; j <= 200; ++j) {
    const double t = j / 100.0;
    const double r = (Angle(t, theta0, 800, 8) - Angle(t, theta0, 800, d_alternative)) / noise;
    sum += r * r;
  }
  return sum;
}

TEST(PlanAlternativesTest, SeparationIsTheClosedFormChiSquareAndDecidesWhoCannotTell) {
  const auto oscillator = MakeOscillator();
  // The recorded test: a quiet release. An alternative 5% off in damping with a small cost
  // excess (as the global search would report one).
  const std::vector<TestDesign> recorded{testing::OscillatorRelease("recorded", 0.01, 1e-4)};
  const std::vector<PlanCandidate> candidates{
      {"quiet", nullptr, testing::OscillatorRelease("quiet", 0.01, 1e-4)},
      {"noisy", nullptr, testing::OscillatorRelease("noisy", 0.01, 0.5)}};
  PlanOptions options;
  const TestPlan at_best = PlanNextTest(*oscillator, recorded, candidates, options);
  AlternativeMinimumValues alternative;
  alternative.label = "design 3";
  alternative.values = {{"c_angle", 800.0}, {"d_angle", 8.4}};
  alternative.cost_excess = 0.5;
  const AlternativesPlan plan =
      PlanAtAlternatives(*oscillator, recorded, candidates, at_best, {alternative}, options,
                         /*residual_count=*/201, /*significance=*/0.05);
  ASSERT_EQ(plan.candidates.size(), 2u);
  ASSERT_EQ(plan.thresholds.size(), 1u);
  // k F(0.95; 2, ~400) = 2 x 3.02: the 2-parameter F-test of the global search.
  EXPECT_NEAR(plan.thresholds[0], 2 * 3.018, 0.01);
  const CandidateAtAlternatives& quiet = plan.candidates[0];
  const CandidateAtAlternatives& noisy = plan.candidates[1];
  EXPECT_EQ(quiet.name, "quiet");
  // CVODES (1e-8 relative) against the closed form: the difference of two decays 5% apart in
  // damping is ~1e-3 of the amplitude, so 1e-4 relative on its square is integration error
  // with margin.
  const double expected_quiet = ClosedFormSeparation(0.01, 1e-4, 8.4);
  EXPECT_NEAR(quiet.separation[0], expected_quiet, 1e-4 * expected_quiet);
  const double expected_noisy = ClosedFormSeparation(0.01, 0.5, 8.4);
  EXPECT_NEAR(noisy.separation[0], expected_noisy, 1e-4 * expected_noisy);
  // The quiet release separates them by ~150 (25 times the threshold); at 0.5 rad noise the
  // bound is ~6e-6 and with the recorded excess stays below a tenth of the threshold: that
  // candidate cannot tell them apart.
  EXPECT_GT(quiet.separation[0], 10 * plan.thresholds[0]);
  EXPECT_FALSE(quiet.cannot_separate[0]);
  EXPECT_LT(noisy.separation[0] + alternative.cost_excess, 0.1 * plan.thresholds[0]);
  EXPECT_TRUE(noisy.cannot_separate[0]);
  // Between them, noise giving a separation of ~2: below the threshold without noise (2 + 0.5
  // against 6.04), but the test's noise adds 2 d.e of std 2 sqrt(2) = 2.8, and its upper 5 %
  // point (2.5 + 1.645 x 2.8 = 7.2) is above it: the candidate may separate them, not certain.
  const AlternativesPlan middle = PlanAtAlternatives(
      *oscillator, recorded,
      {{"middle", nullptr, testing::OscillatorRelease("middle", 0.01, 8.7e-4)}},
      PlanNextTest(*oscillator, recorded,
                   {{"middle", nullptr, testing::OscillatorRelease("middle", 0.01, 8.7e-4)}},
                   options),
      {alternative}, options, 201, 0.05);
  const double separation = middle.candidates[0].separation[0];
  EXPECT_NEAR(separation, 2.0, 0.5);  // 150 x (1e-4 / 8.7e-4)^2
  EXPECT_LT(separation + alternative.cost_excess, middle.thresholds[0]);
  EXPECT_FALSE(middle.candidates[0].cannot_separate[0]);
  // Scores: one per alternative, and the worst is the lower of the best's and the alternative's.
  ASSERT_EQ(quiet.scores.size(), 1u);
  double at_best_quiet = 0;
  for (const CandidateScore& score : at_best.candidates) {
    if (score.name == "quiet") at_best_quiet = score.score;
  }
  EXPECT_DOUBLE_EQ(quiet.worst_score, std::min(at_best_quiet, quiet.scores[0]));
  // Higher damping decays faster and informs less about c: the score at d = 8.4 is lower.
  EXPECT_LT(quiet.scores[0], at_best_quiet);
}

}  // namespace
}  // namespace mbid::updating
