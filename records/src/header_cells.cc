#include "header_cells.h"

#include <algorithm>
#include <cctype>
#include <utility>

#include "internal.h"
#include "units.h"

namespace mbid::records::internal {
namespace {

std::string Lower(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return text;
}

bool EndsWith(const std::string& text, const std::string& tail) {
  return text.size() > tail.size() &&
         text.compare(text.size() - tail.size(), tail.size(), tail) == 0;
}

bool IsTimeBase(const std::string& lower) {
  for (const char* base : {"time", "t", "zeit", "timestamp", "datetime", "x_value"}) {
    if (lower == base) return true;
  }
  return false;
}

}  // namespace

NameAndUnit SplitNameUnit(const std::string& cell) {
  const std::string text = mbid::internal::Trim(cell);
  for (const auto& [open, close] : {std::pair{'[', ']'}, std::pair{'(', ')'}}) {
    if (text.size() < 3 || text.back() != close) continue;
    const size_t at = text.rfind(open);
    if (at == std::string::npos || at == 0) continue;
    const std::string unit = mbid::internal::Trim(text.substr(at + 1, text.size() - at - 2));
    // Square brackets always hold a unit (an unknown one is reported as such); parentheses
    // only when udunits reads them as one.
    if (unit.empty() || (open == '(' && !IsUnit(unit))) continue;
    return {mbid::internal::Trim(text.substr(0, at)), unit};
  }
  return {text, ""};
}

std::string StripUnitBrackets(const std::string& text) {
  const std::string trimmed = mbid::internal::Trim(text);
  if (trimmed.size() >= 2 && ((trimmed.front() == '[' && trimmed.back() == ']') ||
                              (trimmed.front() == '(' && trimmed.back() == ')'))) {
    return mbid::internal::Trim(trimmed.substr(1, trimmed.size() - 2));
  }
  return trimmed;
}

bool IsTimeColumnName(const std::string& name, std::string* unit) {
  const std::string lower = Lower(name);
  if (IsTimeBase(lower)) return true;
  for (const char* suffix : {"_s", "_ms", "_us"}) {
    const std::string tail(suffix);
    if (EndsWith(lower, tail) && IsTimeBase(lower.substr(0, lower.size() - tail.size()))) {
      *unit = tail.substr(1);
      return true;
    }
  }
  return false;
}

NameAndUnit SplitUnitSuffix(const std::string& name) {
  // Longest first: `_m_s2` before `_s2`-less `_m_s`, `_mm_s` before `_m_s`... each is matched as
  // a whole suffix after an underscore, so `_rad_s` is not taken for `_s`.
  static const std::pair<const char*, const char*> kSuffixes[] = {
      {"_rad_s2", "rad/s^2"}, {"_deg_s2", "deg/s^2"},
      {"_mm_s2", "mm/s^2"},   {"_m_s2", "m/s^2"},
      {"_rad_s", "rad/s"},    {"_deg_s", "deg/s"},
      {"_mm_s", "mm/s"},      {"_m_s", "m/s"},
      {"_mrad", "mrad"},      {"_rad", "rad"},
      {"_deg", "deg"},        {"_um", "um"},
      {"_mm", "mm"},          {"_m", "m"},
      {"_rpm", "rpm"},        {"_mps2", "m/s^2"},
      {"_mps", "m/s"}};
  const std::string lower = Lower(name);
  for (const auto& [suffix, unit] : kSuffixes) {
    if (EndsWith(lower, suffix)) {
      return {name.substr(0, name.size() - std::string(suffix).size()), unit};
    }
  }
  return {name, ""};
}

}  // namespace mbid::records::internal
