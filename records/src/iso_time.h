#pragma once

// Timestamps as loggers print them: ISO 8601 "2026-03-01T12:00:00.125" (a space instead of the
// T, optional "Z" or "+01:00" / "-0500"), the date also as "2026/03/01" or day first
// "01.03.2026", a decimal comma in the seconds, or the time of day alone ("12:00:00,125").

#include <cstdint>
#include <string>

namespace mbid::records::internal {

struct Timestamp {
  std::int64_t seconds = 0;  // since 1970-01-01T00:00:00 UTC (local time when no offset)
  double fraction = 0.0;     // [0, 1)
  int decimals = 0;          // digits printed after the seconds' point
  bool has_date = true;      // false for a time of day alone (seconds since midnight)
};

// Parses all of `text`; false when it is not such a timestamp.
bool ParseTimestamp(const std::string& text, Timestamp* timestamp);

// Parses all of `text` as a date alone ("2026-03-01", "2026/03/01", "01.03.2026"): its midnight.
bool ParseDate(const std::string& text, Timestamp* date);

// b - a in seconds; exact to the printed digits for records of any date (the integer seconds
// are subtracted before the fraction is added).
inline double SecondsBetween(const Timestamp& a, const Timestamp& b) {
  return static_cast<double>(b.seconds - a.seconds) + (b.fraction - a.fraction);
}

}  // namespace mbid::records::internal
