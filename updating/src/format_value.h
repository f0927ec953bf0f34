// Numbers in updating's messages.
#pragma once

#include <sstream>
#include <string>

namespace mbid::updating::internal {

// A number in messages: 4 significant digits.
inline std::string FormatValue(double value) {
  std::ostringstream out;
  out.precision(4);
  out << value;
  return out.str();
}

}  // namespace mbid::updating::internal
