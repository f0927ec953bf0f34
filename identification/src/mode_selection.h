#pragma once

// Which candidate modes are significant (significance.h): the threshold and the selection loop
// the methods share.

#include <functional>

#include "estimate.h"
#include "mbid/identification/options.h"
#include "record.h"

namespace mbid::identification {

// The significance a mode needs: min_significance, or the threshold white noise exceeds with
// probability significance_false_alarm on the decimated record.
double SignificanceThreshold(const AnalysisRecord& record, const IdentificationOptions& options);

// Significance on the record the poles come from (the decimated one: the band where the modes
// are, and one fit per dropped mode stays cheap on long records); drops insignificant modes (when
// asked) until every remaining mode is significant. `refit` re-estimates the poles of a reduced
// set.
void SelectSignificant(const AnalysisRecord& record, const IdentificationOptions& options,
                       Estimate* estimate, const std::function<void(Estimate*)>& refit);

}  // namespace mbid::identification
