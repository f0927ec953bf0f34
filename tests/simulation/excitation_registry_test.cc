#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <variant>
#include <vector>

#include "../common/test_util.h"
#include "mbid/common/error.h"
#include "mbid/common/yaml_reader.h"
#include "mbid/model/model_factory.h"
#include "mbid/model/truck_crane_description.h"
#include "mbid/simulation/excitation.h"
#include "mbid/simulation/scenario_sections.h"

namespace mbid::simulation {
namespace {

const std::string kReference = std::string(MBID_SOURCE_DIR) + "/scenarios/reference-crane.yaml";

const model::MultibodyModel& Crane() {
  static const model::MultibodyModel crane = model::MakeTruckCrane(
      model::ReadTruckCraneParameters(YamlReader::FromFile(kReference).Child("model")));
  return crane;
}

Excitation Read(const std::string& yaml) {
  const YamlReader root = YamlReader::FromString("excitation: " + yaml + "\n", "inline.yaml");
  return ReadExcitation(root.Child("excitation"), Crane());
}

TEST(ExcitationRegistryTest, ListsTheTypesInTheVariantsOrder) {
  // The order is the unknown-type error's: a new type joins at the end of ExcitationVariant.
  EXPECT_EQ(ExcitationTypeNames(),
            (std::vector<std::string>{"load_drop", "initial_deflection", "impulse", "burst"}));
  EXPECT_EQ(ExcitationReaders().size(), std::variant_size_v<ExcitationVariant>);
}

TEST(ExcitationRegistryTest, EachReaderGivesItsOwnType) {
  const Excitation drop = Read("{type: load_drop, payload_mass_kg: 650}");
  ASSERT_NE(drop.get_if<LoadDrop>(), nullptr);
  EXPECT_EQ(drop.get<LoadDrop>().payload_mass_kg, 650.0);
  EXPECT_TRUE(drop.start_depends_on_model());
  EXPECT_EQ(drop.force_target(), nullptr);

  const Excitation deflection = Read("{type: initial_deflection, deflection_rad: {theta: 0.01}}");
  ASSERT_NE(deflection.get_if<InitialDeflection>(), nullptr);
  EXPECT_EQ(deflection.get<InitialDeflection>().deflection_rad.at("theta"), 0.01);
  EXPECT_FALSE(deflection.start_depends_on_model());

  const Excitation impulse = Read(
      "{type: impulse, coordinate: gamma, torque_Nm: 1000, duration_s: 0.1, "
      "shape: rectangular}");
  ASSERT_NE(impulse.get_if<Impulse>(), nullptr);
  EXPECT_EQ(impulse.get<Impulse>().pulse_shape, Impulse::PulseShape::kRectangular);
  ASSERT_NE(impulse.force_target(), nullptr);
  EXPECT_EQ(impulse.force_target()->coordinate, "gamma");
  EXPECT_EQ(impulse.CalcForcingEndTime(), 0.1);
  EXPECT_EQ(impulse.CalcForcingFactor(0.05), 1.0);
  EXPECT_EQ(impulse.CalcForcingFactor(0.1), 0.0);  // the forcing has ended

  const Excitation burst =
      Read("{type: burst, point: boom_tip, force_N: [0, 100, 0], frequency_hz: 2, cycles: 3}");
  ASSERT_NE(burst.get_if<Burst>(), nullptr);
  EXPECT_EQ(burst.force_target()->point, "boom_tip");
  EXPECT_EQ(burst.CalcForcingEndTime(), 1.5);
}

// The generalized force on a coordinate has the coordinate's unit in its key: torque_Nm on a
// turning one, force_N (a number) on a sliding one. A slide's force had to be given as
// torque_Nm, and force_N with a coordinate was "needs exactly one target".
TEST(ExcitationRegistryTest, ACoordinatesForceIsNamedInItsUnit) {
  const auto slide = model::MakeModel(YamlReader::FromString(R"(model:
  type: multibody
  bodies:
    cart: {parent: ground, joint: {type: prismatic, coordinates: [x], axis: [1, 0, 0]},
           mass_kg: 10, inertia_kgm2: [1, 1, 1]}
  springs:
    x: {stiffness_N_per_m: 1000, damping_Ns_per_m: 1}
  outputs:
    x: {type: coordinate, coordinate: x}
)",
                                                             "slide.yaml")
                                          .Child("model"));
  const auto read = [&](const std::string& yaml) {
    const YamlReader root = YamlReader::FromString("excitation: " + yaml + "\n", "inline.yaml");
    return ReadExcitation(root.Child("excitation"), *slide);
  };
  // Sensors without a channel list record every output of the model (not the crane's psi, phi).
  EXPECT_EQ(
      ReadSensorOptions(
          YamlReader::FromString("sensors: {sample_rate_hz: 50}\n", "s.yaml").Child("sensors"),
          *slide)
          .channels,
      std::vector<std::string>{"x"});
  const Excitation pushed = read("{type: impulse, coordinate: x, force_N: 50, duration_s: 0.1}");
  ASSERT_NE(pushed.force_target(), nullptr);
  EXPECT_EQ(pushed.force_target()->coordinate, "x");
  EXPECT_EQ(pushed.force_target()->torque_Nm, 50.0);  // the generalized force, here in N
  const InputError torque = testing::CatchInputError(
      [&] { read("{type: impulse, coordinate: x, torque_Nm: 50, duration_s: 0.1}"); });
  EXPECT_EQ(torque.field(), "excitation.torque_Nm");
  EXPECT_NE(std::string(torque.what()).find("coordinate 'x' slides"), std::string::npos);
  EXPECT_EQ(testing::CatchInputError([] {
              Read("{type: impulse, coordinate: gamma, force_N: 50, duration_s: 0.1}");
            }).field(),
            "excitation.force_N");
}

// 7 rad is more than a turn: degrees written as radians, refused naming the key; pi itself (a
// half turn) is the largest accepted.
TEST(ExcitationRegistryTest, ADeflectionOfMoreThanHalfATurnIsRefused) {
  const InputError error = testing::CatchInputError(
      [] { Read("{type: initial_deflection, deflection_rad: {theta: 7}}"); });
  EXPECT_EQ(error.field(), "excitation.deflection_rad.theta");
  EXPECT_NE(std::string(error.what()).find("more than half a turn"), std::string::npos)
      << error.what();
  EXPECT_NE(std::string(error.what()).find("7 deg is 0.122173 rad"), std::string::npos)
      << error.what();
  EXPECT_NO_THROW(Read("{type: initial_deflection, deflection_rad: {theta: -3.14159}}"));
}

// A load drop needs the machine's payload point: said when the scenario is read, naming the
// excitation's type, not when the test is first simulated.
TEST(ExcitationRegistryTest, ALoadDropWithoutAPayloadPointIsRefusedOnReading) {
  const std::unique_ptr<model::MechanicalModel> arm =
      model::MakeModel(YamlReader::FromString(R"(
type: multibody
bodies:
  arm: {parent: ground, joint: {type: revolute, coordinates: [q], axis: [0, 1, 0]},
        mass_kg: 50.0, com_m: [2.0, 0, 0], inertia_kgm2: [1, 1, 1]}
springs:
  q: {stiffness_Nm_per_rad: 4.0e4, damping_Nms_per_rad: 10}
outputs:
  q: {type: coordinate, coordinate: q}
)",
                                              "arm.yaml"));
  const YamlReader root =
      YamlReader::FromString("excitation: {type: load_drop, payload_mass_kg: 500}\n", "drop.yaml");
  const InputError error =
      testing::CatchInputError([&] { ReadExcitation(root.Child("excitation"), *arm); });
  EXPECT_EQ(error.field(), "excitation.type");
  EXPECT_NE(std::string(error.what()).find("drop.yaml"), std::string::npos) << error.what();
  EXPECT_NE(std::string(error.what()).find("names no payload point"), std::string::npos)
      << error.what();
}

TEST(ExcitationRegistryTest, UnknownTypeListsTheRegisteredOnes) {
  try {
    Read("{type: initial_deflexion}");
    FAIL() << "read an unknown type";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()),
              "inline.yaml:excitation.type: unknown choice 'initial_deflexion'; expected one of "
              "load_drop, initial_deflection, impulse, burst; did you mean "
              "'initial_deflection'?");
  }
}

}  // namespace
}  // namespace mbid::simulation
