#include "mbid/model/mechanical_model.h"

#include "mbid/common/error.h"

namespace mbid::model {

double MechanicalModel::GetParameter(const std::string& name) const {
  for (const Parameter& parameter : parameters()) {
    if (parameter.name == name) return parameter.value;
  }
  throw InputError("model", name, "unknown parameter", "one of the model's parameters");
}

}  // namespace mbid::model
