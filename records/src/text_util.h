#pragma once

// Small text helpers shared by the UFF58 and LVM readers; not part of the public API.

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "internal.h"  // common/src: ReadTextFile
#include "mbid/common/error.h"

namespace mbid::records::internal {

inline std::string_view TrimView(std::string_view text) {
  const auto first = text.find_first_not_of(" \t\r\n");
  if (first == std::string_view::npos) return {};
  const auto last = text.find_last_not_of(" \t\r\n");
  return text.substr(first, last - first + 1);
}

inline std::string TrimText(std::string_view text) { return std::string(TrimView(text)); }

inline std::vector<std::string_view> SplitWhitespace(std::string_view text) {
  std::vector<std::string_view> tokens;
  size_t at = 0;
  while (true) {
    at = text.find_first_not_of(" \t\r\n", at);
    if (at == std::string_view::npos) break;
    const size_t end = std::min(text.find_first_of(" \t\r\n", at), text.size());
    tokens.push_back(text.substr(at, end - at));
    at = end;
  }
  return tokens;
}

// Parses all of `text` (already trimmed) as a decimal number, independent of the C locale. A
// leading '+' and the Fortran exponent letter 'D' are accepted; "NaN" and "Inf" parse (callers
// decide). False for anything else, including an empty string.
inline bool ParseNumber(std::string_view text, double* value) {
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);
  if (text.empty() || text.size() > 64 || text.front() == '+') return false;
  char copy[65];
  for (size_t i = 0; i < text.size(); ++i) {
    copy[i] = (text[i] == 'D' || text[i] == 'd') ? 'E' : text[i];
  }
  const char* end = copy + text.size();
  const auto [ptr, ec] = std::from_chars(copy, end, *value);
  if (ptr != end) return false;
  if (ec == std::errc::result_out_of_range) {
    copy[text.size()] = '\0';
    *value = std::strtod(copy, nullptr);  // underflow to a subnormal or zero, overflow to inf
    return true;
  }
  return ec == std::errc();
}

// Parses all of `text` (trimmed) as a decimal integer within [minimum, maximum].
inline bool ParseInteger(std::string_view text, long long minimum, long long maximum,
                         long long* value) {
  text = TrimView(text);
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);
  if (text.empty()) return false;
  const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), *value);
  return ptr == text.data() + text.size() && ec == std::errc() && *value >= minimum &&
         *value <= maximum;
}

// The whole file; one that cannot be opened or read is an InputError naming it.
inline std::string ReadWholeFile(const std::string& path, const std::string& expected) {
  return mbid::internal::ReadTextFile(path, expected);
}

// Most samples per channel any reader accepts (8e8 bytes per channel as doubles), checked before
// anything that size is allocated.
inline constexpr long long kMaxSamples = 100000000;

// The field of an error about a line of a text file: "line 12".
inline std::string LineField(int line) { return "line " + std::to_string(line); }

}  // namespace mbid::records::internal
