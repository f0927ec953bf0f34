// The value of what could not be computed (a standard deviation of an undetermined parameter,
// a cost not evaluated), shared by updating's files.
#pragma once

#include <limits>

namespace mbid::updating::internal {

inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

}  // namespace mbid::updating::internal
