#include "mbid/validation/modes_report.h"

#include <fmt/format.h>

#include "mbid/common/error.h"
#include "mbid/validation/json_summaries.h"

namespace mbid::validation {

ModesReport AnalyseModes(const model::MechanicalModel& model) {
  ModesReport report;
  report.linear = model.Linearize();
  report.modes = model::CalcModes(report.linear);
  try {
    const Eigen::VectorXd rest = model.SolveStaticEquilibrium({});
    if (rest.size() > 0 && rest.cwiseAbs().maxCoeff() > 1e-12) report.rest = rest;
  } catch (const NumericalError&) {
    // A free coordinate: no rest to report (its pole at 0 says so).
  }
  return report;
}

std::string ModesTable(const std::string& name, const ModesReport& report) {
  const model::LinearModel& linear = report.linear;
  std::string rest;
  if (report.rest) {
    std::vector<std::string> at;
    for (size_t i = 0; i < linear.coordinates.size(); ++i) {
      const std::string unit =
          i < linear.coordinate_units.size() ? linear.coordinate_units[i] : "rad";
      at.push_back(fmt::format("{} = {:.6g} {}", linear.coordinates[i],
                               (*report.rest)[static_cast<Eigen::Index>(i)], unit));
    }
    rest = fmt::format(" under its attached payload ({}; an initial deflection counts from q = 0)",
                       fmt::join(at, ", "));
  }
  std::string table = fmt::format("{}: {} coordinates, {} outputs, linearized at rest{}\n", name,
                                  linear.coordinates.size(), linear.outputs.size(), rest);
  table += fmt::format("{:>4} {:>14} {:>16} {:>13} {:>15}\n", "mode", "frequency_hz",
                       "decay_rate_per_s", "damping_ratio", "undamped_hz");
  for (size_t k = 0; k < report.modes.size(); ++k) {
    const model::Mode& mode = report.modes[k];
    if (mode.lambda == 0.0) {
      table +=
          fmt::format("{:>4} {:>14} (a free coordinate's rigid-body motion)\n", k + 1, "pole at 0");
      continue;
    }
    table +=
        fmt::format("{:>4} {:>14.9f} {:>16.9f} {:>13.9f} {:>15.9f}\n", k + 1, mode.frequency_hz(),
                    mode.decay_rate_per_s(), mode.damping_ratio(), mode.undamped_frequency_hz());
  }
  return table;
}

nlohmann::json ModesJson(const ModesReport& report) {
  nlohmann::json json = LinearModelToJson(report.linear, report.modes);
  if (report.rest) {
    for (size_t i = 0; i < report.linear.coordinates.size(); ++i) {
      json["rest"][report.linear.coordinates[i]] = (*report.rest)[static_cast<Eigen::Index>(i)];
    }
  }
  return json;
}

}  // namespace mbid::validation
