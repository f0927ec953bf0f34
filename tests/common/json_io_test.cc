// JSON summaries: pretty, atomic, and never a silent null for a bad number.
#include "mbid/common/json_io.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <limits>
#include <sstream>

#include "test_util.h"

namespace mbid {
namespace {

using testing::CatchInputError;
using ::testing::HasSubstr;
using testing::TempDir;

nlohmann::json Summary() {
  return {{"channels", {"psi", "phi"}},
          {"sample_interval_s", 0.01},  // 100 Hz, inexact in binary: tests the digits
          {"samples", 1000},            // an integer stays an integer
          {"modes",
           {{{"frequency_hz", 1.155},  // values from docs/interfaces' example
             {"decay_rate_per_s", 6.77},
             {"amplitude", {{"psi", 0.0112}, {"phi", 0.0055}}}}}},
          {"passed", true}};
}

TEST(JsonIoTest, RoundTripIsExact) {
  TempDir dir;
  const std::string path = dir.File("summary.json");
  WriteJson(Summary(), path);
  EXPECT_EQ(ReadJson(path), Summary());
  EXPECT_EQ(dir.Entries(), std::vector<std::string>{"summary.json"});  // no temporary left
}

TEST(JsonIoTest, OutputIsIndentedByTwoSpaces) {
  TempDir dir;
  const std::string path = dir.File("summary.json");
  WriteJson({{"a", 1}}, path);  // 1: any value
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_EQ(text.str(), "{\n  \"a\": 1\n}\n");  // the value written above
}

TEST(JsonIoTest, DashWritesToStandardOutput) {
  TempDir dir;
  ::testing::internal::CaptureStdout();
  WriteJson({{"a", 1}}, "-");                                                 // 1: any value
  EXPECT_EQ(::testing::internal::GetCapturedStdout(), "{\n  \"a\": 1\n}\n");  // as written
}

// A rigid-body pole's decay rate is -Re(0) = -0.0: no sign the result has, so none is printed.
TEST(JsonIoTest, NegativeZeroIsWrittenAsZero) {
  ::testing::internal::CaptureStdout();
  WriteJson({{"decay_rate_per_s", -0.0}, {"phase_rad", {-0.0, -1.5}}}, "-");
  EXPECT_EQ(::testing::internal::GetCapturedStdout(),
            "{\n  \"decay_rate_per_s\": 0.0,\n  \"phase_rad\": [\n    0.0,\n    -1.5\n  ]\n}\n");
}

TEST(JsonIoTest, NonFiniteNumberThrowsNamingTheKeyAndWritesNothing) {
  TempDir dir;
  nlohmann::json summary = Summary();
  summary["modes"][0]["decay_rate_per_s"] = std::numeric_limits<double>::quiet_NaN();  // mode 0
  const std::string path = dir.File("summary.json");
  try {
    WriteJson(summary, path);
    ADD_FAILURE() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), HasSubstr("/modes/0/decay_rate_per_s"));  // the NaN's JSON pointer
  }
  EXPECT_TRUE(dir.Entries().empty());
}

TEST(JsonIoTest, ParseErrorNamesFileAndLine) {
  TempDir dir;
  const std::string path = dir.File("bad.json");
  testing::WriteText(path, "{\n  \"a\": 1,\n  \"b\": tru\n}\n");  // line 3 has a bad literal
  const InputError e = CatchInputError([&] { ReadJson(path); });
  EXPECT_EQ(e.source(), path);
  EXPECT_EQ(e.field(), "line 3");  // where 'tru' is
  EXPECT_EQ(e.expected(), "valid JSON");
}

TEST(JsonIoTest, MissingFileCannotOpen) {
  TempDir dir;
  const std::string path = dir.File("absent.json");
  const InputError e = CatchInputError([&] { ReadJson(path); });
  EXPECT_EQ(e.source(), path);
  EXPECT_THAT(e.problem(), HasSubstr("cannot open"));
}

}  // namespace
}  // namespace mbid
