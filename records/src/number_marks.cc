#include "number_marks.h"

#include <string>

#include "internal.h"

namespace mbid::records::internal {
namespace {

constexpr char kGroup = 'G';  // the reading's thousands separator, in the normalized text
constexpr char kSpace = 'S';  // a space used as one

// Valid thousands grouping of `digits` (sign removed) split at `separator`: a first group of 1-3
// digits not starting with 0, then groups of exactly 3.
bool ValidGroups(const std::string& digits, char separator) {
  size_t at = 0;
  bool first = true;
  while (true) {
    const size_t end = std::min(digits.find(separator, at), digits.size());
    const size_t length = end - at;
    if (first ? (length < 1 || length > 3 || digits[at] == '0') : length != 3) return false;
    for (size_t i = at; i < end; ++i) {
      if (digits[i] < '0' || digits[i] > '9') return false;
    }
    if (end == digits.size()) return true;
    at = end + 1;
    first = false;
  }
}

std::optional<double> ReadWith(std::string_view cell, char decimal, char group, bool* grouped) {
  *grouped = false;
  std::string text;
  text.reserve(cell.size());
  for (size_t i = 0; i < cell.size(); ++i) {
    const char c = cell[i];
    if (c == decimal) {
      text += '.';
    } else if (c == group) {
      text += kGroup;
    } else if (c == ' ') {
      text += kSpace;
    } else if (cell.compare(i, 2, "\xC2\xA0") == 0) {  // no-break space
      text += kSpace;
      i += 1;
    } else if (cell.compare(i, 3, "\xE2\x80\xAF") == 0 || cell.compare(i, 3, "\xE2\x80\x89") == 0) {
      text += kSpace;  // narrow no-break space, thin space
      i += 2;
    } else {
      text += c;
    }
  }
  const size_t separator_at = text.find_first_of("GS");
  double value = 0;
  if (separator_at == std::string::npos) {
    if (mbid::internal::ParseDouble(text, &value) != mbid::internal::ParseStatus::kOk) {
      return std::nullopt;
    }
    return value;
  }
  const char separator = text[separator_at];
  const size_t sign = !text.empty() && (text[0] == '-' || text[0] == '+') ? 1 : 0;
  const size_t point = std::min(text.find('.'), text.size());
  if (text.find_first_of("eE") != std::string::npos) return std::nullopt;  // no exponent then
  if (text.find_first_of("GS", point) != std::string::npos) return std::nullopt;
  const std::string integer = text.substr(sign, point - sign);
  if (integer.find(separator == kGroup ? kSpace : kGroup) != std::string::npos) {
    return std::nullopt;  // one kind of separator
  }
  if (!ValidGroups(integer, separator)) return std::nullopt;
  std::string plain = text.substr(0, sign);
  for (const char c : integer) {
    if (c != separator) plain += c;
  }
  plain += text.substr(point);
  if (mbid::internal::ParseDouble(plain, &value) != mbid::internal::ParseStatus::kOk) {
    return std::nullopt;
  }
  *grouped = true;
  return value;
}

}  // namespace

DecimalMark NumberReadings::Evidence() const {
  if (point && !comma) return DecimalMark::kPoint;
  if (comma && !point) return DecimalMark::kComma;
  return DecimalMark::kUnknown;
}

std::optional<double> NumberReadings::With(DecimalMark mark, bool* grouped) const {
  bool ignored = false;
  bool* used = grouped != nullptr ? grouped : &ignored;
  switch (mark) {
    case DecimalMark::kPoint:
      *used = point_grouped;
      return point;
    case DecimalMark::kComma:
      *used = comma_grouped;
      return comma;
    case DecimalMark::kUnknown:
      break;
  }
  if (Ambiguous()) return std::nullopt;
  *used = point ? point_grouped : comma_grouped;
  return point ? point : comma;
}

NumberReadings ReadNumber(std::string_view cell) {
  NumberReadings readings;
  if (cell.find_first_of(", \xC2\xE2") == std::string_view::npos) {
    // The common case (mbid's own files, most loggers): no comma and no space, so the decimal
    // point reading is the plain number, and without a '.' the comma reading is the same.
    double value = 0;
    if (mbid::internal::ParseDouble(cell, &value) == mbid::internal::ParseStatus::kOk) {
      readings.point = value;
    }
    if (cell.find('.') == std::string_view::npos) {
      readings.comma = readings.point;
    } else {
      readings.comma = ReadWith(cell, ',', '.', &readings.comma_grouped);
    }
    return readings;
  }
  readings.point = ReadWith(cell, '.', ',', &readings.point_grouped);
  readings.comma = ReadWith(cell, ',', '.', &readings.comma_grouped);
  return readings;
}

}  // namespace mbid::records::internal
