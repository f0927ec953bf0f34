#include "mbid/app/exit_code.h"

#include <gtest/gtest.h>

#include <stdexcept>

#include "mbid/common/error.h"

namespace mbid::app {
namespace {

TEST(ExitCodeTest, ExceptionsMapToTheContract) {
  EXPECT_EQ(ExitCodeFor(InputError("a", "b", "c", "d")), ExitCode::kInvalidInput);
  EXPECT_EQ(ExitCodeFor(NumericalError("Ceres", "diverged")), ExitCode::kNumericalFailure);
  EXPECT_EQ(ExitCodeFor(std::runtime_error("disk full")), ExitCode::kOther);
  EXPECT_EQ(static_cast<int>(ExitCode::kInvalidInput), 2);      // contract: invalid input
  EXPECT_EQ(static_cast<int>(ExitCode::kNumericalFailure), 3);  // contract: numerical failure
  EXPECT_EQ(static_cast<int>(ExitCode::kOther), 1);             // contract: anything else
}

}  // namespace
}  // namespace mbid::app
