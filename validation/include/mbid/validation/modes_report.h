#pragma once

// What `mbid modes` says of a model: its linearization, its modes, and where it rests when an
// attached payload sags it away from q = 0 (initial deflections count from q = 0, the unloaded
// rest, so a test about the loaded rest needs it).

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "mbid/model/linear_model.h"
#include "mbid/model/mechanical_model.h"

namespace mbid::validation {

struct ModesReport {
  model::LinearModel linear;
  std::vector<model::Mode> modes;
  // The rest's coordinates where any is off q = 0 by more than 1e-12 (rad or m); empty at
  // q = 0 or where no spring holds a coordinate (a free body has no rest).
  std::optional<Eigen::VectorXd> rest;
};

ModesReport AnalyseModes(const model::MechanicalModel& model);

// The table `mbid modes` prints for the scenario `name`: a header line (with the rest's
// coordinates where it is off q = 0), then one line per mode.
std::string ModesTable(const std::string& name, const ModesReport& report);

// LinearModelToJson's fields, with "rest" {coordinate: value} where the rest is off q = 0.
nlohmann::json ModesJson(const ModesReport& report);

}  // namespace mbid::validation
