#include "mbid/common/error.h"

#include <fmt/format.h>

#include <string_view>
#include <utility>

#include "mbid/common/utf8.h"

namespace mbid {
namespace {

// `text` cut to its first and last characters where it is longer than `limit` bytes: a message
// quotes file contents, and a 5 MB cell made a 5 MB error line. Cuts fall between UTF-8
// characters.
std::string Shorten(const std::string& text, size_t limit) {
  if (text.size() <= limit) return text;
  const auto boundary = [&text](size_t at) {
    while (at > 0 && at < text.size() && (static_cast<unsigned char>(text[at]) & 0xC0) == 0x80) {
      --at;
    }
    return at;
  };
  const size_t head = boundary(limit * 3 / 4);
  const size_t tail = boundary(text.size() - limit / 4);
  return text.substr(0, head) + fmt::format(" [... {} bytes ...] ", tail - head) +
         text.substr(tail);
}

std::string FormatInputError(const std::string& source, const std::string& field,
                             const std::string& problem, const std::string& expected) {
  constexpr size_t kLimit = 400;  // per part: a path, a key path, a problem, what was expected
  std::string message = Shorten(source, kLimit);
  if (!field.empty()) message += ":" + Shorten(field, kLimit);
  message += ": " + Shorten(problem, kLimit);
  if (!expected.empty()) message += "; expected " + Shorten(expected, kLimit);
  return OneLine(message);
}

}  // namespace

std::string OneLine(const std::string& text) {
  std::string line;
  line.reserve(text.size());
  const auto escape = [&line](unsigned char c) { line += fmt::format("\\x{:02x}", c); };
  for (size_t i = 0; i < text.size();) {
    const size_t bad = FindInvalidUtf8(std::string_view(text).substr(i));
    const size_t end = bad == std::string_view::npos ? text.size() : i + bad;
    for (; i < end; ++i) {  // valid UTF-8: only control characters to escape
      const auto c = static_cast<unsigned char>(text[i]);
      if (c < 0x20 || c == 0x7F) {
        escape(c);
      } else {
        line += text[i];
      }
    }
    if (i < text.size()) escape(static_cast<unsigned char>(text[i++]));  // a stray byte
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
