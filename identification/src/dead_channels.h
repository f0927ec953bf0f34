#pragma once

// A logger's dead sensor records a constant: it holds no decay, and one such channel among
// live ones should not stop the analysis of the others.

#include "mbid/common/measurement.h"
#include "mbid/identification/modal_result.h"
#include "mbid/identification/options.h"

namespace mbid::identification {

// Where the options name no channels: the channels constant over the analysed window are left
// out of `applied->channels` (the others named there), each with a warning in `result`. Nothing
// changes when every channel is constant (PrepareRecord then says so) or none is.
void LeaveOutDeadChannels(const Measurement& measurement, IdentificationOptions* applied,
                          ModalResult* result);

}  // namespace mbid::identification
