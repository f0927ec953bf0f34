#pragma once

// Numbers as loggers print them (docs/records.md, "Thousands separators"): a decimal point or a
// decimal comma, and the integer part's digits grouped in thousands by the other mark (1,234.5
// and 1.234,5) or by a space (1 234,5; also U+00A0, U+202F, U+2009). A cell such as "1,234" reads
// both ways; the file's other numbers decide which (csv_reader.cc).

#include <cmath>
#include <optional>
#include <string_view>

namespace mbid::records::internal {

enum class DecimalMark { kUnknown, kPoint, kComma };

struct NumberReadings {
  std::optional<double> point;  // with a decimal point (',' or spaces grouping)
  std::optional<double> comma;  // with a decimal comma ('.' or spaces grouping)
  bool point_grouped = false, comma_grouped = false;  // the reading used a thousands separator

  // Both readings hold and differ: "1,234" is 1.234 or 1234.
  bool Ambiguous() const {
    return point && comma && *point != *comma && !(std::isnan(*point) && std::isnan(*comma));
  }
  // The decimal mark the cell shows: the one of the only reading that holds; kUnknown when both
  // or neither hold.
  DecimalMark Evidence() const;
  // The value with `mark` (kUnknown: the readings' common value), if it reads so.
  std::optional<double> With(DecimalMark mark, bool* grouped = nullptr) const;
};

// A reading holds when the whole cell is a decimal number with that mark: an optional sign,
// the integer part (groups of 3 digits after a first group of 1-3 not starting with 0, one kind
// of separator throughout, or plain digits), an optional fraction of digits and, without
// grouping, an optional exponent. "nan" and "inf" read as themselves both ways.
NumberReadings ReadNumber(std::string_view cell);

}  // namespace mbid::records::internal
