#include "steps.h"

namespace mbid::app::internal {

// Model updating (issue 5) has not been committed yet: the step says so for each case.
void RunUpdateStep(const StepInput& /*input*/, CaseOutcome& /*outcome*/) {
  throw StepNotAvailable("update: not available in this build (the updating library is missing)");
}

}  // namespace mbid::app::internal
