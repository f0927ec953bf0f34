#pragma once

#include <string>
#include <vector>

#include "estimate.h"
#include "mbid/identification/modal_result.h"
#include "mbid/identification/options.h"
#include "record.h"

namespace mbid::identification {

// Faults of the record itself, whatever the modes: clipped channels and glitches (common's
// clipping.h and outliers.h), one reason each.
std::vector<std::string> RecordFaults(const AnalysisRecord& record);

// Reasons the data do not support the result (ModalResult::reliable).
void AssessReliability(const AnalysisRecord& record, const IdentificationOptions& options,
                       const Estimate& estimate, ModalResult* result);

}  // namespace mbid::identification
