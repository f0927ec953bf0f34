#include "mbid/app/exit_code.h"

#include "mbid/common/error.h"

namespace mbid::app {

ExitCode ExitCodeFor(const std::exception& error) {
  if (dynamic_cast<const InputError*>(&error) != nullptr) return ExitCode::kInvalidInput;
  if (dynamic_cast<const NumericalError*>(&error) != nullptr) return ExitCode::kNumericalFailure;
  return ExitCode::kOther;
}

}  // namespace mbid::app
