#include <iostream>

#include "mbid/app/commands.h"
#include "mbid/common/json_io.h"
#include "mbid/validation/modes_report.h"
#include "mbid/validation/scenario.h"

namespace mbid::app {

int RunModesCommand(const std::string& scenario_path, const CommonOptions& common) {
  const validation::Scenario scenario = validation::LoadScenario(scenario_path);
  const validation::ModesReport report = validation::AnalyseModes(*scenario.MakeModel());
  for (const std::string& line : model::FindModeDoubts(report.modes)) {
    std::cerr << "mbid: warning: " << line << "\n";
  }
  if (!common.json_path.empty()) WriteJson(validation::ModesJson(report), common.json_path);
  if (common.json_path != "-") std::cout << validation::ModesTable(scenario.name, report);
  return 0;
}

}  // namespace mbid::app
