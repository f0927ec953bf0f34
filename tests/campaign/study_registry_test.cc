// The registry of campaign studies (docs/extending.md): names, factories, and the campaign
// file's `study:` choices and sections drawn from it.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "mbid/campaign/campaign.h"
#include "mbid/campaign/study.h"
#include "mbid/common/error.h"

namespace mbid::campaign {
namespace {

namespace fs = std::filesystem;

constexpr char kOscillator[] = R"(name: oscillator
model:
  type: torsional_oscillator
  inertia_kgm2: 4.0
  joints:
    angle: {stiffness_Nm_per_rad: 100.0, damping_Nms_per_rad: 1.0}
excitation:
  type: initial_deflection
  deflection_rad: {angle: 0.01}
sensors:
  channels: [angle]
)";

// The InputError's message of loading a campaign whose text follows `name: c` and the base.
std::string LoadError(const std::string& rest) {
  const fs::path dir =
      fs::temp_directory_path() / ("mbid_study_registry_" + std::to_string(::getpid()) + "_" +
                                   ::testing::UnitTest::GetInstance()->current_test_info()->name());
  fs::create_directories(dir);
  std::ofstream(dir / "oscillator.yaml") << kOscillator;
  std::ofstream(dir / "c.yaml") << "name: c\nbase: oscillator.yaml\n" << rest;
  std::string message;
  try {
    LoadCampaign((dir / "c.yaml").string());
  } catch (const InputError& error) {
    message = error.what();
  }
  fs::remove_all(dir);
  return message;
}

TEST(StudyRegistryTest, ListsTheStudiesInOrder) {
  EXPECT_EQ(StudyNames(), (std::vector<std::string>{"damper_sizing", "laws"}));
  EXPECT_EQ(MakeStudy("none"), nullptr);
  for (const std::string& name : StudyNames()) {
    const std::shared_ptr<CampaignStudy> study = MakeStudy(name);
    ASSERT_NE(study, nullptr);
    EXPECT_EQ(study->name(), name);
  }
  EXPECT_FALSE(MakeStudy("damper_sizing")->PlotsModesAcrossCases());  // it draws its own curves
  EXPECT_TRUE(MakeStudy("laws")->PlotsModesAcrossCases());
}

TEST(StudyRegistryTest, CampaignFileChoosesAmongTheRegisteredStudies) {
  EXPECT_NE(LoadError("study: lawz\n")
                .find("c.yaml:study: unknown choice 'lawz'; expected one of none, damper_sizing, "
                      "laws"),
            std::string::npos);
  EXPECT_NE(LoadError("laws: {variables: [x], quantities: [y]}\n")
                .find("c.yaml:laws: section without study: laws; expected study: laws, or no "
                      "laws section"),
            std::string::npos);
  EXPECT_EQ(LoadError("study: none\n"), "");
}

}  // namespace
}  // namespace mbid::campaign
