#pragma once

#include <string>
#include <utility>
#include <vector>

namespace mbid::campaign::internal {

// The unit of a scenario key or summary column, read from its name (docs/notation: units in
// names; c_<joint> and d_<joint> are stiffness and damping). "1" when the name has none.
inline std::string UnitOfColumn(const std::string& key) {
  const std::string last = key.substr(key.find_last_of('.') + 1);
  if (last.rfind("c_", 0) == 0) return "N*m/rad";
  if (last.rfind("d_", 0) == 0) return "N*m*s/rad";
  static const std::vector<std::pair<std::string, std::string>> kSuffixes = {
      {"_Nm_per_rad", "N*m/rad"},
      {"_Nms_per_rad", "N*m*s/rad"},
      {"_per_s", "1/s"},
      {"_kgm2", "kg*m^2"},
      {"_mps2", "m/s^2"},
      {"_deg", "deg"},
      {"_rad", "rad"},
      {"_hz", "Hz"},
      {"_kg", "kg"},
      {"_Nm", "N*m"},
      {"_N", "N"},
      {"_m", "m"},
      {"_s", "s"}};
  for (const auto& [suffix, unit] : kSuffixes) {
    if (last.size() > suffix.size() &&
        last.compare(last.size() - suffix.size(), suffix.size(), suffix) == 0) {
      return unit;
    }
  }
  return "1";
}

// The last component of a dotted key ("boom_elevation_deg"), for labels.
inline std::string ShortName(const std::string& key) {
  return key.substr(key.find_last_of('.') + 1);
}

}  // namespace mbid::campaign::internal
