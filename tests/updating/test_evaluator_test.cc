// The fit's evaluator of one record (test_evaluator.h): which simulations a sequence of Ceres'
// requests costs, with and without sensitivities computed at once at promising trial points.
#include "test_evaluator.h"

#include <gtest/gtest.h>

#include "crane_fixture.h"
#include "prepared_test.h"

namespace mbid::updating::internal {
namespace {

using testing::Crane;
using testing::LoadCrane;

// The reference crane's 3 s record, its four stiffnesses tuned from 3% above the truth.
struct OneRecordFit {
  Crane crane = LoadCrane(testing::kReferenceScenario);
  TestRecord test = testing::SimulateTest(crane, "decay", 3.0);
  UpdateOptions options;
  std::vector<Unknown> unknowns;
  PreparedTest prepared;

  explicit OneRecordFit(bool speculative) {
    options = testing::FitFromOff(crane, testing::kStiffnesses, 1.03, 1.0);
    options.speculative_jacobians = speculative;
    unknowns = ResolveUnknowns(*crane.model, {test}, options);
    prepared = PrepareTest(*crane.model, test, 0, unknowns, options);
  }
  Eigen::VectorXd Start() const {
    Eigen::VectorXd x(static_cast<Eigen::Index>(unknowns.size()));
    for (size_t k = 0; k < unknowns.size(); ++k) {
      x[static_cast<Eigen::Index>(k)] = unknowns[k].ToInternal(unknowns[k].initial);
    }
    return x;
  }
};

struct Evaluation {
  Eigen::VectorXd residuals;
  Eigen::MatrixXd jacobian;  // row-major as Ceres reads it, stored transposed here
};

Evaluation Evaluate(TestEvaluator& evaluator, const Eigen::VectorXd& x, bool with_jacobian) {
  Evaluation e;
  e.residuals.resize(evaluator.residual_count());
  e.jacobian.resize(x.size(), evaluator.residual_count());
  EXPECT_TRUE(evaluator.Evaluate(x.data(), e.residuals.data(),
                                 with_jacobian ? e.jacobian.data() : nullptr));
  return e;
}

// An evaluator whose first request was the Jacobian at the start x0, and the Gauss-Newton step
// from there.
struct AtTheStart {
  OneRecordFit setup{true};
  Work work;
  TestEvaluator evaluator{*setup.crane.model, setup.unknowns, setup.prepared, setup.options, work};
  Eigen::VectorXd x0 = setup.Start();
  Evaluation at_x0 = Evaluate(evaluator, x0, true);
  Eigen::VectorXd step = [this] {
    const Eigen::MatrixXd J = at_x0.jacobian.transpose();
    return Eigen::VectorXd(-(J.transpose() * J).ldlt().solve(J.transpose() * at_x0.residuals));
  }();
};

TEST(TestEvaluatorTest, APromisingTrialPointGetsItsJacobianAtOnceAndALastOneDoesNot) {
  AtTheStart start;
  auto& [setup, work, evaluator, x0, at_x0, step] = start;
  ASSERT_EQ(work.sensitivity_simulations, 1);
  ASSERT_EQ(work.simulations, 0);
  // The Gauss-Newton step from 3% off: the linear model predicts most of the cost gone.
  const Eigen::VectorXd x1 = x0 + step;

  // The trial point: one sensitivity run, whose Jacobian Ceres then gets without another.
  const Evaluation trial = Evaluate(evaluator, x1, false);
  EXPECT_EQ(work.sensitivity_simulations, 2);
  EXPECT_EQ(work.simulations, 0);
  const Evaluation accepted = Evaluate(evaluator, x1, true);
  EXPECT_EQ(work.sensitivity_simulations, 2);
  EXPECT_EQ(accepted.residuals, trial.residuals);  // the same run
  EXPECT_LT(trial.residuals.squaredNorm(), 0.01 * at_x0.residuals.squaredNorm());

  // Without speculation the same requests cost a plain run more, and give the same numbers:
  // the Jacobian comes from one sensitivity run at x1 either way.
  {
    OneRecordFit plain_setup(false);
    Work plain_work;
    TestEvaluator plain(*plain_setup.crane.model, plain_setup.unknowns, plain_setup.prepared,
                        plain_setup.options, plain_work);
    Evaluate(plain, x0, true);
    Evaluate(plain, x1, false);
    EXPECT_EQ(plain_work.sensitivity_simulations, 1);
    EXPECT_EQ(plain_work.simulations, 1);
    const Evaluation plain_accepted = Evaluate(plain, x1, true);
    EXPECT_EQ(plain_work.sensitivity_simulations, 2);
    EXPECT_EQ(plain_accepted.residuals, accepted.residuals);
    EXPECT_EQ(plain_accepted.jacobian, accepted.jacobian);
  }

  // A step that would change the cost by less than 10 function tolerances: the fit is about to
  // stop, so a plain run.
  Evaluate(evaluator, x1 + 1e-9 * step, false);
  EXPECT_EQ(work.sensitivity_simulations, 2);
  EXPECT_EQ(work.simulations, 1);
  // A trial that the linear model expects to raise the cost: plain.
  Evaluate(evaluator, x1 - 2.0 * step, false);
  EXPECT_EQ(work.sensitivity_simulations, 2);
  EXPECT_EQ(work.simulations, 2);
}

TEST(TestEvaluatorTest, RejectedSpeculationsTurnTheTrialsPlainAndTheIterateStaysCached) {
  AtTheStart start;
  auto& [setup, work, evaluator, x0, at_x0, step] = start;
  const long sensitivity_rhs = work.rhs_evaluations;

  // Ceres rejects a speculated trial (it never asks for its Jacobian) and tries shorter steps:
  // the next trial is plain.
  Evaluate(evaluator, x0 + 0.5 * step, false);
  EXPECT_EQ(work.sensitivity_simulations, 2);
  const long before_plain = work.rhs_evaluations;
  Evaluate(evaluator, x0 + 0.25 * step, false);
  EXPECT_EQ(work.sensitivity_simulations, 2);
  EXPECT_EQ(work.simulations, 1);
  const long plain_rhs = work.rhs_evaluations - before_plain;
  // None of two trials accepted, 1/3 counted from one of one, is below the break-even share
  // 1 - P/S (a plain run's right-hand sides against a sensitivity run's: ~1/6 here): plain on.
  ASSERT_GT(1.0 - static_cast<double>(plain_rhs) / sensitivity_rhs, 1.0 / 3.0);
  Evaluate(evaluator, x0 + 0.125 * step, false);
  EXPECT_EQ(work.sensitivity_simulations, 2);
  EXPECT_EQ(work.simulations, 2);
  // The iterate's Jacobian survived the speculation: the covariance at x0 costs nothing.
  Evaluate(evaluator, x0, true);
  EXPECT_EQ(work.sensitivity_simulations, 2);

  // The simulated record at a point evaluated before comes from that evaluation: the last plain
  // run's, or a kept Jacobian's (x0's, the speculation's).
  const Measurement at_eighth = evaluator.Simulate(x0 + 0.125 * step);
  const Measurement at_start = evaluator.Simulate(x0);
  const Measurement at_half = evaluator.Simulate(x0 + 0.5 * step);
  EXPECT_EQ(work.simulations, 2);
  // A point no longer kept (the plain run at a quarter step was followed by another) is
  // simulated again.
  const Measurement at_quarter = evaluator.Simulate(x0 + 0.25 * step);
  EXPECT_EQ(work.simulations, 3);
  // The sensitivity run's outputs agree with a plain run's within the integration tolerance:
  // 1e-8 relative steps on a signal of ~4e-3 rad leave ~1e-9 rad.
  const Measurement plain_start = [&] {
    OneRecordFit plain(false);
    Work plain_work;
    TestEvaluator e(*plain.crane.model, plain.unknowns, plain.prepared, plain.options, plain_work);
    return e.Simulate(x0);
  }();
  ASSERT_EQ(plain_start.values.rows(), at_start.values.rows());
  EXPECT_LT((plain_start.values - at_start.values).cwiseAbs().maxCoeff(),
            1e-6 * at_start.values.cwiseAbs().maxCoeff());
  EXPECT_EQ(at_start.start_time_s, setup.test.record.start_time_s);
  // Each is the record at its own point.
  for (const Measurement* other : {&at_eighth, &at_half, &at_quarter}) {
    EXPECT_GT((other->values - at_start.values).cwiseAbs().maxCoeff(),
              1e-3 * at_start.values.cwiseAbs().maxCoeff());
  }
}

// Through the fit: from 5% off, every trial point Ceres accepts was speculated, so the plain runs
// there are saved, the sensitivity runs are the same ones, and so is the result.
TEST(TestEvaluatorTest, AFitFromNearTheTruthSavesItsPlainRunsAndEndsTheSame) {
  const Crane crane = LoadCrane(testing::kReferenceScenario);
  const TestRecord test = testing::SimulateTest(crane, "decay", 3.0);
  auto fit = [&](bool speculative) {
    UpdateOptions options = testing::FitFromOff(crane, testing::kAllParameters, 1.05, 0.95);
    options.speculative_jacobians = speculative;
    return UpdateModel(*crane.model, {test}, options);
  };
  const UpdateResult plain = fit(false);
  const UpdateResult speculative = fit(true);
  ASSERT_EQ(plain.termination, UpdateResult::Termination::kConverged) << plain.message;
  ASSERT_EQ(speculative.termination, UpdateResult::Termination::kConverged);
  EXPECT_EQ(speculative.iterations, plain.iterations);
  EXPECT_EQ(speculative.sensitivity_simulations, plain.sensitivity_simulations);
  // Without speculation: one plain run per trial point and one for the re-simulation; with it,
  // at most the last trial point's (the one that stops the fit) is plain.
  EXPECT_GE(plain.simulations, plain.iterations);
  EXPECT_LE(speculative.simulations, 1);
  // The same Jacobians at the same points: the same estimates, up to the last trial's cost
  // (a plain run either way).
  for (const std::string& name : testing::kAllParameters) {
    EXPECT_EQ(speculative.Find(name).value, plain.Find(name).value) << name;
    EXPECT_EQ(speculative.Find(name).std, plain.Find(name).std) << name;
  }
  EXPECT_EQ(speculative.final_cost, plain.final_cost);
  // The re-simulation at the estimate comes from the last sensitivity run there: the same
  // record as a plain run's to the integration tolerance.
  ASSERT_EQ(speculative.tests.size(), 1u);
  EXPECT_LT((speculative.tests[0].simulated.values - plain.tests[0].simulated.values)
                .cwiseAbs()
                .maxCoeff(),
            1e-6 * plain.tests[0].simulated.values.cwiseAbs().maxCoeff());
}

}  // namespace
}  // namespace mbid::updating::internal
