#pragma once

#include <string>

#include "mbid/common/measurement.h"
#include "mbid/identification/modal_result.h"
#include "mbid/identification/options.h"

namespace mbid::identification {

// Identify with a linear drift per channel fitted together with the modes (the option
// remove_drift): the modes are identified, a straight line a + b (t - start) is fitted by least
// squares to what they leave of each analysed channel (the record less the reconstruction's
// modes), b (t - start) is subtracted from the whole record, and the modes are identified again;
// twice, so that a drift the first fit's modes absorbed is found too. The release is the first
// identification's. The result carries the summed drift per channel (ModalResult::drift_per_s);
// the constant part stays with the offset option.
ModalResult IdentifyRemovingDrift(const Measurement& measurement,
                                  const IdentificationOptions& options, const std::string& origin);

}  // namespace mbid::identification
