// Next-test planning at the alternative minima (plan_alternatives.h): scores at each minimum
// and the candidates' noise-free separation of the best from each alternative.
#include "mbid/updating/plan_alternatives.h"

#include <algorithm>
#include <boost/math/distributions/normal.hpp>
#include <cmath>
#include <memory>

#include "mbid/common/error.h"
#include "mbid/simulation/simulate.h"
#include "mbid/updating/global_search.h"
#include "plan_internal.h"

namespace mbid::updating {
namespace {

// The candidate's noise-free outputs at `values`, each channel divided by its noise.
Eigen::MatrixXd WeightedOutputs(const model::MechanicalModel& model, const PlanCandidate& candidate,
                                const std::map<std::string, double>& values) {
  const std::unique_ptr<model::MechanicalModel> at =
      internal::MakeCandidateModel(model, candidate, {values.begin(), values.end()});
  const TestDesign& test = candidate.test;
  const simulation::SimulationResult run =
      simulation::Simulate(*at, test.excitation, test.simulation, test.sensors);
  Eigen::MatrixXd weighted = run.exact.values;
  for (Eigen::Index c = 0; c < weighted.cols(); ++c) {
    const std::string& channel = run.exact.channels[static_cast<size_t>(c)];
    const auto noise = test.sensors.noise_std.find(channel);
    if (noise == test.sensors.noise_std.end() || !(noise->second > 0)) {
      throw InputError(candidate.name, "sensors.noise_std", "no noise level for '" + channel + "'",
                       "a positive noise level for every channel");
    }
    weighted.col(c) /= noise->second;
  }
  return weighted;
}

}  // namespace

AlternativesPlan PlanAtAlternatives(const model::MechanicalModel& model,
                                    const std::vector<TestDesign>& recorded,
                                    const std::vector<PlanCandidate>& candidates,
                                    const TestPlan& at_best,
                                    const std::vector<AlternativeMinimumValues>& alternatives,
                                    const PlanOptions& options, long residual_count,
                                    double significance) {
  AlternativesPlan result;
  std::map<std::string, double> best;
  for (size_t k = 0; k < at_best.parameters.size(); ++k) {
    best[at_best.parameters[k]] = at_best.values[static_cast<Eigen::Index>(k)];
  }
  for (const PlanCandidate& candidate : candidates) {
    CandidateAtAlternatives entry;
    entry.name = candidate.name;
    entry.worst_score = std::numeric_limits<double>::quiet_NaN();
    for (const CandidateScore& score : at_best.candidates) {
      if (score.name == candidate.name) entry.worst_score = score.score;
    }
    result.candidates.push_back(entry);
  }
  const double k = static_cast<double>(at_best.parameters.size());
  std::vector<Eigen::MatrixXd> best_outputs;
  for (const PlanCandidate& candidate : candidates) {
    best_outputs.push_back(WeightedOutputs(model, candidate, best));
  }
  for (const AlternativeMinimumValues& alternative : alternatives) {
    std::unique_ptr<model::MechanicalModel> at = model.Clone();
    std::map<std::string, double> values = best;
    for (const auto& [name, value] : alternative.values) {
      if (values.count(name) > 0) values[name] = value;
    }
    for (const auto& [name, value] : values) at->SetParameter(name, value);
    const TestPlan plan = PlanNextTest(*at, recorded, candidates, options);
    long candidate_residuals = 0;
    for (size_t i = 0; i < candidates.size(); ++i) {
      CandidateAtAlternatives& entry = result.candidates[i];
      double score = std::numeric_limits<double>::quiet_NaN();
      for (const CandidateScore& s : plan.candidates) {
        if (s.name == entry.name) score = s.score;
      }
      entry.scores.push_back(score);
      entry.worst_score = std::min(entry.worst_score, score);
      const Eigen::MatrixXd outputs = WeightedOutputs(model, candidates[i], values);
      entry.separation.push_back((outputs - best_outputs[i]).squaredNorm());
      candidate_residuals = std::max<long>(candidate_residuals, outputs.size());
    }
    // The threshold with the recorded residuals and the largest candidate's: the F quantile
    // barely moves with the degrees of freedom past a few hundred.
    const double dof = std::max(1.0, static_cast<double>(residual_count + candidate_residuals) - k);
    const double threshold = k * FQuantile(significance, k, dof);
    result.thresholds.push_back(threshold);
    // The test's noise adds 2 d.e to the separation S = |d|^2 (d the weighted difference of the
    // two outputs, e the noise): a normal term of std 2 sqrt(S). A bound that holds only
    // without noise was contradicted by the test itself (S = 8.7 and an excess of 3.9 below
    // 15.5 said certain; the recorded drop gave 19.5): its upper quantile at the significance
    // must stay below the threshold too.
    const double z =
        boost::math::quantile(boost::math::complement(boost::math::normal(), significance));
    for (CandidateAtAlternatives& entry : result.candidates) {
      const double separation = entry.separation.back();
      entry.cannot_separate.push_back(
          alternative.cost_excess + separation + z * 2 * std::sqrt(separation) < threshold);
    }
  }
  return result;
}

}  // namespace mbid::updating
