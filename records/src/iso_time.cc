#include "iso_time.h"

#include <cctype>
#include <cstdlib>

namespace mbid::records::internal {
namespace {

// Reads exactly `digits` decimal digits at `*at`.
bool ReadDigits(const std::string& text, size_t* at, int digits, int* value) {
  *value = 0;
  for (int k = 0; k < digits; ++k) {
    if (*at >= text.size() || std::isdigit(static_cast<unsigned char>(text[*at])) == 0) {
      return false;
    }
    *value = *value * 10 + (text[(*at)++] - '0');
  }
  return true;
}

bool Expect(const std::string& text, size_t* at, char c) {
  if (*at >= text.size() || text[*at] != c) return false;
  ++*at;
  return true;
}

// The date: "2026-03-01", "2026/03/01", day first "01.03.2026" or "01/03/2026" in `order`; false
// when `text` does not start with one.
bool ReadDate(const std::string& text, size_t* at, SlashOrder order, int* year, int* month,
              int* day) {
  size_t start = *at;
  if (ReadDigits(text, at, 4, year) && *at < text.size() &&
      (text[*at] == '-' || text[*at] == '/')) {
    const char separator = text[(*at)++];
    return ReadDigits(text, at, 2, month) && Expect(text, at, separator) &&
           ReadDigits(text, at, 2, day);
  }
  *at = start;
  int first = 0, second = 0;
  if (!ReadDigits(text, at, 2, &first) || *at >= text.size() ||
      (text[*at] != '.' && text[*at] != '/')) {
    return false;
  }
  const char separator = text[(*at)++];
  if (!ReadDigits(text, at, 2, &second) || !Expect(text, at, separator) ||
      !ReadDigits(text, at, 4, year)) {
    return false;
  }
  const bool month_first = separator == '/' && order == SlashOrder::kMonthFirst;
  *day = month_first ? second : first;
  *month = month_first ? first : second;
  return true;
}

}  // namespace

// H. Hinnant's days_from_civil.
std::int64_t DaysFromCivil(std::int64_t y, int m, int d) {
  y -= m <= 2 ? 1 : 0;
  const std::int64_t era = (y >= 0 ? y : y - 399) / 400;
  const std::int64_t yoe = y - era * 400;
  const std::int64_t doy = (153 * (m + (m > 2 ? -3 : 9)) + 2) / 5 + d - 1;
  const std::int64_t doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  return era * 146097 + doe - 719468;
}

bool ReadSlashDate(const std::string& text, int* first, int* second, int* year) {
  size_t at = 0;
  return ReadDigits(text, &at, 2, first) && Expect(text, &at, '/') &&
         ReadDigits(text, &at, 2, second) && Expect(text, &at, '/') &&
         ReadDigits(text, &at, 4, year);
}

bool ParseDate(const std::string& text, Timestamp* date, SlashOrder order) {
  size_t at = 0;
  int year = 0, month = 0, day = 0;
  if (!ReadDate(text, &at, order, &year, &month, &day) || at != text.size() || month < 1 ||
      month > 12 || day < 1 || day > 31) {
    return false;
  }
  *date = Timestamp{};
  date->seconds = DaysFromCivil(year, month, day) * 86400;
  return true;
}

bool ParseTimestamp(const std::string& text, Timestamp* timestamp, SlashOrder order) {
  size_t at = 0;
  int year = 1970, month = 1, day = 1, hour = 0, minute = 0, second = 0;
  const bool has_date = ReadDate(text, &at, order, &year, &month, &day);
  if (has_date) {
    if (at >= text.size() || (text[at] != 'T' && text[at] != ' ')) return false;
    ++at;
  } else {
    at = 0;
    year = 1970, month = 1, day = 1;  // a failed ReadDate may have set some
  }
  // The hour may have one digit ("9:05:00") where no date precedes it.
  if (!ReadDigits(text, &at, 2, &hour)) {
    at = 0;
    if (has_date || !ReadDigits(text, &at, 1, &hour)) return false;
  }
  if (!Expect(text, &at, ':') || !ReadDigits(text, &at, 2, &minute) || !Expect(text, &at, ':') ||
      !ReadDigits(text, &at, 2, &second)) {
    return false;
  }
  if (month < 1 || month > 12 || day < 1 || day > 31 || hour > 23 || minute > 59 || second > 60) {
    return false;
  }
  double fraction = 0.0;
  int decimals = 0;
  if (at < text.size() && (text[at] == '.' || text[at] == ',')) {
    const size_t begin = ++at;
    while (at < text.size() && std::isdigit(static_cast<unsigned char>(text[at])) != 0) ++at;
    decimals = static_cast<int>(at - begin);
    if (decimals == 0) return false;
    fraction = std::strtod(("0." + text.substr(begin, at - begin)).c_str(), nullptr);
  }
  int offset_s = 0;
  if (at < text.size() && text[at] == 'Z') {
    ++at;
  } else if (at < text.size() && (text[at] == '+' || text[at] == '-')) {
    const int sign = text[at++] == '-' ? -1 : 1;
    int offset_h = 0, offset_m = 0;
    if (!ReadDigits(text, &at, 2, &offset_h)) return false;
    if (at < text.size() && text[at] == ':') ++at;
    if (!ReadDigits(text, &at, 2, &offset_m)) return false;
    offset_s = sign * (offset_h * 3600 + offset_m * 60);
  }
  if (at != text.size()) return false;
  timestamp->seconds =
      DaysFromCivil(year, month, day) * 86400 + hour * 3600 + minute * 60 + second - offset_s;
  timestamp->fraction = fraction;
  timestamp->decimals = decimals;
  timestamp->has_date = has_date;
  return true;
}

}  // namespace mbid::records::internal
