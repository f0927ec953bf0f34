// The `update` JSON of docs/interfaces.md and the /updating HDF5 group.
#include "mbid/updating/result_io.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <limits>

#include "mbid/common/json_io.h"

namespace mbid::updating {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

UpdateResult MakeResult() {
  UpdateResult result;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  ParameterEstimate c{"c_theta", "N*m/rad",   "",   true,  9.4e6, 8e6,  8e4, 8e8,
                      2e4,       2e4 / 9.4e6, true, false, -kInf, kInf, "",  {}};
  ParameterEstimate d{"d_eta", "N*m*s/rad", "",    true, 4e4,
                      5e4,     5e2,         5e6,   kNaN, kNaN,
                      false,   false,       -kInf, kInf, "no standard deviation",
                      {}};
  ParameterEstimate m{"drop/1:payload_mass_kg",
                      "kg",
                      "drop/1",
                      true,
                      650,
                      700,
                      7,
                      7e4,
                      1,
                      1 / 650.,
                      true,
                      false,
                      -kInf,
                      kInf,
                      "",
                      {}};
  c.profile.computed = true;
  c.profile.lower = 9.3e6;
  c.profile.upper = 9.6e6;
  c.profile.upper_open = true;
  c.profile.threshold = 4;
  c.profile.values = {9.3e6, 9.4e6, 9.6e6};
  c.profile.cost_rises = {4.1, 0, 2.5};
  c.profile.fits = 5;
  result.parameters = {c, d, m};
  result.correlation = Eigen::Matrix3d::Identity();
  result.correlation(1, 1) = kNaN;
  result.covariance = Eigen::Matrix3d::Identity() * 1e-6;
  result.termination = UpdateResult::Termination::kConverged;
  result.message = "Parameter tolerance reached.";
  result.iterations = 7;
  result.initial_cost = 1.2e5;
  result.final_cost = 812.5;
  result.history = {{0, 1.2e5, 0, 1e3, 10, true, 0.1, 1}, {1, 812.5, 0.3, 1e-3, 30, true, 0.5, 1}};
  result.singular_values = Eigen::Vector3d(3e4, 2e3, 1e-4);
  result.rank = 2;
  result.undetermined = {"d_eta"};
  result.warnings = {"the records leave undetermined: d_eta"};
  TestFit fit;
  fit.name = "drop/1";
  fit.channels = {"psi", "phi"};
  fit.noise_std = Eigen::Vector2d(1e-5, 1e-5);
  fit.noise_estimated = {false, true};
  fit.residual_rms = Eigen::Vector2d(1.1e-5, 0.9e-5);
  fit.correlation = Eigen::Vector2d(0.983, 0.99998);
  fit.simulated.channels = fit.channels;
  fit.simulated.units = {"rad", "rad"};
  fit.simulated.sample_interval_s = 0.01;
  fit.simulated.values = Eigen::MatrixXd::Random(5, 2) * 1e-3;
  fit.offset = Eigen::Vector2d(2e-4, -1e-4);
  fit.offset_std = Eigen::Vector2d(3e-6, kNaN);
  fit.drift = Eigen::Vector2d(1e-5, 2e-5);
  fit.drift_std = Eigen::Vector2d(4e-7, 5e-7);
  result.tests = {fit};
  result.simulations = 9;
  result.sensitivity_simulations = 8;
  result.rhs_evaluations = 123456;
  result.wall_time_s = 2.5;
  result.jacobian = "sensitivities";
  return result;
}

CharacteristicResult MakeAlgebraic() {
  CharacteristicResult algebraic;
  algebraic.status = CharacteristicResult::Status::kSolved;
  algebraic.lambda = {{-0.93, 3.62}, {-0.56, 9.50}};
  algebraic.coordinates = {"gamma", "theta"};
  algebraic.outputs = {"psi", "phi"};
  CharacteristicSolution set;
  set.c = Eigen::Vector2d(1.1e6, 9.4e6);
  set.d = Eigen::Vector2d(1.78e5, 1.16e5);
  set.admissible = true;
  set.initial_q = Eigen::Vector2d(4e-3, -6e-3);
  set.initial_u = Eigen::Vector2d(1e-5, 2e-5);
  set.correlation = Eigen::Vector2d(0.99, 0.999);
  set.mismatch = 0.01;
  set.displacement_mismatch = 0.005;
  set.velocity_mismatch = 0.008;
  CharacteristicSolution negative = set;
  negative.admissible = false;
  negative.d[0] = -1e4;
  negative.reason = "d_gamma = -1e+04 < 0";
  algebraic.solutions = {set, negative};
  algebraic.chosen = 0;
  algebraic.starts = 100;
  algebraic.converged_starts = 100;
  return algebraic;
}

TEST(ResultIoTest, JsonFollowsTheContract) {
  const CharacteristicResult algebraic = MakeAlgebraic();
  const nlohmann::json json = UpdateResultToJson(MakeResult(), &algebraic);
  // docs/interfaces.md: parameters with value, initial, lower, upper, std, units; termination,
  // iterations, cost {initial, final}, correlation per channel.
  const nlohmann::json& c = json.at("parameters").at("c_theta");
  EXPECT_EQ(c.at("value"), 9.4e6);
  EXPECT_EQ(c.at("initial"), 8e6);
  EXPECT_EQ(c.at("lower"), 8e4);
  EXPECT_EQ(c.at("upper"), 8e8);
  EXPECT_EQ(c.at("std"), 2e4);
  EXPECT_EQ(c.at("units"), "N*m/rad");
  // Profiled: the interval, which side is open, the points [value, rise]; absent otherwise.
  EXPECT_EQ(c.at("profile").at("interval"), nlohmann::json::array({9.3e6, 9.6e6}));
  EXPECT_EQ(c.at("profile").at("open"), nlohmann::json::array({false, true}));
  EXPECT_EQ(c.at("profile").at("points").at(2), nlohmann::json::array({9.6e6, 2.5}));
  EXPECT_EQ(c.at("profile").at("fits"), 5);
  EXPECT_FALSE(json.at("parameters").at("d_eta").contains("profile"));
  EXPECT_TRUE(json.at("parameters").at("d_eta").at("std").is_null());  // undetermined: null
  EXPECT_FALSE(json.at("parameters").at("d_eta").at("determined"));
  EXPECT_EQ(json.at("parameters").at("drop/1:payload_mass_kg").at("test"), "drop/1");
  EXPECT_EQ(json.at("termination"), "converged");
  EXPECT_EQ(json.at("iterations"), 7);
  EXPECT_EQ(json.at("cost").at("initial"), 1.2e5);
  EXPECT_EQ(json.at("cost").at("final"), 812.5);
  EXPECT_EQ(json.at("correlation").at("psi"), 0.983);
  EXPECT_EQ(json.at("undetermined"), nlohmann::json({"d_eta"}));
  EXPECT_EQ(json.at("history").size(), 2u);
  EXPECT_EQ(json.at("algebraic").at("status"), "solved");
  EXPECT_EQ(json.at("algebraic").at("sets").size(), 2u);
  EXPECT_EQ(json.at("algebraic").at("sets")[1].at("reason"), "d_gamma = -1e+04 < 0");
  EXPECT_EQ(json.at("algebraic").at("sets")[0].at("c").at("theta"), 9.4e6);
  // The fitted baseline per test and channel, with units; an undefined std is null.
  const nlohmann::json& test = json.at("tests")[0];
  EXPECT_EQ(test.at("offset").at("psi").at("value"), 2e-4);
  EXPECT_EQ(test.at("offset").at("psi").at("std"), 3e-6);
  EXPECT_EQ(test.at("offset").at("psi").at("units"), "rad");
  EXPECT_TRUE(test.at("offset").at("phi").at("std").is_null());
  EXPECT_EQ(test.at("drift").at("phi").at("value"), 2e-5);
  EXPECT_EQ(test.at("drift").at("phi").at("units"), "rad/s");
  // Absent when not fitted.
  UpdateResult plain = MakeResult();
  plain.tests[0].offset.resize(0);
  plain.tests[0].drift.resize(0);
  EXPECT_FALSE(UpdateResultToJson(plain).at("tests")[0].contains("offset"));
  EXPECT_FALSE(UpdateResultToJson(plain).at("tests")[0].contains("drift"));
  EXPECT_TRUE(DescribeBaseline(plain.tests[0]).empty());
  const std::vector<std::string> lines = DescribeBaseline(MakeResult().tests[0]);
  ASSERT_EQ(lines.size(), 4u);
  EXPECT_EQ(lines[0], "offset(drop/1, psi) = 0.0002 +- 3e-06 rad");
  EXPECT_EQ(lines[3], "drift(drop/1, phi) = 2e-05 +- 5e-07 rad/s");
  // Writable: JSON has no NaN, WriteJson would refuse one.
  const std::string path =
      (std::filesystem::temp_directory_path() / "mbid_update_result_test.json").string();
  EXPECT_NO_THROW(WriteJson(json, path));
  EXPECT_EQ(ReadJson(path).at("termination"), "converged");
  std::remove(path.c_str());
}

TEST(ResultIoTest, NoAdmissibleSetAloneIsAResultToo) {
  CharacteristicResult algebraic = MakeAlgebraic();
  algebraic.solutions.erase(algebraic.solutions.begin());
  algebraic.status = CharacteristicResult::Status::kNoAdmissibleSet;
  algebraic.chosen = -1;
  const nlohmann::json json = CharacteristicResultToJson(algebraic);
  EXPECT_EQ(json.at("status"), "no_admissible_set");
  EXPECT_EQ(json.at("sets")[0].at("residual"), 0.0);
}

TEST(ResultIoTest, Hdf5GroupRoundTrips) {
  const std::string path =
      (std::filesystem::temp_directory_path() / "mbid_update_result_test.h5").string();
  const UpdateResult result = MakeResult();
  const CharacteristicResult algebraic = MakeAlgebraic();
  {
    H5Writer writer(path);
    WriteUpdatingGroup(writer, result, &algebraic);
    writer.Commit();
  }
  const H5Reader reader(path);
  EXPECT_EQ(reader.ReadStringAttribute("/updating", "termination"), "converged");
  EXPECT_EQ(reader.ReadScalar("/updating/parameters/c_theta", "value"), 9.4e6);
  EXPECT_EQ(reader.ReadUnits("/updating/parameters/c_theta", "value"), "N*m/rad");
  EXPECT_TRUE(std::isnan(reader.ReadScalar("/updating/parameters/d_eta", "std")));
  EXPECT_EQ(reader.ReadScalar("/updating/parameters/c_theta/profile", "upper"), 9.6e6);
  EXPECT_EQ(reader.ReadStringAttribute("/updating/parameters/c_theta/profile", "upper_open"),
            "true");
  EXPECT_EQ(reader.ReadVector("/updating/parameters/c_theta/profile", "cost_rises")[0], 4.1);
  // '/' cannot be part of an HDF5 name: it becomes '_'.
  EXPECT_EQ(reader.ReadScalar("/updating/parameters/drop_1:payload_mass_kg", "value"), 650);
  EXPECT_EQ(reader.ReadScalar("/updating/cost", "final"), 812.5);
  EXPECT_EQ(reader.ReadScalar("/updating", "iterations"), 7);
  EXPECT_EQ(reader.ReadStrings("/updating", "undetermined"), result.undetermined);
  EXPECT_EQ(reader.ReadVector("/updating/history", "cost").size(), 2);
  EXPECT_EQ(reader.ReadScalar("/updating/correlation", "phi"), 0.99998);
  EXPECT_EQ(reader.ReadVector("/updating/tests/drop_1/simulated", "psi").size(), 5);
  EXPECT_EQ(reader.ReadScalar("/updating/tests/drop_1/offset", "psi"), 2e-4);
  EXPECT_EQ(reader.ReadScalar("/updating/tests/drop_1/offset_std", "psi"), 3e-6);
  EXPECT_EQ(reader.ReadScalar("/updating/tests/drop_1/drift", "phi"), 2e-5);
  EXPECT_EQ(reader.ReadUnits("/updating/tests/drop_1/drift", "phi"), "rad/s");
  EXPECT_EQ(reader.ReadScalar("/updating/tests/drop_1/drift_std", "phi"), 5e-7);
  EXPECT_EQ(reader.ReadMatrix("/updating", "parameter_correlation").rows(), 3);
  EXPECT_EQ(reader.ReadStringAttribute("/updating/algebraic", "status"), "solved");
  EXPECT_EQ(reader.ReadMatrix("/updating/algebraic", "c")(0, 1), 9.4e6);
  EXPECT_EQ(reader.ReadVector("/updating/algebraic", "admissible")[1], 0.0);
  std::remove(path.c_str());
}

}  // namespace
}  // namespace mbid::updating
