#include <fmt/format.h>

#include <iostream>

#include "mbid/app/commands.h"
#include "mbid/common/json_io.h"
#include "mbid/validation/json_summaries.h"
#include "mbid/validation/scenario.h"

namespace mbid::app {
using validation::LinearModelToJson;
using validation::LoadScenario;
using validation::Scenario;

int RunModesCommand(const std::string& scenario_path, const CommonOptions& common) {
  const Scenario scenario = LoadScenario(scenario_path);
  const auto model = scenario.MakeModel();
  const model::LinearModel linear = model->Linearize();
  const std::vector<model::Mode> modes = model::CalcModes(linear);
  for (const std::string& line : model::FindModeDoubts(modes)) {
    std::cerr << "mbid: warning: " << line << "\n";
  }
  if (!common.json_path.empty()) WriteJson(LinearModelToJson(linear, modes), common.json_path);
  if (common.json_path != "-") {
    std::cout << fmt::format("{}: {} coordinates, {} outputs, linearized at rest\n", scenario.name,
                             linear.coordinates.size(), linear.outputs.size());
    std::cout << fmt::format("{:>4} {:>14} {:>16} {:>13} {:>15}\n", "mode", "frequency_hz",
                             "decay_rate_per_s", "damping_ratio", "undamped_hz");
    for (size_t k = 0; k < modes.size(); ++k) {
      if (modes[k].lambda == 0.0) {
        std::cout << fmt::format("{:>4} {:>14} (a free coordinate's rigid-body motion)\n", k + 1,
                                 "pole at 0");
        continue;
      }
      std::cout << fmt::format("{:>4} {:>14.9f} {:>16.9f} {:>13.9f} {:>15.9f}\n", k + 1,
                               modes[k].frequency_hz(), modes[k].decay_rate_per_s(),
                               modes[k].damping_ratio(), modes[k].undamped_frequency_hz());
    }
  }
  return 0;
}

}  // namespace mbid::app
