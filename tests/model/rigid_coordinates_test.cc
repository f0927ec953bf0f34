// A machine with coordinates made rigid (rigid_coordinates.h) against an independent check: the
// original machine with those joints' stiffness made huge. As c -> infinity the joint's own mode
// leaves for high frequency and the others tend to those of the machine without the degree of
// freedom, with errors of the order of (omega / omega_joint)^2 = c_others / c_huge.
#include "mbid/model/rigid_coordinates.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "mbid/common/error.h"
#include "mbid/common/yaml_reader.h"
#include "mbid/model/model_factory.h"
#include "mbid/model/multibody_model.h"
#include "mbid/model/simbody.h"
#include "mbid/model/truck_crane_description.h"

namespace mbid::model {
namespace {

const std::string kReferenceScenario =
    std::string(MBID_SOURCE_DIR) + "/scenarios/reference-crane.yaml";
const std::string kDescriptionScenario =
    std::string(MBID_SOURCE_DIR) + "/scenarios/reference-crane-description.yaml";

MultibodyModel LoadModel(const std::string& path) {
  std::unique_ptr<MechanicalModel> model = MakeModel(YamlReader::FromFile(path).Child("model"));
  return std::move(dynamic_cast<MultibodyModel&>(*model));
}

// The factor the rigid joints' stiffness is raised by. The crane's stiffnesses span 1.1e6 to
// 4.9e7 N*m/rad, so 1e8 times puts the stiffened joint 1e4-1e5 times above the next one in
// frequency squared: the other modes move by ~1e-5 relative or less (measured: at most 7.5e-7
// in frequency and decay rate over the cases below). Not more:
// the linearization's finite differences and the eigen solver lose digits as the stiffness
// ratio grows (1e10 already costs accuracy).
constexpr double kStiffening = 1e8;
// Frequencies and decay rates agree to this relative tolerance: over 100x the measured deviation
// of the stiffened model (above), yet far below what a wrong weld (another joint, a universal
// joint's wrong axis) changes: that removes a different mode altogether.
constexpr double kRelativeTolerance = 1e-4;

void ExpectModesOfStiffened(const MultibodyModel& machine, const std::vector<std::string>& rigid) {
  const MultibodyModel welded = MakeCoordinatesRigid(machine, rigid);
  std::unique_ptr<MechanicalModel> stiff = machine.Clone();
  for (const std::string& name : rigid) {
    const SpringDescription* spring = machine.description().FindSpring(name);
    ASSERT_NE(spring, nullptr) << name;
    stiff->SetParameter("c_" + name, spring->stiffness * kStiffening);
  }
  const std::vector<Mode> expected = CalcModes(stiff->Linearize());
  const std::vector<Mode> actual = CalcModes(welded.Linearize());
  // The stiffened joints' own modes are the fastest: the rest pair up in order of frequency.
  ASSERT_EQ(actual.size() + rigid.size(), expected.size());
  for (size_t k = 0; k < actual.size(); ++k) {
    EXPECT_NEAR(actual[k].frequency_hz(), expected[k].frequency_hz(),
                kRelativeTolerance * expected[k].frequency_hz())
        << "mode " << k;
    EXPECT_NEAR(actual[k].decay_rate_per_s(), expected[k].decay_rate_per_s(),
                kRelativeTolerance * expected[k].decay_rate_per_s())
        << "mode " << k;
  }
}

TEST(RigidCoordinatesTest, EachCraneJointMatchesItsStiffenedModel) {
  const MultibodyModel crane = LoadModel(kReferenceScenario);
  EXPECT_EQ(CompliantCoordinates(crane.description()),
            (std::vector<std::string>{"alpha", "gamma", "eta", "theta"}));
  for (const char* joint : {"alpha", "gamma", "eta", "theta"}) {
    SCOPED_TRACE(joint);
    ExpectModesOfStiffened(crane, {std::string(joint)});
  }
  ExpectModesOfStiffened(crane, {"gamma", "theta"});
}

TEST(RigidCoordinatesTest, TruckCraneAndItsDescriptionFileAgree) {
  // type: truck_crane goes through the crane's description; the written-out description is the
  // same machine (docs/machine-description.md): their rigid variants agree to roundoff (1e-9
  // relative: the two linearizations differ by finite-difference noise of that order).
  const MultibodyModel shorthand = MakeCoordinatesRigid(LoadModel(kReferenceScenario), {"theta"});
  const MultibodyModel described = MakeCoordinatesRigid(LoadModel(kDescriptionScenario), {"theta"});
  EXPECT_EQ(shorthand.type(), "truck_crane");
  EXPECT_EQ(described.type(), "multibody");
  const std::vector<Mode> a = CalcModes(shorthand.Linearize());
  const std::vector<Mode> b = CalcModes(described.Linearize());
  ASSERT_EQ(a.size(), 3u);
  ASSERT_EQ(b.size(), 3u);
  for (size_t k = 0; k < a.size(); ++k) {
    EXPECT_NEAR(a[k].frequency_hz(), b[k].frequency_hz(), 1e-9 * b[k].frequency_hz());
  }
}

TEST(RigidCoordinatesTest, ParametersAndOutputsFollowTheWeld) {
  const MultibodyModel crane = LoadModel(kReferenceScenario);
  const MultibodyModel welded = MakeCoordinatesRigid(crane, {"theta"});
  EXPECT_EQ(welded.coordinate_names(), (std::vector<std::string>{"alpha", "gamma", "eta"}));
  std::vector<std::string> names;
  for (const Parameter& p : welded.parameters()) names.push_back(p.name);
  EXPECT_EQ(std::count(names.begin(), names.end(), "c_theta"), 0);
  EXPECT_EQ(std::count(names.begin(), names.end(), "d_theta"), 0);
  EXPECT_EQ(names.size(), 6u);  // c_ and d_ of the three joints left
  // The welded joint is still an output (a sensor on it reads 0), in rad.
  const std::vector<std::string>& outputs = welded.output_names();
  const auto theta = std::find(outputs.begin(), outputs.end(), "theta");
  ASSERT_NE(theta, outputs.end());
  const size_t index = static_cast<size_t>(theta - outputs.begin());
  EXPECT_EQ(welded.output_units()[index], "rad");
  const LinearModel linear = welded.Linearize();
  EXPECT_EQ(linear.H.row(static_cast<Eigen::Index>(index)).norm(), 0.0);
  const Eigen::VectorXd q = Eigen::Vector3d(0.01, -0.02, 0.03);
  const Eigen::VectorXd y = welded.CalcOutputs(welded.MakeState(q, Eigen::Vector3d::Zero()));
  EXPECT_EQ(y[static_cast<Eigen::Index>(index)], 0.0);
  // The weld keeps the joint at its rest pose: the remaining outputs are the original's at
  // theta = 0 (both are the same kinematics to roundoff).
  const Eigen::VectorXd y_full = crane.CalcOutputs(
      crane.MakeState(Eigen::Vector4d(0.01, -0.02, 0.03, 0), Eigen::Vector4d::Zero()));
  EXPECT_NEAR(y[0], y_full[0], 1e-12);
  EXPECT_NEAR(y[1], y_full[1], 1e-12);
}

TEST(RigidCoordinatesTest, UniversalJointKeepsItsOtherAxis) {
  // A pendulum on a universal joint (a first axis x, a second y in the turned frame) hanging
  // below its pivot, springs on both: either axis made rigid leaves a revolute joint about the
  // other, checked against the stiffened model as above.
  MachineDescription machine;
  BodyDescription bob;
  bob.name = "bob";
  bob.parent = "ground";
  bob.joint.type = JointType::kUniversal;
  bob.joint.coordinates = {"a", "b"};
  bob.joint.axes = {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY()};
  bob.mass_kg = 10;
  bob.com_m = Eigen::Vector3d(0.1, 0, -1.0);
  bob.inertia_kgm2 = Eigen::Vector3d(1.0, 1.5, 2.0).asDiagonal();
  machine.bodies = {bob};
  machine.springs = {{"a", 400.0, 5.0}, {"b", 900.0, 8.0}};
  OutputDescription angle;
  angle.name = "tilt";
  angle.type = OutputType::kElevation;
  angle.body = "bob";
  angle.direction = Eigen::Vector3d::UnitX();
  machine.outputs = {angle};
  const MultibodyModel pendulum(machine);
  ExpectModesOfStiffened(pendulum, {"a"});
  ExpectModesOfStiffened(pendulum, {"b"});
  EXPECT_EQ(MakeCoordinatesRigid(machine, {"a"}).bodies[0].joint.type, JointType::kRevolute);
  EXPECT_EQ(MakeCoordinatesRigid(machine, {"a", "b"}).bodies[0].joint.type, JointType::kWeld);
}

TEST(RigidCoordinatesTest, UnknownOrRepeatedCoordinatesAreInputErrors) {
  const MultibodyModel crane = LoadModel(kReferenceScenario);
  EXPECT_THROW(MakeCoordinatesRigid(crane, {"omega"}), InputError);
  EXPECT_THROW(MakeCoordinatesRigid(crane, {"theta", "theta"}), InputError);
  EXPECT_EQ(MakeCoordinatesRigid(crane, {}).coordinate_names().size(), 4u);
}

}  // namespace
}  // namespace mbid::model
