#pragma once

#include <Eigen/Core>
#include <functional>

#include "estimate.h"
#include "mbid/identification/options.h"
#include "record.h"

namespace mbid::identification {

// Splits each mode whose residual holds a second one of another shape into two, where the refit
// keeps both and the record determines them; else says why the one mode is doubtful (a reason)
// or may be (a warning). `refine` refits an estimate with the channel `weights`.
void SplitCloseModes(const AnalysisRecord& record, const IdentificationOptions& options,
                     const std::function<void(Estimate*)>& refine, const Eigen::VectorXd& weights,
                     Estimate* estimate);

}  // namespace mbid::identification
