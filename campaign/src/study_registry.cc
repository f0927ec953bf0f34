#include <stdexcept>

#include "mbid/campaign/campaign.h"
#include "mbid/campaign/campaign_case.h"
#include "mbid/campaign/study.h"

namespace mbid::campaign {

// One declaration and one entry per study; its file is studies/<name>_study.cc.
std::shared_ptr<CampaignStudy> MakeDamperSizingStudy();
std::shared_ptr<CampaignStudy> MakeLawsStudy();

namespace {

using StudyFactory = std::shared_ptr<CampaignStudy> (*)();

const std::vector<StudyFactory>& StudyRegistry() {
  static const std::vector<StudyFactory> studies{&MakeDamperSizingStudy, &MakeLawsStudy};
  return studies;
}

}  // namespace

std::vector<std::string> StudyNames() {
  std::vector<std::string> names;
  for (const StudyFactory make : StudyRegistry()) names.push_back(make()->name());
  return names;
}

std::shared_ptr<CampaignStudy> MakeStudy(const std::string& name) {
  if (name == "none") return nullptr;
  for (const StudyFactory make : StudyRegistry()) {
    std::shared_ptr<CampaignStudy> study = make();
    if (study->name() == name) return study;
  }
  throw std::logic_error("MakeStudy: no study '" + name + "'");
}

std::optional<std::vector<std::vector<Assignment>>> CampaignStudy::ReadCases(
    const YamlReader& /*root*/, Campaign* /*campaign*/) {
  return std::nullopt;
}

void CampaignStudy::ReadSection(const YamlReader& /*root*/, const Campaign& /*campaign*/) {}

void CampaignStudy::AddCaseMetrics(const simulation::SimulationResult& /*test*/,
                                   CaseOutcome* /*outcome*/) const {}

}  // namespace mbid::campaign
