// MarkUnseenParameters (credibility.h): a parameter whose linear modes the records' channels do
// not see is no determined number, whatever its standard deviation says.
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "mbid/common/yaml_reader.h"
#include "mbid/model/model_factory.h"
#include "mbid/updating/credibility.h"

namespace mbid::updating {
namespace {

const std::string kScenarios = std::string(MBID_SOURCE_DIR) + "/scenarios/";

std::unique_ptr<model::MechanicalModel> LoadModel(const std::string& file) {
  return model::MakeModel(YamlReader::FromFile(kScenarios + file).Child("model"));
}

// Every model parameter at its scenario value, determined, as a fit would report it.
UpdateResult AtTheScenario(const model::MechanicalModel& model) {
  UpdateResult result;
  for (const model::Parameter& p : model.parameters()) {
    ParameterEstimate estimate;
    estimate.name = p.name;
    estimate.value = p.value;
    result.parameters.push_back(estimate);
  }
  return result;
}

TestRecord Channels(const std::vector<std::string>& channels) {
  TestRecord test;
  test.record.channels = channels;
  return test;
}

// The excavator arm is symmetric about its vertical plane: its swing mode has no linear part in
// the boom's and stick's inclinations, only the lateral accelerometer sees it.
TEST(UnseenModesTest, TheSwingOfASymmetricArmIsUnseenByItsInclinometers) {
  const auto arm = LoadModel("excavator-arm.yaml");
  UpdateResult result = AtTheScenario(*arm);
  const std::vector<std::string> unseen =
      MarkUnseenParameters(*arm, {Channels({"boom_incl", "stick_incl"})}, result);
  EXPECT_EQ(unseen, (std::vector<std::string>{"c_swing", "d_swing"}));
  for (const ParameterEstimate& p : result.parameters) {
    const bool swing = p.name == "c_swing" || p.name == "d_swing";
    EXPECT_EQ(p.determined, !swing) << p.name;
    if (swing) {
      EXPECT_NE(p.why_undetermined.find("do not see the modes it acts on"), std::string::npos)
          << p.why_undetermined;
    }
  }
  EXPECT_EQ(result.undetermined, unseen);
  ASSERT_EQ(result.warnings.size(), 1u);

  // Left undetermined by another rule first (a trial's alternative minima): the unseen modes
  // are said too, first, since no fit of these channels can settle it.
  UpdateResult already = AtTheScenario(*arm);
  for (ParameterEstimate& p : already.parameters) {
    if (p.name == "c_swing") {
      p.determined = false;
      p.why_undetermined = "the alternative minima differ in it";
    }
  }
  MarkUnseenParameters(*arm, {Channels({"boom_incl", "stick_incl"})}, already);
  for (const ParameterEstimate& p : already.parameters) {
    if (p.name != "c_swing") continue;
    EXPECT_EQ(p.why_undetermined.find("the records' channels"), 0u) << p.why_undetermined;
    EXPECT_NE(p.why_undetermined.find("; and the alternative minima differ in it"),
              std::string::npos)
        << p.why_undetermined;
  }

  UpdateResult with_accelerometer = AtTheScenario(*arm);
  EXPECT_TRUE(
      MarkUnseenParameters(*arm, {Channels({"boom_incl", "stick_incl"}), Channels({"a_bucket_y"})},
                           with_accelerometer)
          .empty());
}

// The reference crane's two angles see all four modes: nothing is marked.
TEST(UnseenModesTest, TheCranesAnglesSeeEveryMode) {
  const auto crane = LoadModel("reference-crane.yaml");
  UpdateResult result = AtTheScenario(*crane);
  EXPECT_TRUE(MarkUnseenParameters(*crane, {Channels({"phi", "psi"})}, result).empty());
  EXPECT_TRUE(std::all_of(result.parameters.begin(), result.parameters.end(),
                          [](const ParameterEstimate& p) { return p.determined; }));
}

}  // namespace
}  // namespace mbid::updating
