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

// Whether the record determines a mode: the standard deviation of its frequency within 10 % of
// the frequency and that of its decay rate within the decay rate's magnitude (a NaN deviation,
// not computed, passes). AssessReliability calls a mode that fails "undetermined".
bool IsDetermined(double frequency_hz, double std_frequency_hz, double decay_rate_per_s,
                  double std_decay_rate_per_s);

// Reasons the data do not support the result (ModalResult::reliable).
void AssessReliability(const AnalysisRecord& record, const IdentificationOptions& options,
                       const Estimate& estimate, ModalResult* result);

}  // namespace mbid::identification
