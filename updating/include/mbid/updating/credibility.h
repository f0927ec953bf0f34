#pragma once

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

}  // namespace mbid::updating
