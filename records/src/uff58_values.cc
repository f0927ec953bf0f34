// The data values of a dataset 58: ASCII in fixed-width or blank-separated fields, binary 58b.

#include <fmt/format.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "mbid/common/error.h"
#include "text_util.h"
#include "uff58_internal.h"

namespace mbid::records::internal {

bool HostIsLittleEndian() {
  const std::uint16_t probe = 1;
  unsigned char first = 0;
  std::memcpy(&first, &probe, 1);
  return first == 1;
}

std::vector<double> Uff58Reader::DecodeBinary(std::string_view data, size_t width,
                                              bool big_endian) const {
  const bool swap = big_endian == HostIsLittleEndian();
  std::vector<double> numbers(data.size() / width);
  unsigned char word[8];
  for (size_t i = 0; i < numbers.size(); ++i) {
    std::memcpy(word, data.data() + i * width, width);
    if (swap) std::reverse(word, word + width);
    if (width == 4) {
      float value = 0;
      std::memcpy(&value, word, 4);
      numbers[i] = value;
    } else {
      std::memcpy(&numbers[i], word, 8);
    }
  }
  return numbers;
}

// After binary data: an optional line end, then the closing -1. After ASCII data: the -1.
void Uff58Reader::ExpectClosing(const Dataset& d, bool binary) {
  auto line = lines_.Next();
  if (binary && line && TrimView(*line).empty()) line = lines_.Next();
  if (!line) {
    throw InputError(path_, d.where, "the file ends without the closing -1",
                     "the data, then a line '    -1'");
  }
  if (!IsDelimiter(*line)) {
    throw InputError(
        path_, LineField(lines_.line()),
        fmt::format("'{}' after the last of the declared values", TrimText(line->substr(0, 40))),
        "the closing line '    -1'");
  }
}

// Values in fixed-width fields, E13.5 for single and E20.12 for double precision (an uneven
// double record alternates E13.5 abscissae and E20.12 ordinates). A line whose fields do not
// parse at those widths is read as blank-separated numbers.
std::vector<double> Uff58Reader::ReadAsciiValues(const Dataset& d, size_t value_count,
                                                 bool single) {
  std::vector<double> numbers;
  // Every value takes at least two bytes (a digit and a separator or line end).
  if (value_count > lines_.remaining() / 2) {
    throw InputError(path_, fmt::format("{}, record 7", d.where),
                     fmt::format("{} values declared with {} bytes left in the file", value_count,
                                 lines_.remaining()),
                     "no more values than the file holds");
  }
  numbers.reserve(value_count);
  while (numbers.size() < value_count) {
    auto line = lines_.Next();
    if (!line || IsDelimiter(*line)) {
      throw InputError(path_, line ? LineField(lines_.line()) : d.where,
                       fmt::format("the dataset ends after {} of {} declared values",
                                   numbers.size(), value_count),
                       "as many values as record 7 declares");
    }
    if (!ParseFixed(*line, single, d.even, value_count, &numbers) &&
        !ParseBlankSeparated(*line, value_count, &numbers)) {
      throw InputError(path_, LineField(lines_.line()),
                       fmt::format("'{}' is not a line of numbers", TrimText(line->substr(0, 80))),
                       single ? "values in format 6E13.5" : "values in format 4E20.12");
    }
  }
  ExpectClosing(d, /*binary=*/false);
  return numbers;
}

bool Uff58Reader::ParseFixed(std::string_view line, bool single, bool even, size_t limit,
                             std::vector<double>* numbers) {
  const size_t mark = numbers->size();
  size_t at = 0;
  size_t k = mark;
  while (at < line.size()) {
    const size_t width = single || (!even && k % 2 == 0) ? 13 : 20;
    const std::string_view field = TrimView(line.substr(at, width));
    at += width;
    if (field.empty()) {
      if (TrimView(line.substr(std::min(at, line.size()))).empty()) break;
      numbers->resize(mark);
      return false;
    }
    double value = 0;
    if (!ParseNumber(field, &value) || numbers->size() >= limit) {
      numbers->resize(mark);
      return false;
    }
    numbers->push_back(value);
    ++k;
  }
  return numbers->size() > mark;
}

bool Uff58Reader::ParseBlankSeparated(std::string_view line, size_t limit,
                                      std::vector<double>* numbers) {
  const size_t mark = numbers->size();
  for (const std::string_view token : SplitWhitespace(line)) {
    double value = 0;
    if (!ParseNumber(token, &value) || numbers->size() >= limit) {
      numbers->resize(mark);
      return false;
    }
    numbers->push_back(value);
  }
  return numbers->size() > mark;
}

}  // namespace mbid::records::internal
