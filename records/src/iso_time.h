#pragma once

// ISO 8601 timestamps as loggers print them: "2026-03-01T12:00:00.125", a space instead of
// the T, optional "Z" or "+01:00" / "-0500".

#include <cstdint>
#include <string>

namespace mbid::records::internal {

struct Timestamp {
  std::int64_t seconds = 0;  // since 1970-01-01T00:00:00 UTC (local time when no offset)
  double fraction = 0.0;     // [0, 1)
  int decimals = 0;          // digits printed after the seconds' point
};

// Parses all of `text`; false when it is not such a timestamp.
bool ParseTimestamp(const std::string& text, Timestamp* timestamp);

// b - a in seconds; exact to the printed digits for records of any date (the integer seconds
// are subtracted before the fraction is added).
inline double SecondsBetween(const Timestamp& a, const Timestamp& b) {
  return static_cast<double>(b.seconds - a.seconds) + (b.fraction - a.fraction);
}

}  // namespace mbid::records::internal
