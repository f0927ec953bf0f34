// YamlReader: typed, strict access to scenario files; every bad input names the file and the
// dotted field (or the line for syntax errors).
#include "mbid/common/yaml_reader.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <tuple>

#include "test_util.h"

namespace mbid {
namespace {

using testing::CatchInputError;
using ::testing::HasSubstr;
using testing::TempDir;

const char kSource[] = "scenario.yaml";

// The base of the reference crane, with one line replaced by `line` (indented under base).
YamlReader Base(const std::string& line) {
  return YamlReader::FromString("model:\n  base:\n    " + line + "\n", kSource)
      .Child("model")
      .Child("base");
}

const std::vector<std::string> kBaseKeys = {"pitch_pivot_m", "mass_kg", "com_m", "inertia_kgm2"};

// Values as in the reference scenario, or arbitrary; each is checked against what is written.
TEST(YamlReaderTest, ReadsANestedDocument) {
  const YamlReader root = YamlReader::FromString(R"(
name: reference-crane
model:
  type: truck_crane
  base: {mass_kg: 24000, com_m: [0.5, 0, 1.25]}
simulation:
  duration_s: 10
  integrator: {method: bdf, relative_tolerance: 1e-8}
sensors:
  channels: [psi, phi]
  seed: 1
  verbose: true
)",
                                                 kSource);
  root.ExpectMap({"name", "model", "simulation", "sensors"});
  EXPECT_EQ(root.String("name"), "reference-crane");
  const YamlReader base = root.Child("model").Child("base");
  EXPECT_EQ(base.field(), "model.base");
  EXPECT_EQ(base.PositiveDouble("mass_kg"), 24000);  // as written
  const std::array<double, 3> com = base.Vector3("com_m");
  EXPECT_EQ(com[0], 0.5);   // as written
  EXPECT_EQ(com[1], 0.0);   // as written
  EXPECT_EQ(com[2], 1.25);  // as written
  const YamlReader simulation = root.Child("simulation");
  EXPECT_EQ(simulation.PositiveDouble("duration_s"), 10);  // as written
  EXPECT_EQ(simulation.Child("integrator").Choice("method", {"bdf", "adams"}, "adams"), "bdf");
  EXPECT_EQ(simulation.Child("integrator").Double("relative_tolerance"), 1e-8);  // as written
  EXPECT_EQ(simulation.Double("start_s", -1.5), -1.5);  // absent: the fallback comes back
  const YamlReader sensors = root.Child("sensors");
  EXPECT_EQ(sensors.StringList("channels"), (std::vector<std::string>{"psi", "phi"}));
  EXPECT_EQ(sensors.Int("seed"), 1);  // as written
  EXPECT_TRUE(sensors.Bool("verbose", false));
  EXPECT_EQ(root.Keys(), (std::vector<std::string>{"name", "model", "simulation", "sensors"}));
  EXPECT_FALSE(root.Has("updating"));
}

TEST(YamlReaderTest, EmptySectionIsAnEmptyMap) {
  const YamlReader root = YamlReader::FromString("identification:\n", kSource);
  const YamlReader section = root.Child("identification");
  EXPECT_NO_THROW(section.ExpectMap({"model_order"}));
  EXPECT_EQ(section.Int("model_order", 40), 40);  // absent: the fallback comes back
}

TEST(YamlReaderTest, ReadsFromFile) {
  TempDir dir;
  const std::string path = dir.File("s.yaml");
  testing::WriteText(path, "a: 2.5\n");  // 2.5: any number exact in binary
  const YamlReader root = YamlReader::FromFile(path);
  EXPECT_EQ(root.source(), path);
  EXPECT_EQ(root.Double("a"), 2.5);  // as written
}

TEST(YamlReaderTest, ClosestMatchUsesEditDistance) {
  EXPECT_EQ(ClosestMatch("mas_kg", kBaseKeys), "mass_kg");
  EXPECT_EQ(ClosestMatch("com", kBaseKeys), "com_m");
  EXPECT_EQ(ClosestMatch("x", {}), "");
}

// ---- one bad input per test --------------------------------------------------------------
// Numbers inside the YAML snippets are arbitrary unless a comment says why; the checked text
// repeats them.

// A folder named as a scenario: said as what it is (Linux opens it and reads nothing, which was
// then "not a mapping").
TEST(YamlReaderBadInputTest, AFolderIsSaidToBeOne) {
  TempDir dir;
  const InputError error = CatchInputError([&] { YamlReader::FromFile(dir.File(".")); });
  EXPECT_THAT(error.what(), HasSubstr(": is a folder; expected a YAML file"));
}

TEST(YamlReaderBadInputTest, UnknownKeySuggestsClosest) {
  const YamlReader base = Base("mas_kg: 24000");
  const InputError e = CatchInputError([&] { base.ExpectMap(kBaseKeys); });
  EXPECT_EQ(e.source(), kSource);
  EXPECT_EQ(e.field(), "model.base.mas_kg");
  EXPECT_EQ(e.problem(), "unknown key 'mas_kg'");
  EXPECT_THAT(e.expected(), HasSubstr("one of pitch_pivot_m, mass_kg, com_m, inertia_kgm2"));
  EXPECT_THAT(e.expected(), HasSubstr("did you mean 'mass_kg'?"));
}

TEST(YamlReaderBadInputTest, KeyWithoutUnitNamesTheUnit) {
  const YamlReader simulation =
      YamlReader::FromString("simulation:\n  duration: 10\n", kSource).Child("simulation");
  const InputError e = CatchInputError([&] { simulation.ExpectMap({"duration_s", "integrator"}); });
  EXPECT_EQ(e.source(), kSource);
  EXPECT_EQ(e.field(), "simulation.duration");
  EXPECT_STREQ(e.what(),
               "scenario.yaml:simulation.duration: key 'duration' has no unit; expected "
               "'duration_s'");
}

TEST(YamlReaderBadInputTest, MassWithoutUnitNamesTheUnit) {
  const YamlReader base = Base("mass: 24000");
  const InputError e = CatchInputError([&] { base.ExpectMap(kBaseKeys); });
  EXPECT_EQ(e.field(), "model.base.mass");
  EXPECT_EQ(e.problem(), "key 'mass' has no unit");
  EXPECT_EQ(e.expected(), "'mass_kg'");
}

TEST(YamlReaderBadInputTest, EveryUnitOfAKeyIsNamed) {
  // The sensors' noise comes in five units; rad/s ("radps") is the only five-letter unit word.
  const YamlReader sensors =
      YamlReader::FromString("sensors:\n  noise_std: 1\n", kSource).Child("sensors");
  const InputError e = CatchInputError([&] {
    sensors.ExpectMap({"noise_std_rad", "noise_std_m", "noise_std_mps", "noise_std_mps2",
                       "noise_std_radps", "seed"});
  });
  EXPECT_EQ(e.problem(), "key 'noise_std' has no unit");
  EXPECT_EQ(e.expected(),
            "'noise_std_rad' or 'noise_std_m' or 'noise_std_mps' or 'noise_std_mps2' or "
            "'noise_std_radps'");
}

TEST(YamlReaderBadInputTest, NumberWithUnitTextIsWrongType) {
  const YamlReader base = Base("mass_kg: 10 t");
  const InputError e = CatchInputError([&] { base.PositiveDouble("mass_kg"); });
  EXPECT_EQ(e.source(), kSource);
  EXPECT_EQ(e.field(), "model.base.mass_kg");
  EXPECT_EQ(e.problem(), "'10 t' is not a number");
}

TEST(YamlReaderBadInputTest, ListWhereNumberExpectedIsWrongType) {
  const YamlReader base = Base("mass_kg: [1, 2]");
  const InputError e = CatchInputError([&] { base.Double("mass_kg"); });
  EXPECT_EQ(e.field(), "model.base.mass_kg");
  EXPECT_THAT(e.problem(), HasSubstr("is a list, not a number"));
}

TEST(YamlReaderBadInputTest, QuotedNumberIsAString) {
  const YamlReader base = Base("mass_kg: \"24000\"");
  const InputError e = CatchInputError([&] { base.Double("mass_kg"); });
  EXPECT_EQ(e.field(), "model.base.mass_kg");
  EXPECT_THAT(e.problem(), HasSubstr("quoted string"));
}

TEST(YamlReaderBadInputTest, NegativeValueWherePositiveRequired) {
  const YamlReader base = Base("mass_kg: -3");  // -3: any negative number
  const InputError e = CatchInputError([&] { base.PositiveDouble("mass_kg"); });
  EXPECT_EQ(e.field(), "model.base.mass_kg");
  EXPECT_EQ(e.problem(), "negative value -3");
  EXPECT_EQ(e.expected(), "a number > 0");
}

TEST(YamlReaderBadInputTest, ZeroWherePositiveRequired) {
  const YamlReader base = Base("mass_kg: 0");  // 0: the boundary that Positive excludes
  const InputError e = CatchInputError([&] { base.PositiveDouble("mass_kg"); });
  EXPECT_EQ(e.field(), "model.base.mass_kg");
  EXPECT_EQ(e.problem(), "zero value 0");
}

TEST(YamlReaderBadInputTest, NaNIsRejected) {
  const YamlReader base = Base("mass_kg: .nan");
  const InputError e = CatchInputError([&] { base.Double("mass_kg"); });
  EXPECT_EQ(e.field(), "model.base.mass_kg");
  EXPECT_EQ(e.problem(), "'.nan' is not finite");
}

TEST(YamlReaderBadInputTest, InfinityIsRejected) {
  const YamlReader base = Base("mass_kg: .inf");
  const InputError e = CatchInputError([&] { base.PositiveDouble("mass_kg"); });
  EXPECT_EQ(e.field(), "model.base.mass_kg");
  EXPECT_EQ(e.problem(), "'.inf' is not finite");
}

TEST(YamlReaderBadInputTest, NegativeInfinityIsRejected) {
  const YamlReader base = Base("mass_kg: -.Inf");
  const InputError e = CatchInputError([&] { base.Double("mass_kg"); });
  EXPECT_EQ(e.field(), "model.base.mass_kg");
  EXPECT_THAT(e.problem(), HasSubstr("not finite"));
}

TEST(YamlReaderBadInputTest, OverflowIsRejected) {
  const YamlReader base = Base("mass_kg: 1e999");  // beyond the largest double (~1.8e308)
  const InputError e = CatchInputError([&] { base.Double("mass_kg"); });
  EXPECT_EQ(e.field(), "model.base.mass_kg");
  EXPECT_THAT(e.problem(), HasSubstr("out of the range"));
}

TEST(YamlReaderBadInputTest, MissingRequiredKey) {
  const YamlReader base = Base("com_m: [0, 0, 1]");
  const InputError e = CatchInputError([&] { base.PositiveDouble("mass_kg"); });
  EXPECT_EQ(e.source(), kSource);
  EXPECT_EQ(e.field(), "model.base.mass_kg");
  EXPECT_EQ(e.problem(), "missing required key 'mass_kg'");
}

TEST(YamlReaderBadInputTest, MissingRequiredSection) {
  const YamlReader root = YamlReader::FromString("name: x\n", kSource);
  const InputError e = CatchInputError([&] { root.Child("model"); });
  EXPECT_EQ(e.field(), "model");
}

TEST(YamlReaderBadInputTest, Vector3WithTwoElements) {
  const YamlReader base = Base("com_m: [0.5, 1]");  // 2 elements, one short
  const InputError e = CatchInputError([&] { base.Vector3("com_m"); });
  EXPECT_EQ(e.field(), "model.base.com_m");
  EXPECT_EQ(e.problem(), "has 2 elements");
  EXPECT_EQ(e.expected(), "a list of 3 numbers [x, y, z]");  // 3: x, y, z
}

TEST(YamlReaderBadInputTest, Vector3WithANonNumber) {
  const YamlReader base = Base("com_m: [0.5, up, 1]");  // element 1 is a word
  const InputError e = CatchInputError([&] { base.Vector3("com_m"); });
  EXPECT_EQ(e.field(), "model.base.com_m[1]");
  EXPECT_EQ(e.problem(), "'up' is not a number");
}

TEST(YamlReaderBadInputTest, Vector3GivenAsNumber) {
  const YamlReader base = Base("com_m: 0.5");
  const InputError e = CatchInputError([&] { base.Vector3("com_m"); });
  EXPECT_EQ(e.field(), "model.base.com_m");
  EXPECT_THAT(e.problem(), HasSubstr("not a list"));
}

TEST(YamlReaderBadInputTest, SyntaxErrorNamesTheLine) {
  TempDir dir;
  const std::string path = dir.File("broken.yaml");
  // A key without its colon on line 3.
  testing::WriteText(path, "name: x\nmodel:\n  com_m [0, 0, 1]\n  mass_kg: 3\n");
  const InputError e = CatchInputError([&] { YamlReader::FromFile(path); });
  EXPECT_EQ(e.source(), path);
  EXPECT_THAT(e.field(), HasSubstr("line "));
  EXPECT_EQ(e.expected(), "valid YAML");
}

// yaml-cpp reports a flow collection that is never closed where it gives up, lines later (a
// trial's file: "end of map flow not found" on the line of the next section): the error names
// the bracket that opened it. Brackets in quotes and comments do not count.
TEST(YamlReaderBadInputTest, AnUnclosedFlowIsNamedWhereItOpens) {
  for (const auto& [text, line, column, bracket] :
       {std::tuple{"name: x\nmodel: {type: truck_crane\nexcitation: {type: initial_deflection}\n",
                   "line 2", 8, "'{'"},
        std::tuple{"name: '[x'  # a [ in a comment\nmodel:\n  com_m: [0, 0, 1\n  mass_kg: 3\n"
                   "other: 1\n",
                   "line 3", 10, "'['"},
        std::tuple{"a: {b: [1, 2], c: \"}\", d: {e: 1}\nf: 2\n", "line 1", 4, "'{'"}}) {
    const InputError e = CatchInputError([&] { YamlReader::FromString(text, kSource); });
    EXPECT_EQ(e.field(), line) << text;
    EXPECT_THAT(e.problem(), HasSubstr("the " + std::string(bracket) + " at column " +
                                       std::to_string(column) + " is not closed"))
        << text;
    EXPECT_THAT(e.expected(), HasSubstr("closing it")) << text;
  }
}

// yaml-cpp reads a quoted scalar that is never closed to the end of the file, without an error:
// `name: "crane` said "missing required key 'model'", `type: "truck_crane` "unknown choice
// 'truck_crane '". The quote is named where it opens; apostrophes in words, quotes in comments
// and block scalars, '' and \" inside quotes, and quoted scalars closed on a later line are no
// error.
TEST(YamlReaderBadInputTest, AnUnclosedQuoteIsNamedWhereItOpens) {
  for (const auto& [text, line, column] :
       {std::tuple{"name: \"crane\nmodel: {type: truck_crane}\n", "line 1", 7},
        std::tuple{"name: crane\nmodel:\n  type: \"truck_crane\n", "line 3", 9},
        std::tuple{"name: crane  # the crane's\nlist:\n  - 'a''b'\n  - 'open\n", "line 4", 5},
        std::tuple{"a: [1, \"x]\n", "line 1", 8}}) {
    const InputError e = CatchInputError([&] { YamlReader::FromString(text, kSource); });
    EXPECT_EQ(e.field(), line) << text;
    EXPECT_THAT(e.problem(), HasSubstr("at column " + std::to_string(column) + " is not closed"))
        << text << e.what();
  }
  for (const char* text :
       {"description: the crane's boom\nname: 'it''s'  # don't\n",
        "note: |\n  \"a quote in a block\n  it's text\nname: x\n",
        "name: \"two \\\" lines\n  closed here\"\nother: 'yes'\n", "a: [\"x\", 'y']\n"}) {
    EXPECT_NO_THROW(YamlReader::FromString(text, kSource)) << text;
  }
}

TEST(YamlReaderBadInputTest, UnclosedFlowSequenceInStringNamesItsLine) {
  const InputError e = CatchInputError([] { YamlReader::FromString("a: 1\nb: [1, 2\n", kSource); });
  EXPECT_EQ(e.source(), kSource);
  EXPECT_THAT(e.field(), ::testing::MatchesRegex("line [23]"));  // the bracket opens on 2
}

TEST(YamlReaderBadInputTest, MissingFileCannotOpen) {
  TempDir dir;
  const std::string path = dir.File("absent.yaml");
  const InputError e = CatchInputError([&] { YamlReader::FromFile(path); });
  EXPECT_EQ(e.source(), path);
  EXPECT_THAT(e.problem(), HasSubstr("cannot open"));
}

TEST(YamlReaderBadInputTest, DuplicateKey) {
  const YamlReader base =
      YamlReader::FromString("model:\n  base:\n    mass_kg: 1\n    mass_kg: 2\n", kSource)
          .Child("model")
          .Child("base");
  const InputError e = CatchInputError([&] { base.ExpectMap(kBaseKeys); });
  EXPECT_EQ(e.field(), "model.base.mass_kg");
  EXPECT_THAT(e.problem(), HasSubstr("duplicate key"));
}

TEST(YamlReaderBadInputTest, UnknownChoiceListsChoices) {
  const YamlReader integrator =
      YamlReader::FromString("integrator: {method: bfd}\n", kSource).Child("integrator");
  const InputError e = CatchInputError([&] {
    integrator.Choice("method", {"bdf", "adams"}, "bdf");
  });
  EXPECT_EQ(e.field(), "integrator.method");
  EXPECT_EQ(e.problem(), "unknown choice 'bfd'");
  EXPECT_EQ(e.expected(), "one of bdf, adams; did you mean 'bdf'?");
}

TEST(YamlReaderBadInputTest, FractionWhereIntegerExpected) {
  const YamlReader sensors =
      YamlReader::FromString("sensors: {seed: 1.5}\n", kSource).Child("sensors");  // a fraction
  const InputError e = CatchInputError([&] { sensors.Int("seed"); });
  EXPECT_EQ(e.field(), "sensors.seed");
  EXPECT_EQ(e.problem(), "'1.5' is not an integer");
}

// A seed beyond either end of its range: one message, the same range (a negative one said
// ">= 0" while one beyond 2^31 said "between -2147483648 and 2147483647").
TEST(YamlReaderBadInputTest, ASeedOutOfRangeSaysItsRange) {
  for (const char* text : {"-4", "3000000000", "1e10"}) {
    const YamlReader sensors =
        YamlReader::FromString(std::string("sensors: {seed: ") + text + "}\n", kSource)
            .Child("sensors");
    const InputError e = CatchInputError([&] { sensors.Seed("seed", 1); });
    EXPECT_EQ(e.field(), "sensors.seed");
    EXPECT_EQ(e.problem(), std::string("'") + text + "' is out of range");
    EXPECT_EQ(e.expected(), "an integer between 0 and 2147483647");
  }
  const YamlReader absent = YamlReader::FromString("sensors: {}\n", kSource).Child("sensors");
  EXPECT_EQ(absent.Seed("seed", 7), 7);
  EXPECT_THROW(absent.Int("seed"), InputError);  // a required integer stays required
}

TEST(YamlReaderBadInputTest, ScalarWhereMapExpected) {
  const YamlReader root = YamlReader::FromString("model: crane\n", kSource);
  const InputError e = CatchInputError([&] { root.Child("model").ExpectMap(kBaseKeys); });
  EXPECT_EQ(e.field(), "model");
  EXPECT_THAT(e.problem(), HasSubstr("not a map"));
}

TEST(YamlReaderBadInputTest, UnknownKeyFarFromAnyKnownGetsNoSuggestion) {
  const YamlReader base = Base("colour: red");
  const InputError e = CatchInputError([&] { base.ExpectMap(kBaseKeys); });
  EXPECT_EQ(e.field(), "model.base.colour");
  EXPECT_THAT(e.expected(), ::testing::Not(HasSubstr("did you mean")));
}

}  // namespace
}  // namespace mbid
