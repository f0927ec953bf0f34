// A per-channel setting of a sensor or a record (noise, bias, quantization step): absent
// channels have none.
#pragma once

#include <map>
#include <string>

namespace mbid::simulation::internal {

inline double ChannelValueOrZero(const std::map<std::string, double>& values,
                                 const std::string& channel) {
  const auto found = values.find(channel);
  return found == values.end() ? 0.0 : found->second;
}

}  // namespace mbid::simulation::internal
