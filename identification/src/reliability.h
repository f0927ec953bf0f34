#pragma once

#include "estimate.h"
#include "mbid/identification/modal_result.h"
#include "mbid/identification/options.h"
#include "record.h"

namespace mbid::identification {

// Reasons the data do not support the result (ModalResult::reliable).
void AssessReliability(const AnalysisRecord& record, const IdentificationOptions& options,
                       const Estimate& estimate, ModalResult* result);

}  // namespace mbid::identification
