#include "mbid/common/error.h"

#include <fmt/format.h>

#include <string_view>
#include <utility>

#include "mbid/common/utf8.h"

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
