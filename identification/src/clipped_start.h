#pragma once

#include "mbid/common/measurement.h"
#include "mbid/identification/modal_result.h"
#include "mbid/identification/options.h"

namespace mbid::identification {

// A decay clipped at its start (a sensor or logger whose range the first swings exceeded) is
// whole again once its swings fall inside the range: moves `applied`'s window start to the
// sample after the last clipped one and warns, if at least half the window is left and nothing
// after it is clipped. Else the window stays and the reliability check names the clipping.
void SkipClippedStart(const Measurement& measurement, IdentificationOptions* applied,
                      ModalResult* result);

}  // namespace mbid::identification
