#pragma once

#include <limits>
#include <string>
#include <vector>

namespace mbid::updating {

// A tuned parameter's profile likelihood (profile.h): the parameter held at values on either
// side of its estimate, every other unknown re-fitted, and the rise of the weighted cost. The
// interval ends where 2 (cost - best cost) reaches `threshold`; unlike the Fisher interval it
// follows a curved, flat or multi-modal cost, and it is open where the cost never rises enough
// before the parameter's bound.
struct ParameterProfile {
  bool computed = false;
  // Parameter units; when a side is open, its end is the last value reached (the bound, or
  // where the search stopped).
  double lower = std::numeric_limits<double>::quiet_NaN();
  double upper = std::numeric_limits<double>::quiet_NaN();
  bool lower_open = false;
  bool upper_open = false;
  // 2 (cost - best cost) at the interval's ends: sigmas^2 std_inflation^2 (ProfileOptions).
  double threshold = std::numeric_limits<double>::quiet_NaN();
  // A profile point fitted the records better than the estimate by more than a tenth of the
  // threshold: the estimate is not the best minimum (lowest such point in `better_value`).
  bool better_minimum = false;
  double better_value = std::numeric_limits<double>::quiet_NaN();
  // Every point visited, ascending in value, with its 2 (cost - best cost).
  std::vector<double> values;
  std::vector<double> cost_rises;
  int fits = 0;         // constrained fits run
  std::string failure;  // a constrained fit failed on this side (the side is then open)
};

}  // namespace mbid::updating
