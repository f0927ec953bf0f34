#pragma once

#include <exception>

namespace mbid::app {

// Exit codes of the `mbid` command (docs/interfaces.md: contracts). They belong to the command
// line alone: the libraries throw InputError / NumericalError and return results that say
// converged, solved or stopped, which the commands map here.
enum class ExitCode : int { kSuccess = 0, kOther = 1, kInvalidInput = 2, kNumericalFailure = 3 };

// The exit code of the contract for an exception that reached the command line.
ExitCode ExitCodeFor(const std::exception& error);

}  // namespace mbid::app
