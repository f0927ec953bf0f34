#pragma once

// What a header cell says: a column's name and, in "name [unit]" or "name (unit)", its unit;
// and which names mark the time column.

#include <string>

namespace mbid::records::internal {

// "Boom angle [deg]" -> {"Boom angle", "deg"}; "Boom angle (deg)" -> {"Boom angle", "deg"};
// "psi" -> {"psi", ""}. A parenthesis that is not a unit ("Sensor (left)") stays in the name.
struct NameAndUnit {
  std::string name;
  std::string unit;
};
NameAndUnit SplitNameUnit(const std::string& cell);

// "[deg]" -> "deg", "(deg)" -> "deg", "deg" -> "deg".
std::string StripUnitBrackets(const std::string& text);

// Whether `name` marks the time column: time, t, Zeit, timestamp, datetime or X_Value (case
// ignored), optionally with the project's unit suffix _s, _ms or _us (`*unit` is then "s",
// "ms" or "us", else left as is).
bool IsTimeColumnName(const std::string& name, std::string* unit);

// The unit a channel's name states by the project's suffix convention (`boom_angle_rad`,
// `theta_deg`, `acc_m_s2`, `rate_deg_s`) and the name without it: {"boom_angle", "rad"}; the
// unit "" when it states none. Only suffixes that name one unit unambiguously (no `_g`: gram or
// gravity; no `_nm`: newton metre or nanometre).
NameAndUnit SplitUnitSuffix(const std::string& name);

}  // namespace mbid::records::internal
