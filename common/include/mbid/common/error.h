#pragma once

#include <stdexcept>
#include <string>

namespace mbid {

// Exit codes of the `mbid` command (docs/interfaces: contracts).
enum class ExitCode : int { kSuccess = 0, kOther = 1, kInvalidInput = 2, kNumericalFailure = 3 };

// Input that breaks a contract: a file, field, flag or sample. The message has the form
// "<source>[:<field>]: <problem>; expected <expected>" and maps to exit code 2.
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
// method's own words where it has them. Maps to exit code 3.
class NumericalError : public std::runtime_error {
 public:
  NumericalError(std::string stage, std::string reason);

  const std::string& stage() const { return stage_; }
  const std::string& reason() const { return reason_; }

 private:
  std::string stage_, reason_;
};

// The exit code of the contract for an exception that reached the command line.
ExitCode ExitCodeFor(const std::exception& error);

}  // namespace mbid
