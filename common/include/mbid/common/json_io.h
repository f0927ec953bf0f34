#pragma once

#include <nlohmann/json.hpp>
#include <string>

namespace mbid {

// Writes `value` pretty-printed to `path` atomically; "-" writes to standard output.
void WriteJson(const nlohmann::json& value, const std::string& path);

// Reads a JSON file; a parse error is an InputError naming the file and line.
nlohmann::json ReadJson(const std::string& path);

}  // namespace mbid
