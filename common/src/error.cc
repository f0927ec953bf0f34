#include "mbid/common/error.h"

#include <utility>

namespace mbid {
namespace {

std::string FormatInputError(const std::string& source, const std::string& field,
                             const std::string& problem, const std::string& expected) {
  std::string message = source;
  if (!field.empty()) message += ":" + field;
  message += ": " + problem;
  if (!expected.empty()) message += "; expected " + expected;
  return message;
}

}  // namespace

InputError::InputError(std::string source, std::string field, std::string problem,
                       std::string expected)
    : std::runtime_error(FormatInputError(source, field, problem, expected)),
      source_(std::move(source)),
      field_(std::move(field)),
      problem_(std::move(problem)),
      expected_(std::move(expected)) {}

NumericalError::NumericalError(std::string stage, std::string reason)
    : std::runtime_error(stage + ": " + reason),
      stage_(std::move(stage)),
      reason_(std::move(reason)) {}

}  // namespace mbid
