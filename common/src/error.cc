#include "mbid/common/error.h"

#include <fmt/format.h>

#include <utility>

namespace mbid {
namespace {

std::string FormatInputError(const std::string& source, const std::string& field,
                             const std::string& problem, const std::string& expected) {
  std::string message = source;
  if (!field.empty()) message += ":" + field;
  message += ": " + problem;
  if (!expected.empty()) message += "; expected " + expected;
  return OneLine(message);
}

// Length of the valid UTF-8 sequence at text[i], 0 if it is not one (RFC 3629: no overlong
// forms, no surrogates, nothing above U+10FFFF).
size_t Utf8SequenceLength(const std::string& text, size_t i) {
  const auto byte = [&](size_t k) { return static_cast<unsigned char>(text[k]); };
  const unsigned char lead = byte(i);
  size_t length = 0;
  unsigned char low = 0x80, high = 0xBF;
  if (lead >= 0xC2 && lead <= 0xDF) {
    length = 2;
  } else if (lead >= 0xE0 && lead <= 0xEF) {
    length = 3;
    if (lead == 0xE0) low = 0xA0;
    if (lead == 0xED) high = 0x9F;
  } else if (lead >= 0xF0 && lead <= 0xF4) {
    length = 4;
    if (lead == 0xF0) low = 0x90;
    if (lead == 0xF4) high = 0x8F;
  } else {
    return 0;
  }
  if (i + length > text.size()) return 0;
  if (byte(i + 1) < low || byte(i + 1) > high) return 0;
  for (size_t k = 2; k < length; ++k) {
    if (byte(i + k) < 0x80 || byte(i + k) > 0xBF) return 0;
  }
  return length;
}

}  // namespace

std::string OneLine(const std::string& text) {
  std::string line;
  line.reserve(text.size());
  for (size_t i = 0; i < text.size();) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c >= 0x20 && c < 0x7F) {
      line += text[i++];
    } else if (c >= 0x80 && Utf8SequenceLength(text, i) > 0) {
      const size_t length = Utf8SequenceLength(text, i);
      line.append(text, i, length);
      i += length;
    } else {
      line += fmt::format("\\x{:02x}", c);  // a control character or a stray byte
      ++i;
    }
  }
  return line;
}

InputError::InputError(std::string source, std::string field, std::string problem,
                       std::string expected)
    : std::runtime_error(FormatInputError(source, field, problem, expected)),
      source_(std::move(source)),
      field_(std::move(field)),
      problem_(std::move(problem)),
      expected_(std::move(expected)) {}

NumericalError::NumericalError(std::string stage, std::string reason)
    : std::runtime_error(OneLine(stage + ": " + reason)),
      stage_(std::move(stage)),
      reason_(std::move(reason)) {}

}  // namespace mbid
