#include "mbid/model/mechanical_model.h"

#include <algorithm>

#include "mbid/common/error.h"

namespace mbid::model {

double MechanicalModel::GetParameter(const std::string& name) const {
  for (const Parameter& parameter : parameters()) {
    if (parameter.name == name) return parameter.value;
  }
  throw InputError("model", name, "unknown parameter", "one of the model's parameters");
}

std::string MechanicalModel::coordinate_unit(const std::string& name) const {
  const std::vector<std::string>& names = coordinate_names();
  const auto at = std::find(names.begin(), names.end(), name);
  return at == names.end() ? "" : coordinate_units()[static_cast<size_t>(at - names.begin())];
}

}  // namespace mbid::model
