// Fisher information of a test (updating/fisher.h) against independent computations: the
// torsional oscillator's closed-form free decay differentiated by central differences (no
// CVODES at all), the Schur complement of an explicit offset column, and UpdateModel's own
// covariance on the crane.
#include "mbid/updating/fisher.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <limits>

#include "crane_fixture.h"
#include "mbid/common/error.h"
#include "oscillator_fixture.h"

namespace mbid::updating {
namespace {

// J theta'' + d theta' + c theta = 0 with J = 2 kg m^2, c = 800 N m/rad, d = 8 N m s/rad:
// omega_0 = 20 rad/s (3.2 Hz), damping ratio d / (2 sqrt(c J)) = 0.1, so a 2 s record at
// 100 Hz holds about 6 decaying cycles, ~31 samples per cycle.
constexpr double kInertia = 2.0;
constexpr double kStiffness = 800.0;
constexpr double kDamping = 8.0;
constexpr double kDeflection = 0.01;  // rad, released from rest
constexpr double kNoise = 1e-4;       // rad: 40 dB below the release amplitude

using testing::MakeOscillator;

TestDesign OscillatorDesign() { return testing::OscillatorRelease("release", kDeflection, kNoise); }

// The closed-form free decay from rest at theta0 (underdamped).
double Angle(double t, double c, double d) {
  const double a = d / (2 * kInertia);
  const double omega = std::sqrt(c / kInertia - a * a);
  return kDeflection * std::exp(-a * t) * (std::cos(omega * t) + a / omega * std::sin(omega * t));
}

// J of the closed form in log coordinates: central differences with a relative step of 1e-5
// (truncation ~1e-10 relative, round-off ~1e-16 / 1e-5 = 1e-11: both far below the 1e-4
// compared), weighted by 1 / noise; 201 samples at 100 Hz.
Eigen::MatrixXd ClosedFormJacobian() {
  const int samples = 201;
  Eigen::MatrixXd jacobian(samples, 2);
  const double h = 1e-5;
  for (int j = 0; j < samples; ++j) {
    const double t = j / 100.0;
    jacobian(j, 0) = (Angle(t, kStiffness * std::exp(h), kDamping) -
                      Angle(t, kStiffness * std::exp(-h), kDamping)) /
                     (2 * h) / kNoise;
    jacobian(j, 1) = (Angle(t, kStiffness, kDamping * std::exp(h)) -
                      Angle(t, kStiffness, kDamping * std::exp(-h))) /
                     (2 * h) / kNoise;
  }
  return jacobian;
}

double RelativeDifference(const Eigen::MatrixXd& actual, const Eigen::MatrixXd& expected) {
  return (actual - expected).cwiseAbs().maxCoeff() / expected.cwiseAbs().maxCoeff();
}

TEST(FisherTest, OscillatorMatchesTheClosedForm) {
  const auto oscillator = MakeOscillator();
  const FisherInformation information = CalcFisherInformation(
      *oscillator, OscillatorDesign(), {"c_angle", "d_angle"}, simulation::SensitivityOptions());
  const Eigen::MatrixXd jacobian = ClosedFormJacobian();
  const Eigen::MatrixXd expected = jacobian.transpose() * jacobian;
  ASSERT_EQ(information.matrix.rows(), 2);
  EXPECT_EQ(information.residuals, 201);
  const double difference = RelativeDifference(information.matrix, expected);
  RecordProperty("relative_difference", std::to_string(difference));
  // The sensitivities' own error test is 1e-6 relative (SensitivityOptions), the states' 1e-8:
  // 1e-4 leaves two orders of margin and would still catch a wrong weight or a missing p factor
  // (both change F by O(1)).
  EXPECT_LT(difference, 1e-4);
  // Symmetric and positive definite: one free decay determines c and d.
  EXPECT_NEAR(information.matrix(0, 1), information.matrix(1, 0), 1e-12 * expected.norm());
  const ExpectedUncertainty uncertainty = CalcExpectedUncertainty(information.matrix);
  EXPECT_EQ(uncertainty.rank, 2);
  // The Cramer-Rao bound of the closed form: the same relative std to the comparison's 1e-4.
  const Eigen::MatrixXd covariance = expected.inverse();
  for (int k = 0; k < 2; ++k) {
    EXPECT_NEAR(uncertainty.relative_std[k], std::sqrt(covariance(k, k)),
                1e-4 * std::sqrt(covariance(k, k)));
  }
  // The stiffness (frequency, many cycles) is far better determined than the damping (decay).
  EXPECT_LT(uncertainty.relative_std[0], uncertainty.relative_std[1]);
}

TEST(FisherTest, OffsetIsTheSchurComplementOfAnOffsetColumn) {
  // With a fitted offset the information about (c, d) is what remains after the offset takes
  // its share: F_pp - F_po F_oo^-1 F_op of the closed form extended by the column 1 / noise
  // (d y / d offset = 1).
  const auto oscillator = MakeOscillator();
  TestDesign design = OscillatorDesign();
  design.fit_offsets = true;
  const FisherInformation information = CalcFisherInformation(
      *oscillator, design, {"c_angle", "d_angle"}, simulation::SensitivityOptions());
  Eigen::MatrixXd extended(201, 3);
  extended.leftCols(2) = ClosedFormJacobian();
  extended.col(2).setConstant(1.0 / kNoise);
  const Eigen::MatrixXd full = extended.transpose() * extended;
  const Eigen::MatrixXd schur = full.topLeftCorner(2, 2) -
                                full.topRightCorner(2, 1) * full.bottomRightCorner(1, 1).inverse() *
                                    full.bottomLeftCorner(1, 2);
  // The same 1e-4 as the test above: the projection itself adds only round-off.
  EXPECT_LT(RelativeDifference(information.matrix, schur), 1e-4);
  // Information can only be lost to the offset: the diagonal does not grow.
  const FisherInformation plain = CalcFisherInformation(
      *oscillator, OscillatorDesign(), {"c_angle", "d_angle"}, simulation::SensitivityOptions());
  EXPECT_LE(information.matrix(0, 0), plain.matrix(0, 0));
  EXPECT_LE(information.matrix(1, 1), plain.matrix(1, 1));
}

TEST(FisherTest, NoiseScalesTheInformation) {
  // F is proportional to 1 / sigma^2: ten times the noise, a hundredth of the information.
  const auto oscillator = MakeOscillator();
  TestDesign noisy = OscillatorDesign();
  noisy.sensors.noise_std["angle"] = 10 * kNoise;
  const FisherInformation quiet = CalcFisherInformation(
      *oscillator, OscillatorDesign(), {"c_angle", "d_angle"}, simulation::SensitivityOptions());
  const FisherInformation loud =
      CalcFisherInformation(*oscillator, noisy, {"c_angle", "d_angle"}, {});
  EXPECT_LT(RelativeDifference(100 * loud.matrix, quiet.matrix), 1e-12);
}

TEST(FisherTest, RejectsMissingNoiseAndUnknownParameters) {
  const auto oscillator = MakeOscillator();
  TestDesign design = OscillatorDesign();
  EXPECT_THROW(CalcFisherInformation(*oscillator, design, {"c_nothing"}, {}), InputError);
  design.sensors.noise_std.clear();
  EXPECT_THROW(CalcFisherInformation(*oscillator, design, {"c_angle"}, {}), InputError);
}

TEST(FisherTest, UndeterminedDirectionsAreInfinite) {
  // Two parameters that act only together (identical columns): the sum is determined, the
  // difference not, so both take part in the null space; the third is independent.
  Eigen::MatrixXd jacobian(3, 3);
  jacobian << 1, 1, 0,  //
      2, 2, 0,          //
      0, 0, 5;
  const ExpectedUncertainty uncertainty = CalcExpectedUncertainty(jacobian.transpose() * jacobian);
  EXPECT_EQ(uncertainty.rank, 2);
  EXPECT_TRUE(std::isinf(uncertainty.relative_std[0]));
  EXPECT_TRUE(std::isinf(uncertainty.relative_std[1]));
  EXPECT_DOUBLE_EQ(uncertainty.relative_std[2], 0.2);  // 1 / 5
}

TEST(FisherTest, CraneRecordMatchesUpdateModelCovariance) {
  // The recorded test's design (MakeRecordedDesign) at UpdateModel's estimate gives the
  // covariance UpdateModel reports: both are (J^T J)^-1 of the same sensitivities in log
  // coordinates. A noiseless 3 s record of the reference crane's initial deflection at 50 Hz,
  // fitted from the truth with the scenario's noise as weights, so the fit stays at the truth.
  const testing::Crane crane = testing::LoadCrane(testing::kReferenceScenario);
  const Measurement record = testing::SimulateExact(crane, 3.0, 50.0);
  UpdateOptions options;
  options.quiet = true;
  options.integrator = crane.simulation.integrator;
  options.integrator.interpolate_outputs = true;
  const TestRecord test{"deflection", record, crane.excitation, crane.sensors.noise_std};
  const UpdateResult result = UpdateModel(*crane.model, {test}, options);
  ASSERT_EQ(result.termination, UpdateResult::Termination::kConverged) << result.message;
  auto model = crane.model->Clone();
  ApplyEstimates(result, *model);
  std::vector<std::string> names;
  for (const ParameterEstimate& estimate : result.parameters) names.push_back(estimate.name);
  const FisherInformation information = CalcFisherInformation(
      *model, MakeRecordedDesign(test, result.tests[0].noise_std, options.integrator), names,
      options.sensitivity);
  const ExpectedUncertainty uncertainty = CalcExpectedUncertainty(information.matrix);
  EXPECT_EQ(uncertainty.rank, result.rank);
  for (size_t k = 0; k < names.size(); ++k) {
    const double reported = result.parameters[k].relative_std;
    // Same sensitivities, same weights; Ceres' covariance is computed by its own SVD: 1e-6.
    EXPECT_NEAR(uncertainty.relative_std[static_cast<Eigen::Index>(k)], reported, 1e-6 * reported)
        << names[k];
  }
}

}  // namespace
}  // namespace mbid::updating
