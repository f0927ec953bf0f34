#pragma once

#include <stdexcept>
#include <string>

namespace mbid {

// Input that breaks a contract: a file, field, flag or sample. The message has the form
// "<source>[:<field>]: <problem>; expected <expected>" and is exit code 2 of the command line.
class InputError : public std::runtime_error {
 public:
  InputError(std::string source, std::string field, std::string problem, std::string expected);

  const std::string& source() const { return source_; }
  const std::string& field() const { return field_; }
  const std::string& problem() const { return problem_; }
  const std::string& expected() const { return expected_; }

 private:
  std::string source_, field_, problem_, expected_;
};

// A numerical method that failed on valid input (integrator, optimizer, no modes found).
// `stage` names the method ("CVODES", "Ceres", "identification"), `reason` says why, in the
// method's own words where it has them. Exit code 3 of the command line.
class NumericalError : public std::runtime_error {
 public:
  NumericalError(std::string stage, std::string reason);

  const std::string& stage() const { return stage_; }
  const std::string& reason() const { return reason_; }

 private:
  std::string stage_, reason_;
};

// `text` made fit for one line of a message: control characters (line breaks, tabs, NUL) and
// bytes that are not UTF-8 become "\xNN". Messages quote file contents; a quoted line break
// or a stray byte must not break the one-line contract or the JSON written from them.
std::string OneLine(const std::string& text);

}  // namespace mbid
