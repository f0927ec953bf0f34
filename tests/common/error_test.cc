// Message formats and exit codes of the error contract (docs/interfaces: exit codes).
#include "mbid/common/error.h"

#include <gtest/gtest.h>

#include <stdexcept>

namespace mbid {
namespace {

// The numbers inside the messages below are arbitrary examples; only the layout matters.
TEST(ErrorTest, InputErrorMessageHasSourceFieldProblemExpected) {
  const InputError e("scenario.yaml", "model.base.mass_kg", "negative value -3", "a number > 0");
  EXPECT_STREQ(e.what(),
               "scenario.yaml:model.base.mass_kg: negative value -3; expected a number > 0");
  EXPECT_EQ(e.source(), "scenario.yaml");
  EXPECT_EQ(e.field(), "model.base.mass_kg");
  EXPECT_EQ(e.problem(), "negative value -3");
  EXPECT_EQ(e.expected(), "a number > 0");
}

TEST(ErrorTest, InputErrorWithoutFieldOmitsTheColon) {
  const InputError e("data.h5", "", "not an HDF5 file", "an HDF5 file");
  EXPECT_STREQ(e.what(), "data.h5: not an HDF5 file; expected an HDF5 file");
}

TEST(ErrorTest, NumericalErrorMessageIsStageAndReason) {
  const NumericalError e("CVODES", "too much work at t = 1.5");
  EXPECT_STREQ(e.what(), "CVODES: too much work at t = 1.5");
  EXPECT_EQ(e.stage(), "CVODES");
  EXPECT_EQ(e.reason(), "too much work at t = 1.5");
}

}  // namespace
}  // namespace mbid
