#pragma once

// Results: the modes of a method's estimate as ModalResult reports them.

#include "estimate.h"
#include "mbid/identification/modal_result.h"
#include "mbid/identification/options.h"
#include "record.h"

namespace mbid::identification {

// Fills `result` from the estimate: order, termination, stabilization (moved out of `estimate`)
// and warnings; amplitudes, reconstruction, correlation, noise and offset on the full-rate
// record; the modes with their standard deviations, drifting ones merged (backbone.h); A1..Ap
// of eq. 2 by eq. 5; modes sorted by frequency.
void AddEstimate(const AnalysisRecord& record, const IdentificationOptions& options,
                 Estimate* estimate, ModalResult* result);

}  // namespace mbid::identification
