#pragma once

// Free-decay preparation: where the analysed free decay starts (release.h).

#include "mbid/common/measurement.h"
#include "mbid/identification/modal_result.h"
#include "mbid/identification/options.h"

namespace mbid::identification {

// Where the free decay starts, and the options with the analysis window starting there.
IdentificationOptions ApplyRelease(const Measurement& measurement,
                                   const IdentificationOptions& options, ModalResult* result,
                                   bool* from_rest);

}  // namespace mbid::identification
