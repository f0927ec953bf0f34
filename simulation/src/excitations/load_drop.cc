#include "mbid/simulation/excitations/load_drop.h"

#include "mbid/common/yaml_reader.h"

namespace mbid::simulation {

LoadDrop LoadDrop::Read(const YamlReader& node, const model::MechanicalModel& /*model*/) {
  node.ExpectMap({"type", "payload_mass_kg"});
  LoadDrop drop;
  drop.payload_mass_kg = node.PositiveDouble("payload_mass_kg");
  return drop;
}

Eigen::VectorXd LoadDrop::CalcInitialCoordinates(const model::MechanicalModel& model) const {
  // At rest only the payload's weight matters; after release the machine is unloaded.
  return model.SolveStaticEquilibrium(model.CalcPayloadLoads(payload_mass_kg));
}

}  // namespace mbid::simulation
