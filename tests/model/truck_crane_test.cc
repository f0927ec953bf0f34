// The truck crane (its machine description, as `type: truck_crane` expands) against the
// independent reference of docs/reference-crane.md and against finite differences of its own
// nonlinear forces and outputs.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>

#include "mbid/common/error.h"
#include "mbid/common/yaml_reader.h"
#include "mbid/model/model_factory.h"
#include "mbid/model/simbody.h"
#include "mbid/model/truck_crane_description.h"

namespace mbid::model {
namespace {

const std::string kTruckCraneScenario =
    std::string(MBID_SOURCE_DIR) + "/scenarios/reference-crane.yaml";

TruckCraneParameters ReferenceParameters() {
  return ReadTruckCraneParameters(YamlReader::FromFile(kTruckCraneScenario).Child("model"));
}

// The reference tables carry 10 significant digits and come from an independent implementation:
// the issue asks for agreement to 1e-6 relative. Entries that are roundoff in the reference
// (|x| ~ 1e-12 next to 1e5) are compared relative to the matrix's largest entry.
void ExpectMatrixNear(const Eigen::MatrixXd& actual, const Eigen::MatrixXd& expected,
                      double relative, const std::string& name) {
  ASSERT_EQ(actual.rows(), expected.rows()) << name;
  ASSERT_EQ(actual.cols(), expected.cols()) << name;
  const double scale = expected.cwiseAbs().maxCoeff();
  for (int i = 0; i < expected.rows(); ++i) {
    for (int j = 0; j < expected.cols(); ++j) {
      const double tolerance = relative * std::max(std::abs(expected(i, j)), 1e-6 * scale);
      EXPECT_NEAR(actual(i, j), expected(i, j), tolerance) << name << "(" << i << "," << j << ")";
    }
  }
}

TEST(TruckCraneTest, LinearModelMatchesReference) {
  const MultibodyModel crane = MakeTruckCrane(ReferenceParameters());
  const LinearModel linear = crane.Linearize();
  Eigen::MatrixXd M(4, 4), C(4, 4), H(2, 4);
  M << 1.527234387e+05, 1.673841514e+04, 2.331638945e+04, -3.539826254e+04,  //
      1.673841514e+04, 6.894393872e+04, 6.646258451e+04, -4.547473509e-13,   //
      2.331638945e+04, 6.646258451e+04, 9.241665030e+04, -1.364242053e-12,   //
      -3.539826254e+04, 4.547473509e-13, -1.364242053e-12, 1.000000000e+05;
  C << 4.886292173e+07, -5.429994628e+04, -7.072482928e+04, 3.512602234e+04,  //
      -5.429994628e+04, 1.100000000e+06, 0, 0,                                //
      -7.072482928e+04, 0, 5.500000000e+06, 0,                                //
      3.512602234e+04, 0, 0, 9.359439963e+06;
  H << 1.433726929e-01, 1, 1, 0,  //
      -8.660254038e-01, 0, 0, 1;
  ExpectMatrixNear(linear.M, M, 1e-6, "M");
  ExpectMatrixNear(linear.C, C, 1e-6, "C");
  ExpectMatrixNear(linear.H, H, 1e-6, "H");
  const Eigen::Vector4d d(520000.0, 178000.0, 44000.0, 116000.0);  // the scenario's dampers
  ExpectMatrixNear(linear.D, Eigen::MatrixXd(d.asDiagonal()), 1e-15, "D");
  EXPECT_EQ(linear.coordinates, (std::vector<std::string>{"alpha", "gamma", "eta", "theta"}));
  EXPECT_EQ(linear.outputs, (std::vector<std::string>{"psi", "phi"}));
}

TEST(TruckCraneTest, ModesMatchReference) {
  const MultibodyModel crane = MakeTruckCrane(ReferenceParameters());
  const std::vector<Mode> modes = CalcModes(crane.Linearize());
  ASSERT_EQ(modes.size(), 4u);  // four underdamped modes, one per degree of freedom
  const double frequency_hz[] = {0.576553150, 1.512559861, 2.263377565, 3.088456892};
  const double decay_per_s[] = {0.929700915, 0.559673523, 4.008790815, 2.067117843};
  const double damping_ratio[] = {0.248583984, 0.058788252, 0.271314546, 0.105923834};
  const double undamped_hz[] = {0.595237447, 1.515180404, 2.351583740, 3.105930090};
  for (int k = 0; k < 4; ++k) {
    // 9-10 significant digits in the table; 1e-6 relative asked.
    EXPECT_NEAR(modes[k].frequency_hz(), frequency_hz[k], 1e-6 * frequency_hz[k]) << k;
    EXPECT_NEAR(modes[k].decay_rate_per_s(), decay_per_s[k], 1e-6 * decay_per_s[k]) << k;
    EXPECT_NEAR(modes[k].damping_ratio(), damping_ratio[k], 1e-6 * damping_ratio[k]) << k;
    EXPECT_NEAR(modes[k].undamped_frequency_hz(), undamped_hz[k], 1e-6 * undamped_hz[k]) << k;
    EXPECT_NEAR(modes[k].shape.cwiseAbs().maxCoeff(), 1.0, 1e-15);  // unit largest magnitude
  }
}

TEST(TruckCraneTest, ModesSatisfyQuadraticEigenproblem) {
  // (lambda^2 M + lambda D + C) v = 0 (eq. 6) for every mode: residual at roundoff of |C| |v|.
  const MultibodyModel crane = MakeTruckCrane(ReferenceParameters());
  const LinearModel linear = crane.Linearize();
  for (const Mode& mode : CalcModes(linear)) {
    const std::complex<double> l = mode.lambda;
    const Eigen::MatrixXcd Q = l * l * linear.M.cast<std::complex<double>>() +
                               l * linear.D.cast<std::complex<double>>() +
                               linear.C.cast<std::complex<double>>();
    EXPECT_LT((Q * mode.shape).norm(), 1e-9 * linear.C.norm());
  }
}

TEST(TruckCraneTest, UnloadedCraneRestsAtZero) {
  // The preload rule: the springs carry the dead weight at q = 0. Residual at roundoff of the
  // gravity torques (~1e5 N*m), 1e-9 N*m.
  const MultibodyModel crane = MakeTruckCrane(ReferenceParameters());
  const Eigen::VectorXd f = crane.CalcStaticGeneralizedForce(Eigen::VectorXd::Zero(4), {});
  EXPECT_LT(f.lpNorm<Eigen::Infinity>(), 1e-9);
  EXPECT_LT(crane.SolveStaticEquilibrium({}).lpNorm<Eigen::Infinity>(), 1e-15);
}

TEST(TruckCraneTest, LoadedEquilibriumMatchesReference) {
  // docs/reference-crane.md: the 650 kg load drop starts from these q (7 significant digits).
  const MultibodyModel crane = MakeTruckCrane(ReferenceParameters());
  const double payload_kg = 650.0;
  const std::vector<PointLoad> loads{{"boom_tip", Eigen::Vector3d(0, 0, -payload_kg * 9.81)}};
  const Eigen::VectorXd q = crane.SolveStaticEquilibrium(loads);
  const Eigen::Vector4d expected(5.846515e-04, 4.219559e-05, 1.079496e-05, -6.563916e-03);
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(q[i], expected[i], 1e-6 * std::abs(expected[i])) << i;
  // Machine precision: residual torque at roundoff of the largest torque c_alpha * q_alpha.
  const double torque_scale = 4.9e7 * 5.8e-4;
  EXPECT_LT(crane.CalcStaticGeneralizedForce(q, loads).lpNorm<Eigen::Infinity>(),
            1e-13 * torque_scale);
}

TEST(TruckCraneTest, StiffnessMatchesFiniteDifferenceOfForces) {
  // C = -d f / d q of the full nonlinear rest force (springs + gravity) at q = 0, by central
  // differences with h = 1e-6 rad: truncation ~h^2 and roundoff ~1e-16 f/h leave ~1e-6 N*m/rad
  // on entries up to 5e7, so 1e-7 relative to the largest entry.
  const MultibodyModel crane = MakeTruckCrane(ReferenceParameters());
  const LinearModel linear = crane.Linearize();
  Eigen::MatrixXd C_fd(4, 4);
  const double h = 1e-6;
  for (int j = 0; j < 4; ++j) {
    Eigen::VectorXd dq = Eigen::VectorXd::Zero(4);
    dq[j] = h;
    C_fd.col(j) =
        -(crane.CalcStaticGeneralizedForce(dq, {}) - crane.CalcStaticGeneralizedForce(-dq, {})) /
        (2 * h);
  }
  EXPECT_LT((C_fd - linear.C).cwiseAbs().maxCoeff(), 1e-7 * linear.C.cwiseAbs().maxCoeff());
}

TEST(TruckCraneTest, OutputJacobianMatchesFiniteDifferences) {
  // H from angular velocities vs central differences of the nonlinear outputs, h = 1e-6 rad:
  // error ~h^2 ~ 1e-12 plus roundoff 1e-16/1e-6 = 1e-10.
  const MultibodyModel crane = MakeTruckCrane(ReferenceParameters());
  const LinearModel linear = crane.Linearize();
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(4);
  for (int j = 0; j < 4; ++j) {
    Eigen::VectorXd dq = zero;
    dq[j] = 1e-6;
    const Eigen::VectorXd dy = (crane.CalcOutputs(crane.MakeState(dq, zero)) -
                                crane.CalcOutputs(crane.MakeState(-dq, zero))) /
                               2e-6;
    EXPECT_LT((dy - linear.H.col(j)).norm(), 1e-9) << j;
  }
  EXPECT_LT(crane.CalcOutputs(crane.MakeState(zero, zero)).norm(), 1e-15);  // y = 0 at rest
}

TEST(TruckCraneTest, BoomAnglesFollowKinematics) {
  // With alpha = gamma = 0 the boom azimuth is eta and the elevation theta exactly
  // (R_K = Rz(psi0 + eta) Ry(-(phi0 + theta))).
  const MultibodyModel crane = MakeTruckCrane(ReferenceParameters());
  Eigen::VectorXd q(4);
  q << 0, 0, 0.1, -0.2;
  const Eigen::VectorXd y = crane.CalcOutputs(crane.MakeState(q, Eigen::VectorXd::Zero(4)));
  EXPECT_NEAR(y[0], 0.1, 1e-15);
  EXPECT_NEAR(y[1], -0.2, 1e-15);
  q << 0, 0.3, -0.1, 0;  // gamma and eta add in yaw
  const Eigen::VectorXd y2 = crane.CalcOutputs(crane.MakeState(q, Eigen::VectorXd::Zero(4)));
  EXPECT_NEAR(y2[0], 0.2, 1e-15);
}

TEST(TruckCraneTest, OutputsEqualSimbodysBoomRotation) {
  // CalcOutputs uses the closed-form boom axis; Simbody's realized boom body must give the same
  // angles at large, mixed deflections (all four joints, up to 0.6 rad, slew and luff included).
  // Both are a few rotations of unit vectors in double precision: agreement to 1e-14 rad.
  TruckCraneParameters parameters = ReferenceParameters();
  parameters.slew_rad = 2.5;  // past 90 degrees: atan2's branches and the wrap to (-pi, pi]
  const MultibodyModel crane = MakeTruckCrane(parameters);
  const SimTK::SimbodyMatterSubsystem& matter = crane.system().getMatterSubsystem();
  const SimTK::MobilizedBody& boom =
      matter.getMobilizedBody(SimTK::MobilizedBodyIndex(matter.getNumBodies() - 1));
  const Eigen::Vector4d scale(0.3, 0.6, -0.5, 0.4);  // rad
  for (int k = 0; k < 7; ++k) {
    const Eigen::VectorXd q = scale * std::sin(1.0 + k) + Eigen::Vector4d::Constant(0.01 * k);
    const SimTK::State state = crane.MakeState(q, Eigen::VectorXd::Zero(4));
    crane.system().realize(state, SimTK::Stage::Position);
    const SimTK::Vec3 u = boom.getBodyRotation(state).x();
    const double psi = std::remainder(std::atan2(u[1], u[0]) - parameters.slew_rad, 2 * M_PI);
    const double phi = std::atan2(u[2], std::hypot(u[0], u[1])) - parameters.boom_elevation_rad;
    const Eigen::VectorXd y = crane.CalcOutputs(crane.MakeState(q, Eigen::VectorXd::Zero(4)));
    EXPECT_NEAR(y[0], psi, 1e-14) << k;
    EXPECT_NEAR(y[1], phi, 1e-14) << k;
  }
}

TEST(TruckCraneTest, LinearizationFollowsParameterChangesExactly) {
  // M, K_g and H are computed once per model; C and D must still follow SetParameter. After a
  // change the linearization equals that of a crane built with the new values, bit for bit.
  MultibodyModel crane = MakeTruckCrane(ReferenceParameters());
  const LinearModel before = crane.Linearize();
  crane.SetParameter("c_theta", 7.0e6);
  crane.SetParameter("d_alpha", 3.0e5);
  TruckCraneParameters changed = ReferenceParameters();
  changed.joints[3].stiffness_Nm_per_rad = 7.0e6;
  changed.joints[0].damping_Nms_per_rad = 3.0e5;
  const LinearModel after = crane.Linearize();
  const LinearModel fresh = MakeTruckCrane(changed).Linearize();
  EXPECT_EQ(after.M, fresh.M);
  EXPECT_EQ(after.C, fresh.C);
  EXPECT_EQ(after.D, fresh.D);
  EXPECT_EQ(after.H, fresh.H);
  // The spring alone changed; roundoff of sums near 1e7 is 2e-9.
  EXPECT_NEAR(after.C(3, 3) - before.C(3, 3), 7.0e6 - 9.4e6, 1e-6);
  EXPECT_EQ(after.D(0, 0), 3.0e5);
}

TEST(TruckCraneTest, ParametersRoundTripAndChangeTheModel) {
  MultibodyModel crane = MakeTruckCrane(ReferenceParameters());
  EXPECT_EQ(crane.parameters().size(), 8u);  // c and d of four joints
  crane.SetParameter("c_gamma", 2.2e6);
  EXPECT_EQ(crane.GetParameter("c_gamma"), 2.2e6);
  // C's gamma diagonal is the spring alone (no gravity stiffness on a vertical axis at alpha=0).
  EXPECT_NEAR(crane.Linearize().C(1, 1), 2.2e6, 1e-6);
  // The preload follows the stiffness: still at rest at q = 0.
  EXPECT_LT(crane.CalcStaticGeneralizedForce(Eigen::VectorXd::Zero(4), {}).norm(), 1e-9);
  EXPECT_THROW(crane.SetParameter("c_gama", 1.0), InputError);
  EXPECT_THROW(crane.SetParameter("c_alpha", -1.0), InputError);
  EXPECT_THROW(crane.SetParameter("d_eta", std::nan("")), InputError);
}

TEST(TruckCraneTest, AttachedPayloadKeepsUnloadedRestAndLowersFrequencies) {
  TruckCraneParameters parameters = ReferenceParameters();
  parameters.attached_payload_kg = 650.0;
  const MultibodyModel loaded = MakeTruckCrane(parameters);
  const MultibodyModel unloaded = MakeTruckCrane(ReferenceParameters());
  // Payload mass at the tip adds m L^2 to the luffing inertia: 650 * 10^2.
  EXPECT_NEAR(loaded.Linearize().M(3, 3) - unloaded.Linearize().M(3, 3), 650.0 * 100.0, 1e-6);
  const std::vector<Mode> modes_loaded = CalcModes(loaded.Linearize());
  const std::vector<Mode> modes_unloaded = CalcModes(unloaded.Linearize());
  for (int k = 0; k < 4; ++k) {
    EXPECT_LT(modes_loaded[k].undamped_frequency_hz(), modes_unloaded[k].undamped_frequency_hz());
  }
}

TEST(TruckCraneTest, ValidationRejectsUnphysicalData) {
  TruckCraneParameters p = ReferenceParameters();
  p.boom_mass_kg = -1;
  EXPECT_THROW(MakeTruckCrane(p), InputError);
  p = ReferenceParameters();
  p.base_inertia_kgm2 = Eigen::Vector3d(1, 1, 3);  // 3 > 1 + 1
  EXPECT_THROW(MakeTruckCrane(p), InputError);
  p = ReferenceParameters();
  p.boom_elevation_rad = M_PI / 2;
  EXPECT_THROW(MakeTruckCrane(p), InputError);
}

}  // namespace
}  // namespace mbid::model

namespace mbid::model {
namespace {

TEST(TruckCraneTest, ApplyParameterToStateMatchesSetParameter) {
  // Same accelerations, bit for bit, whether the parameter comes from the model or the state.
  MultibodyModel crane = MakeTruckCrane(ReferenceParameters());
  Eigen::VectorXd q(4), u(4);
  q << 0.001, -0.002, 0.003, 0.004;  // a generic state: every spring and damper acts
  u << 0.01, 0.02, -0.03, 0.04;
  SimTK::State in_state = crane.MakeState(q, u);
  crane.ApplyParameterToState(in_state, "c_theta", 1.2e7);
  crane.ApplyParameterToState(in_state, "d_gamma", 9e4);
  crane.SetParameter("c_theta", 1.2e7);
  crane.SetParameter("d_gamma", 9e4);
  SimTK::State in_model = crane.MakeState(q, u);
  crane.system().realize(in_state, SimTK::Stage::Acceleration);
  crane.system().realize(in_model, SimTK::Stage::Acceleration);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(in_state.getUDot()[i], in_model.getUDot()[i]) << i;
  EXPECT_THROW(crane.ApplyParameterToState(in_state, "c_theta", 0.0), InputError);
}

}  // namespace
}  // namespace mbid::model
