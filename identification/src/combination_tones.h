#pragma once

#include "mbid/identification/modal_result.h"
#include "mbid/identification/options.h"
#include "record.h"

namespace mbid::identification {

// Marks modes that are combination tones of others (IdentifiedMode::combination) and warns of
// each: a weak mode at a sum or difference of two modes' poles, or one that is no longer
// significant on `record` beside the products of the modes' poles up to third order.
void MarkCombinationTones(const AnalysisRecord& record, const IdentificationOptions& options,
                          ModalResult* result);

}  // namespace mbid::identification
