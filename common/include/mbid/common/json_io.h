#pragma once

#include <cmath>
#include <nlohmann/json.hpp>
#include <string>

namespace mbid {

// Writes `value` pretty-printed (2-space indent) to `path` atomically; "-" writes to standard
// output. JSON has no NaN or infinity: a non-finite number throws std::invalid_argument naming
// its JSON pointer ("/modes/0/frequency_hz") and nothing is written. I/O failures throw
// std::runtime_error.
void WriteJson(const nlohmann::json& value, const std::string& path);

// `value`, or null where it has none: JSON has no NaN or infinity, and the contract writes null
// for "not available" (an undefined standard deviation, the damping ratio of a rigid-body pole).
inline nlohmann::json NumberOrNull(double value) {
  return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(nullptr);
}

// Reads a JSON file; a parse error is an InputError naming the file and line.
nlohmann::json ReadJson(const std::string& path);

}  // namespace mbid
