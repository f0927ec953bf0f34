// Angles in files are in degrees where their key says so (`_deg`); inside, radians.
#pragma once

#include <cmath>

namespace mbid::model::internal {

inline constexpr double kDegToRad = M_PI / 180.0;

}  // namespace mbid::model::internal
