#include "mbid/common/utf8.h"

#include <fmt/format.h>

#include <algorithm>

#include "mbid/common/error.h"

namespace mbid {
namespace {

constexpr char kExpected[] = "UTF-8 text (convert other encodings, e.g. iconv -f latin1 -t utf-8)";

bool IsContinuation(unsigned char c) { return (c & 0xC0) == 0x80; }

// Length of the valid sequence starting at `at`, or 0.
size_t SequenceLength(std::string_view text, size_t at) {
  const auto byte = [&](size_t i) { return static_cast<unsigned char>(text[at + i]); };
  const unsigned char lead = byte(0);
  if (lead < 0x80) return 1;
  size_t length = 0;
  unsigned char low = 0x80, high = 0xBF;  // allowed range of the second byte
  if (lead >= 0xC2 && lead <= 0xDF) {
    length = 2;
  } else if (lead >= 0xE0 && lead <= 0xEF) {
    length = 3;
    if (lead == 0xE0) low = 0xA0;   // overlong
    if (lead == 0xED) high = 0x9F;  // surrogates
  } else if (lead >= 0xF0 && lead <= 0xF4) {
    length = 4;
    if (lead == 0xF0) low = 0x90;   // overlong
    if (lead == 0xF4) high = 0x8F;  // above U+10FFFF
  } else {
    return 0;
  }
  if (at + length > text.size()) return 0;
  if (byte(1) < low || byte(1) > high) return 0;
  for (size_t i = 2; i < length; ++i) {
    if (!IsContinuation(byte(i))) return 0;
  }
  return length;
}

std::string DescribeByte(std::string_view text, size_t at) {
  return fmt::format("invalid UTF-8: byte 0x{:02X}",
                     static_cast<unsigned>(static_cast<unsigned char>(text[at])));
}

}  // namespace

size_t FindInvalidUtf8(std::string_view text) {
  size_t at = 0;
  while (at < text.size()) {
    const size_t length = SequenceLength(text, at);
    if (length == 0) return at;
    at += length;
  }
  return std::string_view::npos;
}

void ValidateUtf8(std::string_view text, const std::string& source, const std::string& field) {
  const size_t at = FindInvalidUtf8(text);
  if (at == std::string_view::npos) return;
  throw InputError(source, field, fmt::format("{} at byte {}", DescribeByte(text, at), at + 1),
                   kExpected);
}

void ValidateUtf8Text(std::string_view text, const std::string& source) {
  size_t at = FindInvalidUtf8(text);
  // A NUL byte is valid UTF-8 but no text: zeroed blocks of a damaged file, a logger's unfinished
  // write. YAML read it as "not a mapping".
  const size_t nul = text.find('\0');
  const bool is_nul = nul != std::string_view::npos && (at == std::string_view::npos || nul < at);
  if (is_nul) at = nul;
  if (at == std::string_view::npos) return;
  const size_t newline = at == 0 ? std::string_view::npos : text.rfind('\n', at - 1);
  const size_t column_start = newline == std::string_view::npos ? 0 : newline + 1;
  const auto line =
      1 + std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(at), '\n');
  if (is_nul) {
    throw InputError(source, fmt::format("line {}", line),
                     fmt::format("a NUL byte at column {} (zeroed blocks of a damaged file, or an "
                                 "unfinished write)",
                                 at - column_start + 1),
                     "text without NUL bytes: the file as its writer completed it");
  }
  throw InputError(source, fmt::format("line {}", line),
                   fmt::format("{} at column {}", DescribeByte(text, at), at - column_start + 1),
                   kExpected);
}

}  // namespace mbid
