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

TEST(ErrorTest, MessagesStayOneLineAndUtf8) {
  // A quoted line break, tab or NUL and bytes that are not UTF-8 (a stray 0xff, a sequence cut
  // short) become \xNN; valid UTF-8 (an umlaut, a euro sign) stays as it is.
  EXPECT_EQ(OneLine("a\nb\tc"), "a\\x0ab\\x09c");
  EXPECT_EQ(OneLine(std::string("x\0y", 3)), "x\\x00y");
  EXPECT_EQ(OneLine("M\xc3\xa4rz \xe2\x82\xac"), "M\xc3\xa4rz \xe2\x82\xac");
  EXPECT_EQ(OneLine("bad\xff byte"), "bad\\xff byte");
  EXPECT_EQ(OneLine("cut \xe2\x82"), "cut \\xe2\\x82");
  const InputError e("f.yaml", "line 3", "unknown escape \x01\n", "valid YAML");
  EXPECT_STREQ(e.what(), "f.yaml:line 3: unknown escape \\x01\\x0a; expected valid YAML");
}

}  // namespace
}  // namespace mbid
