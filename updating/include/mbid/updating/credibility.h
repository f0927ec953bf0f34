#pragma once

#include <set>
#include <string>
#include <vector>

#include "mbid/updating/output_error.h"

namespace mbid::updating {

// Decides whether the Fisher standard deviations of `result` (a fit of `tests`) can be taken as
// they are (UpdateOptions::max_chi_square_per_dof): fills the tests' whiteness, the result's
// chi^2 per degree of freedom, inflation and credibility, each parameter's interval, and marks
// parameters undetermined (with the reason) where the inflated standard deviation or a misfit
// says the records do not determine them.
void AssessCredibility(UpdateResult& result, const std::vector<TestRecord>& tests,
                       const UpdateOptions& options);

// Marks `p` undetermined, with the reason, where its spread says the records do not determine
// it: no finite std, a relative std (times `std_inflation`) above `undetermined_relative_std`,
// or an interval (ParameterEstimate::interval_lower, already set) reaching a bound. Returns
// whether it did; `p` is left as it is otherwise. With the fit `within` (p among its
// parameters), a relative std above the limit names the parameter `p` is correlated +-1 with:
// the records then determine a combination of the two (springs in series), not each.
bool MarkIfSpreadUndetermined(ParameterEstimate& p, double std_inflation,
                              double undetermined_relative_std,
                              const UpdateResult* within = nullptr);

// Shared parameters the records can tell only through the model's nonlinear coupling: in the
// tuned model's linearization every mode the parameter moves is invisible in the records'
// channels (a swing mode of a symmetric arm in its inclinometers). A fit then reads the
// parameter off a second-order effect near the noise, where the cost is far from the quadratic
// its standard deviation assumes: an excavator's c_swing came out 27 standard deviations off,
// "determined". Such parameters are marked undetermined with the reason (and a warning);
// returns their names.
// A parameter of `model` (at its values) whose modes the `channels` do not see in its
// linearization, with the frequencies (Hz) of those modes: the test of MarkUnseenParameters
// below, for the plan's candidate tests too.
struct UnseenParameter {
  std::string name;
  std::vector<double> modes_hz;
};
std::vector<UnseenParameter> FindUnseenParameters(const model::MechanicalModel& model,
                                                  const std::set<std::string>& channels,
                                                  const std::vector<std::string>& parameters);

std::vector<std::string> MarkUnseenParameters(const model::MechanicalModel& model,
                                              const std::vector<TestRecord>& tests,
                                              UpdateResult& result);

// The Fisher standard deviation is the cost's curvature at the estimate. With little signal for a
// parameter the records' information on it changes across its interval (a mode's share of a
// channel changes with the stiffness that places it), and the estimator's spread is the std where
// the information is lower: the crane at 1e-3 rad noise had c_eta "determined" at 0.14 relative
// std, 4.8 of those from the truth, where the std at the truth is 0.31. For each determined shared
// parameter above a few percent, the covariance is evaluated again at both ends of its interval
// (its linearized profile: the others moved along by their correlation; `tests` as fitted, with
// `result`'s weights) and the larger std at an end is reported, twice at most as the end moves
// out; the interval and `determined` follow, a flat direction at an end makes it undetermined,
// and a warning names each parameter changed. Returns their names.
std::vector<std::string> WidenToTheIntervalEnds(const model::MechanicalModel& model,
                                                const std::vector<TestRecord>& tests,
                                                const UpdateOptions& options, UpdateResult& result);

}  // namespace mbid::updating
