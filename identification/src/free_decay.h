#pragma once

// Free-decay preparation: where the analysed free decay starts (release.h).

#include "mbid/common/measurement.h"
#include "mbid/identification/modal_result.h"
#include "mbid/identification/options.h"
#include "mbid/identification/release.h"

namespace mbid::identification {

// Where the free decay starts, and the options with the analysis window starting there.
// `detection` gets what DetectRelease found (not detected when the release is given or none);
// a detected release's line is the first of result->warnings.
IdentificationOptions ApplyRelease(const Measurement& measurement,
                                   const IdentificationOptions& options, ModalResult* result,
                                   ReleaseDetection* detection);

}  // namespace mbid::identification
