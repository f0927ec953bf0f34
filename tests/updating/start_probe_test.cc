// The global search's probe of a start's cost (global_search_internal.h): far starts are
// decided on the records' first tenth, which bounds the cost from below only where the noise is
// given and no baseline is projected out; elsewhere the whole records are simulated.
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
    options.integrator = crane.simulation.integrator;
    options.integrator.interpolate_outputs = true;
    options.quiet = true;
    // A far start: every stiffness 30% high, as a space-filling point would be.
    for (const char* name : {"c_alpha", "c_gamma", "c_eta", "c_theta"}) {
      ParameterSetting setting;
      setting.name = name;
      setting.initial = 1.3 * crane.model->GetParameter(name);
      options.parameters.push_back(setting);
    }
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

}  // namespace
}  // namespace mbid::updating::internal
