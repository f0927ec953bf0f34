// The global search's probe of a start's cost (global_search_internal.h): far starts are
// decided on the records' first tenth, which bounds the cost from below only where the noise is
// given and no baseline is projected out; elsewhere the whole records are simulated. And the
// screens' looser integration.
#include <gtest/gtest.h>

#include <limits>

#include "crane_fixture.h"
#include "global_search_internal.h"
#include "output_error_fit.h"

namespace mbid::updating::internal {
namespace {

using testing::Crane;
using testing::LoadCrane;

struct Probe {
  Crane crane = LoadCrane(testing::kLoadDropScenario);
  TestRecord test;
  UpdateOptions options;
  Probe() {
    // 301 samples: the first tenth is 50 (Window's least).
    test = testing::SimulateTest(crane, "load drop", 3.0);
    // A far start: every stiffness 30% high, as a space-filling point would be.
    options = testing::FitFromOff(crane, testing::kStiffnesses, 1.3, 1.0);
  }
};

TEST(StartProbeTest, AFarStartIsDecidedOnTheFirstTenthOfTheRecord) {
  const Probe probe;
  ASSERT_EQ(probe.test.noise_std.size(), probe.test.record.channels.size());
  const double whole = CalcStartCost(*probe.crane.model, {probe.test}, probe.options);
  const double prefix =
      CalcStartCost(*probe.crane.model, Window({probe.test}, kProbePrefix), probe.options);
  // A sum of fixed squares: the first 50 samples' part is below the whole, and well below here
  // (the far start misses every sample).
  ASSERT_LT(prefix, 0.5 * whole);
  // Above the limit there already: the prefix's cost is the answer, the rest is not simulated.
  EXPECT_EQ(CalcStartCostUpTo(*probe.crane.model, {probe.test}, probe.options, 0.5 * prefix),
            prefix);
  // Below the limit there: the whole records decide, to the bit.
  EXPECT_EQ(CalcStartCostUpTo(*probe.crane.model, {probe.test}, probe.options, 2 * prefix), whole);
  EXPECT_EQ(CalcStartCostUpTo(*probe.crane.model, {probe.test}, probe.options,
                              std::numeric_limits<double>::infinity()),
            whole);
}

TEST(StartProbeTest, NoShortcutWhereThePrefixIsNoLowerBound) {
  Probe probe;
  // Offsets projected out: the first tenth's own offsets could fit it better or worse.
  TestRecord with_offsets = probe.test;
  with_offsets.fit_offsets = true;
  EXPECT_EQ(CalcStartCostUpTo(*probe.crane.model, {with_offsets}, probe.options, 0.0),
            CalcStartCost(*probe.crane.model, {with_offsets}, probe.options));
  // A channel's noise not given: its weight comes from the record's spread, which the first
  // tenth does not share.
  TestRecord without_noise = probe.test;
  without_noise.noise_std.erase(without_noise.noise_std.begin());
  EXPECT_EQ(CalcStartCostUpTo(*probe.crane.model, {without_noise}, probe.options, 0.0),
            CalcStartCost(*probe.crane.model, {without_noise}, probe.options));
}

TEST(ScreeningTest, LoosensEveryToleranceByOneFactorOnlyWhereTheFitsAreTighter) {
  UpdateOptions options;
  options.integrator.relative_tolerance = 1e-8;
  options.integrator.absolute_tolerance = 1e-10;
  options.sensitivity.relative_tolerance = 1e-6;
  options.sensitivity.absolute_tolerance = 1e-8;
  UpdateOptions screen = options;
  LoosenForScreening(1e-5, screen);
  EXPECT_EQ(screen.integrator.relative_tolerance, 1e-5);
  // The same factor, 1000, on the others (to rounding).
  EXPECT_NEAR(screen.integrator.absolute_tolerance, 1e-7, 1e-22);
  EXPECT_NEAR(screen.sensitivity.relative_tolerance, 1e-3, 1e-18);
  EXPECT_NEAR(screen.sensitivity.absolute_tolerance, 1e-5, 1e-20);
  // A fit already at 1e-4 is left as it is.
  options.integrator.relative_tolerance = 1e-4;
  screen = options;
  LoosenForScreening(1e-5, screen);
  EXPECT_EQ(screen.integrator.relative_tolerance, 1e-4);
  EXPECT_EQ(screen.integrator.absolute_tolerance, 1e-10);
  EXPECT_EQ(screen.sensitivity.relative_tolerance, 1e-6);
}

TEST(ScreeningTest, ALooserScreenEndsInTheSameBasinWithFewerRightHandSides) {
  const Probe probe;
  // A screen of the far start: the first 30% of the record, at most 20 iterations.
  const std::vector<TestRecord> window = Window({probe.test}, 0.3);
  UpdateOptions tight = probe.options;
  tight.max_iterations = 20;
  UpdateOptions loose = tight;
  LoosenForScreening(1e-5, loose);
  const UpdateResult a = UpdateModel(*probe.crane.model, window, tight);
  const UpdateResult b = UpdateModel(*probe.crane.model, window, loose);
  ASSERT_EQ(a.parameters.size(), b.parameters.size());
  // The same end (measured: 1e-4 relative apart, under 0.01 of a standard deviation), by far
  // within the global search's clustering tolerance (0.02), and the truth's minimum of this
  // noisy window (within 3 standard deviations; the 30% were the start's error); the same cost
  // to 1% (measured 0.13%: the record's noise dominates a simulation error of 1e-5).
  for (size_t k = 0; k < a.parameters.size(); ++k) {
    const ParameterEstimate& p = a.parameters[k];
    EXPECT_NEAR(b.parameters[k].value, p.value, 0.05 * p.std) << p.name;
    EXPECT_NEAR(p.value, probe.crane.model->GetParameter(p.name), 3 * p.std) << p.name;
  }
  EXPECT_NEAR(b.final_cost / a.final_cost, 1.0, 0.01);
  // The point: fewer steps (measured: 3110 right-hand sides against 5929, 0.52; both 8
  // iterations).
  EXPECT_LT(b.rhs_evaluations, 0.7 * a.rhs_evaluations)
      << a.rhs_evaluations << " " << b.rhs_evaluations;
}

}  // namespace
}  // namespace mbid::updating::internal
