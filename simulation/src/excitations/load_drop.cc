#include "mbid/simulation/excitations/load_drop.h"

#include "mbid/common/error.h"
#include "mbid/common/yaml_reader.h"

namespace mbid::simulation {

LoadDrop LoadDrop::Read(const YamlReader& node, const model::MechanicalModel& model) {
  node.ExpectMap({"type", "payload_mass_kg"});
  LoadDrop drop;
  drop.payload_mass_kg = node.PositiveDouble("payload_mass_kg");
  // Said when the scenario is read (modes, update), not when the test is first simulated.
  try {
    model.CalcPayloadLoads(drop.payload_mass_kg);
  } catch (const InputError&) {
    node.FailAt("type", "a load drop on a machine that names no payload point",
                "model.payload_point naming where the payload hangs, or another excitation");
  }
  return drop;
}

Eigen::VectorXd LoadDrop::CalcInitialCoordinates(const model::MechanicalModel& model) const {
  // At rest only the payload's weight matters; after release the machine is unloaded.
  return model.SolveStaticEquilibrium(model.CalcPayloadLoads(payload_mass_kg));
}

}  // namespace mbid::simulation
