// Structural identification (updating/structure.h): the ranking finds the joint a record's
// machine did not have, and the leave-one-out prediction error reads in noise units.
#include "mbid/updating/structure.h"

#include <gtest/gtest.h>

#include <cmath>

#include "crane_fixture.h"
#include "mbid/model/multibody_model.h"
#include "mbid/model/rigid_coordinates.h"

namespace mbid::updating {
namespace {

using testing::Crane;
using testing::LoadCrane;

// 4 s of the reference test (CI time, as the other updating tests): the fast modes' decay and
// several cycles of the slow ones, 401 samples x 2 channels.
constexpr double kDurationS = 4.0;
// The sensors' noise in the reference scenario (sensors.noise_std_rad): the records' true sigma.
constexpr double kNoiseRad = 1e-5;

const model::MultibodyModel& AsMultibody(const model::MechanicalModel& model) {
  return dynamic_cast<const model::MultibodyModel&>(model);
}

// A noisy record of `machine` in the reference test (its excitation, sensors and seed).
TestRecord MakeRecord(const Crane& crane, const model::MechanicalModel& machine,
                      const std::string& name, const simulation::Excitation& excitation,
                      unsigned seed) {
  simulation::SimulationOptions options = crane.simulation;
  options.duration_s = kDurationS;
  simulation::SensorOptions sensors = crane.sensors;
  sensors.seed = seed;
  TestRecord test;
  test.name = name;
  test.record = simulation::Simulate(machine, excitation, options, sensors).measured;
  test.excitation = excitation;
  test.noise_std = {{"psi", kNoiseRad}, {"phi", kNoiseRad}};
  return test;
}

// The full crane and its variants with each joint rigid (K = 1), fitted from the scenario's
// values (the full model) and from the full fit (the others).
std::vector<StructureCandidate> CraneCandidates(const Crane& crane, int max_rigid) {
  const model::MultibodyModel& full = AsMultibody(*crane.model);
  std::vector<StructureCandidate> candidates;
  candidates.push_back({"full",
                        {},
                        "",
                        std::shared_ptr<const model::MechanicalModel>(full.Clone()),
                        UpdateOptions(),
                        false});
  for (const auto& rigid :
       EnumerateRigidSets(model::CompliantCoordinates(full.description()), max_rigid)) {
    candidates.push_back(
        {"rigid", rigid, "",
         std::make_shared<const model::MultibodyModel>(model::MakeCoordinatesRigid(full, rigid)),
         UpdateOptions(), true});
  }
  return candidates;
}

TEST(StructureTest, EnumeratesRigidSetsSmallerFirst) {
  const std::vector<std::string> joints{"alpha", "gamma", "eta", "theta"};
  const auto one = EnumerateRigidSets(joints, 1);
  ASSERT_EQ(one.size(), 4u);
  EXPECT_EQ(one[3], std::vector<std::string>{"theta"});
  const auto two = EnumerateRigidSets(joints, 2);
  ASSERT_EQ(two.size(), 10u);  // 4 singles + C(4, 2) = 6 pairs
  EXPECT_EQ(two[4], (std::vector<std::string>{"alpha", "gamma"}));
  EXPECT_EQ(two[9], (std::vector<std::string>{"eta", "theta"}));
  EXPECT_TRUE(EnumerateRigidSets(joints, 0).empty());
  EXPECT_EQ(EnumerateRigidSets(joints, 9).size(), 15u);  // every non-empty subset: 2^4 - 1
}

TEST(StructureTest, WeightedResidualOfTheTrueModelIsTheNoise) {
  // The machine that made the record, simulated as it is: the residual is the sensor noise, so
  // its rms in noise units is 1 within sampling error (802 residuals: 1 +- 0.025, 1/sqrt(2N)).
  const Crane crane = LoadCrane(testing::kReferenceScenario);
  const TestRecord test = MakeRecord(crane, *crane.model, "full", crane.excitation, 1);
  const Eigen::MatrixXd r = CalcWeightedResidual(*crane.model, test, UpdateOptions().integrator);
  ASSERT_EQ(r.rows(), test.record.samples());
  const double rms = std::sqrt(r.squaredNorm() / static_cast<double>(r.size()));
  EXPECT_NEAR(rms, 1.0, 0.1);  // 4 standard errors of the rms
}

// Test (1) of the issue: a record of the crane with the boom's luffing joint theta welded. Every
// candidate but "rigid theta" misses it by orders of magnitude in cost: the other rigid variants
// keep a luffing mode the record does not have and lack one it has, and the full model cannot
// stiffen theta enough within its bounds (c_theta at most 100x the scenario's: measured cost
// 3.1e5 against 432 for rigid theta). Had it fitted as well, BIC would still charge its two extra
// parameters ln N = 6.7 each.
TEST(StructureTest, RecordWithThetaWeldedRanksRigidThetaFirst) {
  const Crane crane = LoadCrane(testing::kReferenceScenario);
  const model::MultibodyModel welded =
      model::MakeCoordinatesRigid(AsMultibody(*crane.model), {"theta"});
  const std::vector<TestRecord> tests = {
      MakeRecord(crane, welded, "theta-welded", crane.excitation, 1)};
  StructureOptions options;
  options.threads = 2;
  // The reference fitted from the scenario's values alone (CI time) ends at the minimum the
  // default search of twelve design points finds (cost 3.1e5, above; measured 312961).
  options.search.enabled = false;
  options.quiet = true;
  const StructureRanking ranking = RankStructures(CraneCandidates(crane, 1), tests, options);
  ASSERT_EQ(ranking.structures.size(), 5u);
  const StructureFit& best = ranking.structures.front();
  EXPECT_EQ(best.rigid, std::vector<std::string>{"theta"});
  EXPECT_EQ(best.coordinates, (std::vector<std::string>{"alpha", "gamma", "eta"}));
  EXPECT_EQ(best.parameter_count, 6);  // c_, d_ of three joints
  EXPECT_EQ(best.residual_count, 802);
  EXPECT_EQ(best.rank, 1);
  // The right structure fits to the noise: 2 cost / N near 1, whose standard error over 802
  // residuals is sqrt(2 / 802) = 0.05 (measured 1.078); 0.2 is four of them.
  EXPECT_NEAR(2 * best.cost / 802, 1.0, 0.2);
  // The runner-up trails by more than 10 (Kass and Raftery's "very strong" evidence).
  EXPECT_GT(ranking.structures[1].delta_bic, 10.0);
  // One record: no leave-one-out.
  EXPECT_TRUE(std::isnan(best.prediction_error));
  for (const StructureFit& fit : ranking.structures)
    EXPECT_TRUE(fit.skipped.empty()) << fit.skipped;
  // Every candidate was weighed with the same sigma, the given one.
  ASSERT_EQ(ranking.noise_std.size(), 1u);
  EXPECT_EQ(ranking.noise_std[0].at("psi"), kNoiseRad);
}

// Leave-one-out on two tests of the full crane (the reference initial deflection and a load
// drop): fitted to one, the full model predicts the other to the noise level; the crane with
// theta rigid cannot. The full structure ranks first (test (2) of the issue for the library).
TEST(StructureTest, LeaveOneOutPredictsTheHeldOutRecord) {
  const Crane crane = LoadCrane(testing::kReferenceScenario);
  const Crane drop = LoadCrane(testing::kLoadDropScenario);
  const std::vector<TestRecord> tests = {
      MakeRecord(crane, *crane.model, "deflection", crane.excitation, 1),
      MakeRecord(crane, *crane.model, "load-drop", drop.excitation, 2)};
  std::vector<StructureCandidate> candidates = CraneCandidates(crane, 1);
  // The full model and rigid theta (the weakest misfit above): CI time.
  candidates.erase(candidates.begin() + 1, candidates.begin() + 4);
  ASSERT_EQ(candidates[1].rigid, std::vector<std::string>{"theta"});
  StructureOptions options;
  options.threads = 2;
  // No global search (CI time): the reference's fit from the scenario's values (the truth) is
  // the best end the search finds too (cost 840).
  options.search.enabled = false;
  options.quiet = true;
  const StructureRanking ranking = RankStructures(candidates, tests, options);
  ASSERT_EQ(ranking.structures.size(), 2u);
  const StructureFit& best = ranking.structures.front();
  EXPECT_TRUE(best.rigid.empty());
  ASSERT_EQ(best.prediction_error_per_record.size(), 2u);
  // Predicted to the noise: rms near 1 (the fit to one record leaves parameter errors of a few
  // tenths of a standard deviation in the other's prediction; 1.2 bounds that with margin).
  // Fitted to the deflection test (which excites every mode), the full model predicts the load
  // drop to the noise: measured 1.010; the bound allows the rms' sampling error (+-0.025 over 802
  // residuals) and the fit's parameter errors several times over.
  EXPECT_GT(best.prediction_error_per_record[1], 0.95);
  EXPECT_LT(best.prediction_error_per_record[1], 1.1);
  // Fitted to the load drop alone, whose record leaves some joints' parameters loose (the update
  // tests name them undetermined), it predicts the deflection test less well: measured 1.81.
  EXPECT_LT(best.prediction_error_per_record[0], 2.5);
  EXPECT_LT(best.prediction_error, 2.0);  // pooled: measured 1.46
  // Without theta the boom's luffing mode is missing: the prediction misses by many sigma
  // (measured 111).
  EXPECT_GT(ranking.structures[1].prediction_error, 10.0);
}

}  // namespace
}  // namespace mbid::updating
