#pragma once

// Timestamps as loggers print them: ISO 8601 "2026-03-01T12:00:00.125" (a space instead of the
// T, optional "Z" or "+01:00" / "-0500"), the date also as "2026/03/01", day first
// "01.03.2026", or "01/03/2026" day or month first (as the record's dates tell, csv_reader.cc),
// a decimal comma in the seconds, or the time of day alone ("12:00:00,125").

#include <cstdint>
#include <string>

namespace mbid::records::internal {

struct Timestamp {
  std::int64_t seconds = 0;  // since 1970-01-01T00:00:00 UTC (local time when no offset)
  double fraction = 0.0;     // [0, 1)
  int decimals = 0;          // digits printed after the seconds' point
  bool has_date = true;      // false for a time of day alone (seconds since midnight)
};

// How "01/03/2026" reads: the 1st of March (day first, as in Europe) or January 3rd (month
// first, as in the US).
enum class SlashOrder { kDayFirst, kMonthFirst };

// Parses all of `text`; false when it is not such a timestamp.
bool ParseTimestamp(const std::string& text, Timestamp* timestamp,
                    SlashOrder order = SlashOrder::kDayFirst);

// Parses all of `text` as a date alone ("2026-03-01", "2026/03/01", "01.03.2026",
// "01/03/2026"): its midnight.
bool ParseDate(const std::string& text, Timestamp* date, SlashOrder order = SlashOrder::kDayFirst);

// The fields of a "NN/NN/YYYY" date at the start of `text`; false when it has none.
bool ReadSlashDate(const std::string& text, int* first, int* second, int* year);

// Days from 1970-01-01 to the proleptic Gregorian date y-m-d.
std::int64_t DaysFromCivil(std::int64_t y, int m, int d);

// b - a in seconds; exact to the printed digits for records of any date (the integer seconds
// are subtracted before the fraction is added).
inline double SecondsBetween(const Timestamp& a, const Timestamp& b) {
  return static_cast<double>(b.seconds - a.seconds) + (b.fraction - a.fraction);
}

}  // namespace mbid::records::internal
