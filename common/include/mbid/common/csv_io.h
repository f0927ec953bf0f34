#pragma once

#include <string>

#include "mbid/common/measurement.h"

namespace mbid {

// CSV measurement (docs/interfaces): '#' comment lines, header "time,<channel>,...", time in
// seconds uniformly spaced (relative deviation under 1e-6), values in SI units. Channels whose
// name is an angle output get units "rad"; all channels are taken as SI. Errors name the file
// and line (and column).
Measurement ReadMeasurementCsv(const std::string& path);

// Writes the same layout atomically, with full double precision (round-trips exactly).
void WriteMeasurementCsv(const Measurement& measurement, const std::string& path);

}  // namespace mbid
