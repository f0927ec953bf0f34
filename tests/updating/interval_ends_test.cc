// WidenToTheIntervalEnds (credibility.h): with little signal for a parameter, the Fisher standard
// deviation at the estimate understates its spread; the one at the interval's end does not.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "crane_fixture.h"
#include "mbid/updating/credibility.h"

namespace mbid::updating {
namespace {

using testing::kAllParameters;
using testing::LoadCrane;

double LogZ(const ParameterEstimate& p, double truth) {
  return std::log(p.value / truth) / p.relative_std;
}

TEST(IntervalEndsTest, ALowSignalStiffnessGetsTheStdAtItsIntervalsEnd) {
  // The reference crane's 8 s release, psi and phi at 1e-3 rad noise (seed 1): psi correlates
  // with its fit at K = 0.44 only. Fitted from the truth, the minimum has c_eta at 0.61 of it with
  // a Fisher relative std of 0.135: "determined", 3.7 of those (in log c) below the truth. The
  // records' information on c_eta falls as it rises (the eta mode's share of the channels), so
  // the std at the truth is 0.31 (a fit evaluated there), and at the interval's upper end 0.20.
  testing::Crane crane = LoadCrane(testing::kReferenceScenario);
  crane.sensors.noise_std = {{"psi", 1e-3}, {"phi", 1e-3}};
  const TestRecord test = testing::SimulateTest(crane, "release", 8.0);
  const UpdateOptions options = testing::FitFromOff(crane, kAllParameters, 1.0, 1.0);
  UpdateResult result = UpdateModel(*crane.model, {test}, options);
  ASSERT_EQ(result.termination, UpdateResult::Termination::kConverged) << result.message;
  const double c_eta = crane.model->GetParameter("c_eta");
  const ParameterEstimate fisher = result.Find("c_eta");
  ASSERT_TRUE(fisher.determined);
  ASSERT_LT(fisher.relative_std, 0.16);
  ASSERT_LT(LogZ(fisher, c_eta), -3.5);  // the confident wrong answer this guards against

  const std::vector<std::string> widened =
      WidenToTheIntervalEnds(*crane.model, {test}, options, result);
  const ParameterEstimate& p = result.Find("c_eta");
  EXPECT_NE(std::find(widened.begin(), widened.end(), "c_eta"), widened.end());
  // Two looks out: 0.135 -> 0.20 (the std at the first end) -> 0.26 (at the end that one gives).
  EXPECT_GT(p.relative_std, 0.24);
  EXPECT_NEAR(p.std_widening, p.relative_std / fisher.relative_std, 1e-12);
  EXPECT_GT(LogZ(p, c_eta), -3.0);
  EXPECT_NEAR(p.interval_upper / p.value, std::exp(2 * p.relative_std * result.std_inflation),
              1e-9);
  EXPECT_TRUE(std::any_of(result.warnings.begin(), result.warnings.end(),
                          [](const std::string& w) { return w.rfind("c_eta: ", 0) == 0; }));
  // Where the records carry much (c_theta: 0.4 %), nothing is evaluated and nothing changes.
  EXPECT_EQ(result.Find("c_theta").std_widening, 1.0);
  EXPECT_TRUE(result.Find("c_theta").determined);
  // Parameters the widening leaves undetermined are listed as such.
  for (const ParameterEstimate& q : result.parameters) {
    const bool listed = std::find(result.undetermined.begin(), result.undetermined.end(), q.name) !=
                        result.undetermined.end();
    EXPECT_EQ(listed, !q.determined) << q.name;
  }
}

}  // namespace
}  // namespace mbid::updating
