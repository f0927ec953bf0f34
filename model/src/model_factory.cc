#include "mbid/model/model_factory.h"

#include <fmt/format.h>

#include <cmath>

#include "degrees.h"
#include "mbid/common/error.h"
#include "mbid/model/multibody_model.h"
#include "mbid/model/truck_crane_description.h"

namespace mbid::model {
namespace {

// Far past any crane (the longest booms ~250 m), like kMaxBodyMass_kg for masses.
constexpr double kMaxLength_m = 1000.0;

double ReadMass(const YamlReader& reader, const std::string& key) {
  const double mass_kg = reader.PositiveDouble(key);
  if (mass_kg > kMaxBodyMass_kg) {
    reader.FailAt(key, fmt::format("mass {:g} kg", mass_kg), "a mass up to 1e9 kg");
  }
  return mass_kg;
}

using internal::kDegToRad;

Eigen::Vector3d ReadVector3(const YamlReader& node, const std::string& key) {
  const std::array<double, 3> v = node.Vector3(key);
  return Eigen::Vector3d(v[0], v[1], v[2]);
}

Eigen::Vector3d ReadPrincipalInertia(const YamlReader& node) {
  const Eigen::Vector3d I = ReadVector3(node, "inertia_kgm2");
  for (int i = 0; i < 3; ++i) {
    if (!(I[i] > 0)) {
      node.FailAt("inertia_kgm2", "non-positive principal moment", "positive moments in kg*m^2");
    }
    if (I[i] > I[(i + 1) % 3] + I[(i + 2) % 3]) {
      node.FailAt("inertia_kgm2", "principal moments violate the triangle inequality",
                  "each moment at most the sum of the other two");
    }
  }
  return I;
}

}  // namespace

TruckCraneParameters ReadTruckCraneParameters(const YamlReader& model) {
  model.ExpectMap({"type", "gravity_mps2", "configuration", "base", "slewing", "boom", "joints",
                   "payload_mass_kg"});
  TruckCraneParameters p;
  p.gravity_mps2 = model.PositiveDouble("gravity_mps2", 9.81);
  p.attached_payload_kg = model.Double("payload_mass_kg", 0.0);
  if (p.attached_payload_kg < 0) {
    model.FailAt("payload_mass_kg", "negative mass", "a non-negative mass in kg");
  }

  const YamlReader configuration = model.Child("configuration");
  configuration.ExpectMap({"boom_elevation_deg", "slew_deg"});
  const double elevation_deg = configuration.Double("boom_elevation_deg");
  if (!(std::abs(elevation_deg) < 90)) {
    configuration.FailAt("boom_elevation_deg", "elevation " + std::to_string(elevation_deg),
                         "an angle in (-90, 90) degrees");
  }
  p.boom_elevation_rad = elevation_deg * kDegToRad;
  p.slew_rad = configuration.Double("slew_deg") * kDegToRad;

  const YamlReader base = model.Child("base");
  base.ExpectMap({"pitch_pivot_m", "mass_kg", "com_m", "inertia_kgm2"});
  p.p_GOa_m = ReadVector3(base, "pitch_pivot_m");
  p.base_mass_kg = ReadMass(base, "mass_kg");
  p.p_GBcm_m = ReadVector3(base, "com_m");
  p.base_inertia_kgm2 = ReadPrincipalInertia(base);

  const YamlReader slewing = model.Child("slewing");
  slewing.ExpectMap({"bearing_m", "mass_kg", "com_m", "inertia_kgm2"});
  p.p_GOs_m = ReadVector3(slewing, "bearing_m");
  p.slewing_mass_kg = ReadMass(slewing, "mass_kg");
  p.p_OsScm_S_m = ReadVector3(slewing, "com_m");
  p.slewing_inertia_kgm2 = ReadPrincipalInertia(slewing);

  const YamlReader boom = model.Child("boom");
  boom.ExpectMap({"foot_m", "mass_kg", "length_m", "axial_inertia_kgm2"});
  p.p_OsF_S_m = ReadVector3(boom, "foot_m");
  p.boom_mass_kg = ReadMass(boom, "mass_kg");
  p.boom_length_m = boom.PositiveDouble("length_m");
  if (p.boom_length_m > kMaxLength_m) {
    boom.FailAt("length_m", fmt::format("length {:g} m", p.boom_length_m),
                "a boom length up to 1000 m");
  }
  p.boom_axial_inertia_kgm2 = boom.PositiveDouble("axial_inertia_kgm2");

  const YamlReader joints = model.Child("joints");
  joints.ExpectMap({"alpha", "gamma", "eta", "theta"});
  const char* names[] = {"alpha", "gamma", "eta", "theta"};
  for (int i = 0; i < 4; ++i) {
    const YamlReader joint = joints.Child(names[i]);
    joint.ExpectMap({"stiffness_Nm_per_rad", "damping_Nms_per_rad"});
    p.joints[i].stiffness_Nm_per_rad = joint.PositiveDouble("stiffness_Nm_per_rad");
    p.joints[i].damping_Nms_per_rad = joint.PositiveDouble("damping_Nms_per_rad");
  }
  try {
    p.Validate();
  } catch (const InputError& error) {
    // Re-anchor a model-level check to the scenario file and field.
    throw InputError(model.source(), model.field() + "." + error.field(), error.problem(),
                     error.expected());
  }
  return p;
}

TorsionalOscillatorParameters ReadTorsionalOscillatorParameters(const YamlReader& model) {
  model.ExpectMap({"type", "inertia_kgm2", "joints"});
  TorsionalOscillatorParameters p;
  p.inertia_kgm2 = model.PositiveDouble("inertia_kgm2");
  const YamlReader joints = model.Child("joints");
  joints.ExpectMap({"angle"});
  const YamlReader joint = joints.Child("angle");
  joint.ExpectMap({"stiffness_Nm_per_rad", "damping_Nms_per_rad"});
  p.stiffness_Nm_per_rad = joint.PositiveDouble("stiffness_Nm_per_rad");
  p.damping_Nms_per_rad = joint.Double("damping_Nms_per_rad", 0.0);
  if (p.damping_Nms_per_rad < 0) {
    joint.FailAt("damping_Nms_per_rad", "negative damping", "a value >= 0 in N*m*s/rad");
  }
  return p;
}

std::unique_ptr<MechanicalModel> MakeModel(const YamlReader& model) {
  // The default type is the crane's shorthand; a description by bodies without its type would
  // otherwise be refused key by key against the crane's.
  if (!model.Has("type") && model.Has("bodies")) {
    model.FailAt("type", "missing in a machine described by bodies",
                 "type: multibody (the default, truck_crane, takes the crane's keys)");
  }
  const std::string type =
      model.Choice("type", {"truck_crane", "multibody", "torsional_oscillator"}, "truck_crane");
  if (type == "torsional_oscillator") {
    return std::make_unique<MultibodyModel>(
        MakeTorsionalOscillator(ReadTorsionalOscillatorParameters(model)));
  }
  try {
    if (type == "multibody") return std::make_unique<MultibodyModel>(ReadMachineDescription(model));
    // The shorthand: the crane's keys expand to its description.
    return std::make_unique<MultibodyModel>(MakeTruckCrane(ReadTruckCraneParameters(model)));
  } catch (const InputError& error) {
    if (error.source() != "machine description") throw;
    // A check of the built model (e.g. a free coordinate that gravity drives): anchor it here.
    throw InputError(model.source(),
                     model.field().empty() ? error.field() : model.field() + "." + error.field(),
                     error.problem(), error.expected());
  }
}

}  // namespace mbid::model
