#include "mbid/simulation/excitations/initial_deflection.h"

#include <fmt/format.h>

#include <cmath>
#include <utility>
#include <vector>

#include "mbid/common/yaml_reader.h"

namespace mbid::simulation {

InitialDeflection InitialDeflection::Read(const YamlReader& node,
                                          const model::MechanicalModel& model) {
  node.ExpectMap({"type", "deflection_rad", "deflection_m"});
  InitialDeflection excitation;
  // Angles of rotational coordinates under deflection_rad, slides of prismatic ones under
  // deflection_m; both are kept in SI in one map.
  const std::vector<std::string> units = model.coordinate_units();
  for (const auto& [key, unit] : {std::pair<const char*, const char*>{"deflection_rad", "rad"},
                                  std::pair<const char*, const char*>{"deflection_m", "m"}}) {
    if (!node.Has(key)) continue;
    std::vector<std::string> coordinates;
    for (size_t i = 0; i < units.size(); ++i) {
      if (units[i] == unit) coordinates.push_back(model.coordinate_names()[i]);
    }
    const YamlReader deflection = node.Child(key);
    // A coordinate of the other unit: name the key it belongs under.
    for (const std::string& coordinate : deflection.Keys()) {
      const std::string coordinate_unit = model.coordinate_unit(coordinate);
      if (!coordinate_unit.empty() && coordinate_unit != unit) {
        deflection.FailAt(
            coordinate,
            "coordinate '" + coordinate + (std::string(unit) == "rad" ? "' slides" : "' turns"),
            std::string("its deflection under ") +
                (std::string(unit) == "rad" ? "deflection_m (in m)" : "deflection_rad (in rad)"));
      }
    }
    deflection.ExpectMap(coordinates);
    for (const std::string& coordinate : deflection.Keys()) {
      const double value = deflection.Double(coordinate);
      // A deflection of more than half a turn is no test of a structure: degrees written as
      // radians (7 rad for 7 deg) would otherwise simulate a machine spun round.
      if (std::string(unit) == "rad" && std::abs(value) > M_PI) {
        deflection.FailAt(coordinate, fmt::format("{:.17g} rad, more than half a turn", value),
                          fmt::format("an angle in rad within +-pi ({:g} deg is {:.6g} rad)", value,
                                      value * M_PI / 180));
      }
      excitation.deflection_rad[coordinate] = deflection.Double(coordinate);
    }
  }
  if (excitation.deflection_rad.empty()) {
    node.FailAt("deflection_rad", "no coordinate given",
                "at least one coordinate's deflection (deflection_rad or deflection_m)");
  }
  return excitation;
}

Eigen::VectorXd InitialDeflection::CalcInitialCoordinates(
    const model::MechanicalModel& model) const {
  const int n = model.coordinate_count();
  Eigen::VectorXd q = Eigen::VectorXd::Zero(n);
  for (int i = 0; i < n; ++i) {
    const auto found = deflection_rad.find(model.coordinate_names()[i]);
    if (found != deflection_rad.end()) q[i] = found->second;
  }
  return q;
}

}  // namespace mbid::simulation
