#pragma once

#include <Eigen/Core>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "mbid/model/mechanical_model.h"
#include "mbid/simulation/integrator_options.h"
#include "mbid/updating/fisher.h"

namespace mbid::updating {

// Next-test planning (D-optimal design): which of some candidate tests, added to the tests
// already recorded, tells most about the tuned parameters. Each candidate is scored by
//   score = log det(F_recorded + F_candidate + r I),
// the Fisher information of all tests together (fisher.h) in the parameters' log coordinates at
// the current estimate: the log of the inverse volume of the joint confidence ellipsoid of
// log p (relative errors), larger is better. r is a ridge of `ridge` times the mean diagonal
// of the sum, negligible against any determined direction; it keeps the score finite when the
// tests leave a direction undetermined (e.g. no recorded tests and a candidate that cannot see
// every parameter), and such a candidate then scores far below one that determines all.
// `gain` = score - log det(F_recorded + r I) is what the candidate adds (NaN without recorded
// tests, whose F is zero). Each candidate also gets the expected relative standard deviation
// of every parameter after it, sqrt(diag(F^-1)) (CalcExpectedUncertainty), +Inf where
// undetermined.

// A test that could be made next. Its model may differ from the plan's (another configuration,
// a payload): the tuned parameters are set to the plan model's values in a copy of it.
struct PlanCandidate {
  std::string name;
  std::shared_ptr<const model::MechanicalModel> model;  // null: the plan's model
  TestDesign test;  // sensors.noise_std: the expected noise of every channel
};

struct PlanOptions {
  // The tuned parameters (positive, log coordinates); empty: every parameter of the model.
  std::vector<std::string> parameters;
  // The sensitivities as UpdateModel computes them by default.
  simulation::SensitivityOptions sensitivity = [] {
    simulation::SensitivityOptions o;
    o.difference_quotient = simulation::SensitivityOptions::DifferenceQuotient::kForward;
    o.right_hand_side = simulation::SensitivityOptions::RightHandSide::kAuto;
    return o;
  }();
  double ridge = 1e-12;  // relative to the mean diagonal of F
  // UpdateModel's rules for "undetermined" (UpdateOptions).
  double rank_tolerance = 1e-7;
  double undetermined_relative_std = 0.3;
  int threads = 1;  // tests whose information is computed in parallel
};

struct CandidateScore {
  std::string name;
  double score = 0;
  double gain = std::numeric_limits<double>::quiet_NaN();
  double ridge = 0;              // r added to the sum (absolute)
  Eigen::MatrixXd fisher;        // the candidate's own F, without its `unseen` parameters
  Eigen::VectorXd relative_std;  // expected, with the recorded tests; +Inf: undetermined
  std::vector<bool> determined;  // relative_std <= undetermined_relative_std
  // Parameters whose modes the candidate's channels do not see in its linearized model
  // (credibility.h's FindUnseenParameters): its information on them is a second-order effect
  // no fit can use, left out of `fisher`, the score and the standard deviations.
  std::vector<std::string> unseen;
  // The candidate's test moves no output by its sensors' noise (a deflection of zero from the
  // rest): its information, round-off of a still machine, is left out; it adds nothing.
  bool moves_nothing = false;
  int rank = 0;  // of the recorded tests and this candidate together
  simulation::IntegratorStatistics statistics;
};

struct TestPlan {
  std::vector<std::string> parameters;
  Eigen::VectorXd values;  // the parameters' values where the information was computed
  int recorded_tests = 0;
  Eigen::MatrixXd recorded_fisher;  // zero without recorded tests
  // The recorded tests alone: log det(F_recorded + r I) (NaN without them) and the relative
  // standard deviations they give (+Inf everywhere without them).
  double recorded_score = std::numeric_limits<double>::quiet_NaN();
  Eigen::VectorXd current_relative_std;
  std::vector<CandidateScore> candidates;  // best (highest score) first
  double wall_time_s = 0;
};

// Scores `candidates` against the `recorded` tests (maybe none), with `model` at the current
// estimate (the recorded tests' fit, or the scenario's values). InputError for unknown
// parameters, a candidate model without them, missing noise levels, no candidates; CVODES
// failures as NumericalError naming the test.
TestPlan PlanNextTest(const model::MechanicalModel& model, const std::vector<TestDesign>& recorded,
                      const std::vector<PlanCandidate>& candidates, const PlanOptions& options);

// log det of a symmetric positive semi-definite F + r I, r = ridge * mean(diag F) (returned in
// `added` if not null); -Inf for a zero matrix.
double CalcLogDetWithRidge(const Eigen::MatrixXd& fisher, double ridge, double* added = nullptr);

}  // namespace mbid::updating
