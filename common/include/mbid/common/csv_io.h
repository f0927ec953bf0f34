#pragma once

#include <string>

#include "mbid/common/measurement.h"

namespace mbid {

// CSV measurement (docs/interfaces): '#' comment lines, header "time,<channel>,...", time in
// seconds strictly increasing and uniformly spaced (relative deviation under 1e-6), values in
// SI units. The CSV carries no units, so every channel gets units "rad" (all outputs of the
// models are angles in radians) unless a "# units: a,b" comment lists them. Optional comments
// "# source: x" and "# sample_interval_s: x" (which must agree with the time column) restore
// those fields exactly. Errors are InputErrors naming the file and line (and column): bad
// numbers, NaN/Inf, wrong field counts, a missing 'time' first column, duplicate channels, fewer
// than 2 data rows, decreasing or non-uniform time.
Measurement ReadMeasurementCsv(const std::string& path);

// Writes the same layout atomically (with the metadata comments above), every double in the
// shortest form that parses back to the same bits, so a write/read round trip is exact.
// Validate()s first; throws std::runtime_error on I/O failure and leaves no file then.
void WriteMeasurementCsv(const Measurement& measurement, const std::string& path);

}  // namespace mbid
