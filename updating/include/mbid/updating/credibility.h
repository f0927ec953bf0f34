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
// whether it did; `p` is left as it is otherwise.
bool MarkIfSpreadUndetermined(ParameterEstimate& p, double std_inflation,
                              double undetermined_relative_std);

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

}  // namespace mbid::updating
