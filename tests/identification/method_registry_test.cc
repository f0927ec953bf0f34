// The registry of identification methods (docs/extending.md): names, parsing, dispatch and the
// error for a method no file registers.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "mbid/common/error.h"
#include "mbid/identification/identify.h"
#include "mbid/identification/options.h"
#include "signals.h"

namespace mbid::identification {
namespace {

using testing::MakeRecord;
using testing::SignalSpec;
using testing::Synthesize;

SignalSpec OneMode() {
  SignalSpec spec;
  spec.channels = {"a"};
  spec.sample_interval_s = 0.01;
  spec.samples = 600;
  spec.modes = {{1.5, 0.5, {1.0}, {0.3}}};
  return spec;
}

TEST(MethodRegistryTest, ListsTheBuiltInMethodsInOrder) {
  // The order of the `--method` choices and of the scenario error's list.
  EXPECT_EQ(MethodNames(), (std::vector<std::string>{"hankel-nls", "prony-svd"}));
  EXPECT_EQ(MethodName(Method::kHankelNls), "hankel-nls");
  EXPECT_EQ(MethodName(Method::kPronySvd), "prony-svd");
  EXPECT_EQ(IdentificationOptions().method, Method::kHankelNls);
}

TEST(MethodRegistryTest, ParsesOnlyRegisteredNames) {
  Method method = Method::kHankelNls;
  EXPECT_TRUE(ParseMethod("prony-svd", &method));
  EXPECT_EQ(method, Method::kPronySvd);
  EXPECT_FALSE(ParseMethod("prony", &method));
  EXPECT_EQ(method, Method::kPronySvd);  // unchanged
}

TEST(MethodRegistryTest, EachMethodRunsUnderItsName) {
  const SignalSpec spec = OneMode();
  for (const std::string& name : MethodNames()) {
    IdentificationOptions options;
    ASSERT_TRUE(ParseMethod(name, &options.method));
    options.prony.order = 6;
    const ModalResult result = Identify(MakeRecord(spec, Synthesize(spec)), options);
    EXPECT_EQ(result.method, name);
    ASSERT_EQ(result.modes.size(), 1u) << name;
    EXPECT_NEAR(result.modes[0].frequency_hz, 1.5, 1e-6) << name;
  }
}

TEST(MethodRegistryTest, AnUnregisteredMethodIsAnOptionError) {
  IdentificationOptions options;
  options.method = Method("matrix-pencil");
  EXPECT_FALSE(options.IsValid());
  const SignalSpec spec = OneMode();
  try {
    Identify(MakeRecord(spec, Synthesize(spec)), options);
    FAIL() << "identified with an unregistered method";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()),
              "identification options:method: unknown method 'matrix-pencil'; expected one of "
              "hankel-nls, prony-svd");
  }
}

}  // namespace
}  // namespace mbid::identification
