#pragma once

#include <map>
#include <string>
#include <vector>

#include "mbid/model/mechanical_model.h"
#include "mbid/updating/plan.h"

namespace mbid::updating {

// Next-test planning when the recorded tests leave several minima of equal fit (the global
// search's alternatives, non_unique). PlanNextTest's Fisher information is local to the best
// minimum; here each candidate is also
// - scored at every alternative (the same log det, with the tuned parameters at the
//   alternative's values): a candidate good at one minimum only is a gamble, and
//   `worst_score` says what it is worth wherever the truth is;
// - checked for whether it can tell the minima apart: `separation` is
//   sum ((y_best - y_alternative) / sigma)^2 over the candidate's samples and channels, the
//   candidate's outputs simulated without noise at both value sets. A joint re-fit moves the
//   alternative to lower it, so it is an upper bound of what the candidate adds to the
//   alternative's cost excess (2 x cost) without noise; the test's noise adds a normal term of
//   std 2 sqrt(separation). When even the bound plus that term's upper quantile at the
//   significance, added to the recorded tests' excess, stays below the F-test's threshold
//   (k F(1 - significance; k, dof)), the candidate `cannot_separate` that alternative. Above it
//   the candidate may separate them; only the test itself will say.

struct AlternativeMinimumValues {
  std::string label;                     // e.g. the starts that ended there
  std::map<std::string, double> values;  // tuned shared parameters
  double cost_excess = 0;                // 2 (cost - best cost) on the recorded tests
};

struct CandidateAtAlternatives {
  std::string name;
  std::vector<double> scores;      // log det at each alternative (PlanNextTest's score)
  double worst_score = 0;          // min of the score at the best and at every alternative
  std::vector<double> separation;  // per alternative (upper bound, see above)
  std::vector<bool> cannot_separate;
};

struct AlternativesPlan {
  std::vector<CandidateAtAlternatives> candidates;  // in the order of the candidates given
  std::vector<double> thresholds;                   // per alternative: k F(1 - significance)
};

// `model` carries the best minimum's values; `at_best` is PlanNextTest's plan there (its scores
// are matched to `candidates` by name). `residual_count` is the recorded tests' samples x channels
// (the F-test's degrees of freedom, with each candidate's own added). Throws as PlanNextTest does.
AlternativesPlan PlanAtAlternatives(const model::MechanicalModel& model,
                                    const std::vector<TestDesign>& recorded,
                                    const std::vector<PlanCandidate>& candidates,
                                    const TestPlan& at_best,
                                    const std::vector<AlternativeMinimumValues>& alternatives,
                                    const PlanOptions& options, long residual_count,
                                    double significance);

}  // namespace mbid::updating
