// The global search of Route 2 (global_search.h) and the credibility of its numbers
// (credibility.h), on the case that fooled the local fit: the paper's 650 kg load drop of the
// reference crane with 1e-5 rad noise, started from a design model 22-36% off.
#include "mbid/updating/global_search.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "crane_fixture.h"
#include "mbid/updating/credibility.h"
#include "oscillator_fixture.h"

namespace mbid::updating {
namespace {

using testing::Crane;
using testing::LoadCrane;

// A design model's values: each joint parameter 22-36% off the truth, in both directions, as
// the trial had them (c_alpha +27%, d_alpha -25%, c_gamma +27%, d_gamma +29%, c_eta
// -27%, d_eta +32%, c_theta -22%, d_theta +29%).
const std::map<std::string, double> kDesignFactors{
    {"c_alpha", 1.27}, {"d_alpha", 0.75}, {"c_gamma", 1.27}, {"d_gamma", 1.29},
    {"c_eta", 0.73},   {"d_eta", 1.32},   {"c_theta", 0.78}, {"d_theta", 1.29}};

UpdateOptions DesignModel(const model::MechanicalModel& truth) {
  UpdateOptions options;
  for (const auto& [name, f] : kDesignFactors) {
    ParameterSetting setting;
    setting.name = name;
    setting.initial = truth.GetParameter(name) * f;
    options.parameters.push_back(setting);
  }
  options.quiet = true;
  return options;
}

struct LoadDrop {
  Crane crane = LoadCrane(testing::kLoadDropScenario);
  TestRecord test;
  LoadDrop(double duration_s) {
    crane.sensors.seed = 3;
    test = testing::SimulateTest(crane, "load drop", duration_s);
  }
  UpdateOptions Options() const {
    UpdateOptions options = DesignModel(*crane.model);
    options.integrator = crane.simulation.integrator;
    options.integrator.interpolate_outputs = true;
    return options;
  }
};

// No parameter may be reported determined with the truth outside 4 of its (inflated) standard
// deviations: the acceptance rule.
void ExpectNoConfidentWrongAnswer(const UpdateResult& result, const model::MechanicalModel& truth) {
  for (const ParameterEstimate& p : result.parameters) {
    if (!p.determined || !p.test.empty()) continue;
    const double error = std::abs(std::log(p.value / truth.GetParameter(p.name)));
    EXPECT_LE(error, 4 * p.relative_std * result.std_inflation)
        << p.name << " = " << p.value << " reported determined, truth "
        << truth.GetParameter(p.name);
  }
}

TEST(GlobalSearchTest, FindsTheTrueMinimumAndReportsTheSwappedOneAsAlternative) {
  const LoadDrop drop(8.0);
  GlobalSearchOptions search;
  search.threads = 2;
  // 4 design points for CI time: the true minimum and the swapped alternative are reached from
  // the same starts as with the default 12 (measured: best chi^2/dof 0.998 with either; 3 minima
  // kept against 4).
  search.design_starts = 4;
  const GlobalSearchResult result =
      SearchGlobally(*drop.crane.model, {drop.test}, drop.Options(), "design", {}, search);
  ASSERT_FALSE(result.minima.empty());
  const UpdateResult& best = result.best;
  ASSERT_EQ(best.termination, UpdateResult::Termination::kConverged);
  RecordProperty("minima", static_cast<int>(result.minima.size()));
  RecordProperty("chi_square_per_dof", std::to_string(best.chi_square_per_dof));
  RecordProperty("wall_time_s", std::to_string(result.wall_time_s));
  // At the true minimum the residual is the noise: chi^2/dof within 10% of 1 (its sampling
  // spread over 1602 residuals is 3.5%; the weights are the true noise).
  EXPECT_NEAR(best.chi_square_per_dof, 1.0, 0.1);
  EXPECT_TRUE(best.credible);
  // c_alpha, the one the local fit got 43% wrong, within 3% (its std is about 0.6%).
  EXPECT_NEAR(best.Find("c_alpha").value / drop.crane.model->GetParameter("c_alpha"), 1.0, 0.03);
  ExpectNoConfidentWrongAnswer(best, *drop.crane.model);
  // The load drop barely moves the 2.3 and 3.1 Hz modes: a set with gamma and eta trading roles
  // fits as well (measured: cost 792.4 against 790.5, F = 0.49), so the result must say that
  // the minimum is not unique and leave those parameters undetermined.
  EXPECT_TRUE(result.non_unique);
  for (const char* name : {"c_gamma", "c_eta"}) {
    EXPECT_NE(std::find(result.differing.begin(), result.differing.end(), name),
              result.differing.end())
        << name;
    EXPECT_FALSE(best.Find(name).determined) << name;
  }
  // The worse local minima (the design model's own, cost about 10 times the noise's) are kept
  // as minima but are no alternatives: the F-test separates them.
  bool separated = false;
  for (const SearchMinimum& minimum : result.minima) {
    separated = separated || (!minimum.alternative && minimum.cost > 2 * result.minima[0].cost &&
                              minimum.p_value < 1e-6);
  }
  EXPECT_TRUE(separated);
  // The local fit from the design model (the search's primary start, fitted as a local fit
  // alone would fit it) ends at c_alpha about 0.57 of the truth with a 0.3% std (the issue's
  // trial): its residual is about 3 times the 1e-5 rad noise, which the credibility check must
  // turn into "nothing determined".
  const auto design = std::find_if(result.minima.begin(), result.minima.end(), [](const auto& m) {
    return std::find(m.starts.begin(), m.starts.end(), "design") != m.starts.end();
  });
  ASSERT_NE(design, result.minima.end());
  const UpdateResult& local = design->fit;
  ASSERT_EQ(local.termination, UpdateResult::Termination::kConverged);
  RecordProperty("local_chi_square_per_dof", std::to_string(local.chi_square_per_dof));
  // 4: UpdateOptions::max_chi_square_per_dof (residual rms twice the noise).
  EXPECT_GT(local.chi_square_per_dof, 4);
  EXPECT_FALSE(local.credible);
  for (const ParameterEstimate& p : local.parameters) EXPECT_FALSE(p.determined) << p.name;
  EXPECT_NEAR(local.Find("c_alpha").value / drop.crane.model->GetParameter("c_alpha"), 0.57, 0.05);
}

// The same drop cut to 6 s: no start of the search reaches the true minimum (measured, with the
// default 12 design points and with the 4 used here for CI time: the best end has cost 797
// against about 600 at the truth, chi^2/dof 1.335 over 1194 degrees of freedom, c_alpha 5.8% off
// with a 0.4% std, residual correlation time 6). Its excess over the noise is small but not
// white, so the fit must not be believed: nothing determined.
TEST(GlobalSearchTest, AMissedMinimumOnAShorterDropIsNotBelieved) {
  const LoadDrop drop(6.0);
  GlobalSearchOptions search;
  search.threads = 2;
  search.design_starts = 4;
  const GlobalSearchResult result =
      SearchGlobally(*drop.crane.model, {drop.test}, drop.Options(), "design", {}, search);
  const UpdateResult& best = result.best;
  ASSERT_EQ(best.termination, UpdateResult::Termination::kConverged);
  RecordProperty("chi_square_per_dof", std::to_string(best.chi_square_per_dof));
  ExpectNoConfidentWrongAnswer(best, *drop.crane.model);
  // 1.2: the excess the credibility check notices; at the truth 1 +- 0.04 (sqrt(2 / 1194)).
  if (best.chi_square_per_dof > 1.2) {
    EXPECT_FALSE(best.explains_records);
    EXPECT_FALSE(best.credible);
    for (const ParameterEstimate& p : best.parameters) {
      EXPECT_FALSE(p.determined) << p.name;
      EXPECT_NE(p.why_undetermined.find("not white"), std::string::npos) << p.why_undetermined;
    }
  }
}

TEST(GlobalSearchTest, FTestQuantilesMatchTheTables) {
  // F(0.95; 1, 10) = 4.9646 and F(0.95; 8, 1594) = 1.94 (to the tables' digits); the survival
  // function is the quantile's inverse.
  EXPECT_NEAR(FQuantile(0.05, 1, 10), 4.9646, 1e-4);
  EXPECT_NEAR(FQuantile(0.05, 8, 1594), 1.94, 0.01);
  EXPECT_NEAR(FSurvival(FQuantile(0.01, 3, 50), 3, 50), 0.01, 1e-10);
  EXPECT_EQ(FSurvival(0, 3, 50), 1.0);
}

// A free decay of the scenario's crane with its noise, and fit options starting every joint
// parameter at truth * factor[name].
struct NearStart {
  Crane crane;
  TestRecord test;
  UpdateOptions options;
  NearStart(const std::string& scenario, double duration_s,
            const std::map<std::string, double>& factor)
      : crane(LoadCrane(scenario)) {
    crane.sensors.seed = 3;
    test = testing::SimulateTest(crane, "decay", duration_s);
    options = DesignModel(*crane.model);
    options.integrator = crane.simulation.integrator;
    options.integrator.interpolate_outputs = true;
    for (ParameterSetting& p : options.parameters) {
      p.initial = crane.model->GetParameter(p.name) * factor.at(p.name);
    }
  }
  // The search's only fit, from the start, with or without the matched radius.
  UpdateResult Fit(bool matches_poles) const {
    GlobalSearchOptions search;
    search.enabled = false;
    search.primary_matches_poles = matches_poles;
    return SearchGlobally(*crane.model, {test}, options, "route1", {}, search).best;
  }
};

TEST(GlobalSearchTest, SameBitsWithOneOrTwoThreads) {
  // The reference crane's free decay (2 s) from the design model, with few design points
  // screened for few iterations: cheap fits (the load drop's take seconds each). The point is
  // that the parallel local fits each fill their own slot, so the result cannot depend on the
  // thread count.
  const NearStart decay(testing::kReferenceScenario, 2.0, kDesignFactors);
  GlobalSearchOptions search;
  search.design_starts = 4;
  search.screen_iterations = 5;
  search.full_fits = 2;
  search.threads = 1;
  const GlobalSearchResult one =
      SearchGlobally(*decay.crane.model, {decay.test}, decay.options, "design", {}, search);
  search.threads = 2;
  const GlobalSearchResult two =
      SearchGlobally(*decay.crane.model, {decay.test}, decay.options, "design", {}, search);
  // Work for both threads: the design points screened and more than one whole-record fit.
  EXPECT_EQ(one.screened, 4);
  EXPECT_GE(one.full_fits, 2);
  ASSERT_EQ(one.minima.size(), two.minima.size());
  for (size_t m = 0; m < one.minima.size(); ++m) {
    EXPECT_EQ(one.minima[m].cost, two.minima[m].cost);
    EXPECT_EQ(one.minima[m].starts, two.minima[m].starts);
    for (const ParameterEstimate& p : one.minima[m].fit.parameters) {
      EXPECT_EQ(p.value, two.minima[m].fit.Find(p.name).value) << p.name;
    }
  }
}

TEST(GlobalSearchTest, AStartWithTheIdentifiedPolesTakesLargerFirstSteps) {
  // Route 1's set matches the identified poles: about 1% off on the reference crane's 8 s
  // record. From there the matched radius (1000) reaches the minimum in fewer iterations than
  // the cautious radius (10) meant for far starts (3 against 5 through mbid update), at the
  // same cost.
  const NearStart reference(testing::kReferenceScenario, 8.0,
                            {{"c_alpha", 1.01},
                             {"d_alpha", 0.99},
                             {"c_gamma", 1.01},
                             {"d_gamma", 1.01},
                             {"c_eta", 0.99},
                             {"d_eta", 1.01},
                             {"c_theta", 0.99},
                             {"d_theta", 1.01}});
  const UpdateResult cautious = reference.Fit(false);
  const UpdateResult matched = reference.Fit(true);
  ASSERT_EQ(cautious.termination, UpdateResult::Termination::kConverged);
  ASSERT_EQ(matched.termination, UpdateResult::Termination::kConverged);
  RecordProperty("iterations",
                 std::to_string(cautious.iterations) + " -> " + std::to_string(matched.iterations));
  EXPECT_LT(matched.iterations, cautious.iterations);
  // 1e-5: each stops where a step gains less than the function tolerance (1e-6 relative), which
  // on a linearly converging path leaves a few times that to the minimum.
  EXPECT_NEAR(matched.final_cost / cautious.final_cost, 1.0, 1e-5);
  for (size_t i = 0; i < matched.parameters.size(); ++i) {
    // Far inside the estimates' own uncertainty: 0.05 of a standard deviation.
    EXPECT_LT(std::abs(matched.parameters[i].value - cautious.parameters[i].value),
              0.05 * cautious.parameters[i].std)
        << matched.parameters[i].name;
  }
}

TEST(GlobalSearchTest, LargerFirstStepsEndNoHigherInAFlatValley) {
  // The load drop leaves d_eta and c_gamma weakly determined: from 3-6% off, the cautious
  // radius stops early on the valley's slope (the function tolerance is relative), the matched
  // one follows it further down. Larger first steps must never end higher.
  const NearStart drop(testing::kLoadDropScenario, 4.0,
                       {{"c_alpha", 1.04},
                        {"d_alpha", 0.95},
                        {"c_gamma", 1.03},
                        {"d_gamma", 1.06},
                        {"c_eta", 0.96},
                        {"d_eta", 1.05},
                        {"c_theta", 0.97},
                        {"d_theta", 1.04}});
  const UpdateResult cautious = drop.Fit(false);
  const UpdateResult matched = drop.Fit(true);
  ASSERT_EQ(cautious.termination, UpdateResult::Termination::kConverged);
  ASSERT_EQ(matched.termination, UpdateResult::Termination::kConverged);
  RecordProperty("costs",
                 std::to_string(cautious.final_cost) + " -> " + std::to_string(matched.final_cost));
  // 1e-5: as above, where either may stop; a far minimum would be orders of magnitude above.
  EXPECT_LE(matched.final_cost, cautious.final_cost * (1 + 1e-5));
}

TEST(GlobalSearchTest, RejectsBadOptions) {
  GlobalSearchOptions search;
  search.significance = 1.5;
  std::string why;
  EXPECT_FALSE(search.IsValid(&why));
  EXPECT_NE(why.find("significance"), std::string::npos);
  GlobalSearchOptions radius;
  radius.matched_trust_region_radius = -1;
  EXPECT_FALSE(radius.IsValid(&why));
  EXPECT_NE(why.find("matched_trust_region_radius"), std::string::npos);
  GlobalSearchOptions screen;
  screen.screen_relative_tolerance = 0;
  EXPECT_FALSE(screen.IsValid(&why));
  EXPECT_NE(why.find("screen_relative_tolerance"), std::string::npos);
  const LoadDrop drop(1.0);
  EXPECT_THROW(SearchGlobally(*drop.crane.model, {drop.test}, drop.Options(), "design", {}, search),
               InputError);
}

// A fit result around a residual of known colour: the whiteness and the inflation it causes.
UpdateResult FitWithResidual(const Eigen::VectorXd& residual, TestRecord* test) {
  test->record.channels = {"psi"};
  test->record.sample_interval_s = 0.01;
  test->record.values = Eigen::MatrixXd::Zero(residual.size(), 1);
  UpdateResult result;
  TestFit fit;
  fit.name = "t";
  fit.channels = {"psi"};
  fit.noise_std = Eigen::VectorXd::Ones(1);
  fit.noise_estimated = {false};
  fit.simulated = test->record;
  fit.simulated.values.col(0) = residual;
  result.tests = {fit};
  ParameterEstimate p;
  p.name = "c_alpha";
  p.value = 1e7;
  p.std = 1e5;
  p.relative_std = 0.01;
  result.parameters = {p};
  result.final_cost = residual.squaredNorm() / 2;
  return result;
}

// `count` samples of AR(1) noise, x_j = rho x_(j-1) + sqrt(1 - rho^2) e_j, scaled to `std`:
// white for rho = 0.
Eigen::VectorXd Ar1Noise(Eigen::Index count, double rho, double std, std::uint64_t seed) {
  std::mt19937_64 random(seed);
  std::normal_distribution<double> normal;
  Eigen::VectorXd noise(count);
  double value = 0;
  for (Eigen::Index i = 0; i < count; ++i) {
    value = rho * value + std::sqrt(1 - rho * rho) * normal(random);
    noise[i] = std * value;
  }
  return noise;
}

// The credibility check of a fit whose residual is `residual` against unit weights.
UpdateResult AssessResidual(const Eigen::VectorXd& residual) {
  TestRecord test;
  UpdateResult result = FitWithResidual(residual, &test);
  AssessCredibility(result, {test}, UpdateOptions());
  return result;
}

TEST(CredibilityTest, WhiteResidualAtTheNoiseIsCredible) {
  const UpdateResult result = AssessResidual(Ar1Noise(4000, 0.0, 1.0, 11));
  // Unit-variance noise against unit weights: chi^2/dof within 5% of 1 (spread 2.2% at 4000).
  EXPECT_NEAR(result.chi_square_per_dof, 1.0, 0.05);
  EXPECT_TRUE(result.credible);
  EXPECT_TRUE(result.parameters[0].determined);
  // Interval: value */ exp(2 * 0.01) with no inflation (white: p-value far above 1e-3).
  EXPECT_NEAR(result.parameters[0].interval_upper, 1e7 * std::exp(0.02), 1.0);
}

TEST(CredibilityTest, ColouredResidualInflatesTheStandardDeviations) {
  // AR(1) with rho = 0.8 at unit variance: correlation time 1 + 2 sum_{k<=20} 0.8^k = 8.9, so
  // the standard deviations are scaled by about 3.
  const UpdateResult result = AssessResidual(Ar1Noise(20000, 0.8, 1.0, 12));
  EXPECT_NEAR(result.tests[0].correlation_time[0], 8.9, 1.0);
  EXPECT_NEAR(result.std_inflation, std::sqrt(8.9), 0.3);
  EXPECT_FALSE(result.credible);
  // 3 % inflated, below 30 %, but a fit that is not credible determines nothing: a model that
  // lacks something leaves such a residual too.
  EXPECT_FALSE(result.parameters[0].determined);
  EXPECT_NE(result.parameters[0].why_undetermined.find("not credible"), std::string::npos);
  // At the noise's level, so the reason says so, and names coloured sensor noise beside a model
  // that lacks something (a trial's filtered logger at chi^2/dof 0.99 read "above the noise").
  EXPECT_NE(result.parameters[0].why_undetermined.find("at the records' noise"), std::string::npos)
      << result.parameters[0].why_undetermined;
  EXPECT_NE(result.parameters[0].why_undetermined.find("coloured sensor noise"), std::string::npos);
}

// Two springs in series that one sensor sees as one: each undetermined, and the reason says the
// records know their combination (a trial's read only "relative std 0.71 above 0.3").
TEST(CredibilityTest, AParameterKnownOnlyInACombinationNamesItsPartner) {
  UpdateResult result;
  for (const char* name : {"c_qa", "c_qb", "d_qa"}) {
    ParameterEstimate p;
    p.name = name;
    p.value = 1e4;
    p.std = 7e3;
    p.relative_std = 0.7;
    result.parameters.push_back(p);
  }
  result.correlation = Eigen::Matrix3d{{1, -0.9999, 0.5}, {-0.9999, 1, -0.5}, {0.5, -0.5, 1}};
  ASSERT_TRUE(MarkIfSpreadUndetermined(result.parameters[0], 1.0, 0.3, &result));
  EXPECT_EQ(result.parameters[0].why_undetermined,
            "relative std 0.7 above 0.3; correlated -1 with c_qb: the records determine a "
            "combination of the two (as of two joints in series that the sensors see as one), not "
            "each");
  ASSERT_TRUE(MarkIfSpreadUndetermined(result.parameters[2], 1.0, 0.3, &result));
  EXPECT_EQ(result.parameters[2].why_undetermined, "relative std 0.7 above 0.3");
}

TEST(CredibilityTest, WhiteExcessOverTheNoiseOnlyInflates) {
  // White noise 1.2 times the stated level (chi^2/dof 1.44): the level was stated too low, the
  // model still explains the record; the standard deviations are scaled by 1.2.
  const UpdateResult result = AssessResidual(Ar1Noise(4000, 0.0, 1.2, 14));
  EXPECT_NEAR(result.chi_square_per_dof, 1.44, 0.07);  // spread 2.2% of 1.44 at 4000
  EXPECT_NEAR(result.std_inflation, 1.2, 0.03);
  EXPECT_TRUE(result.explains_records);
  EXPECT_TRUE(result.parameters[0].determined);
}

TEST(CredibilityTest, AFewSamplesFarBeyondTheNoiseDetermineNothing) {
  // A trial's hammer blow 10 % off: the misfit sits in the samples under the pulse (33 times the
  // noise in one), the rest is white at the noise. Here: unit white noise with two samples at 30
  // and -20: chi^2/dof 1 + 1300 / 4000 = 1.33 and white (Ljung-Box sees two spikes as noise), so
  // it was taken for a noise level stated too low, and the parameter stayed determined.
  // Gaussian noise passes 4.9 times its spread in one of 4000 samples with probability 1e-3.
  Eigen::VectorXd residual = Ar1Noise(4000, 0.0, 1.0, 19);
  residual[1] = 30;
  residual[2] = -20;
  const UpdateResult result = AssessResidual(residual);
  EXPECT_FALSE(result.credible);
  EXPECT_FALSE(result.explains_records);
  EXPECT_FALSE(result.parameters[0].determined);
  ASSERT_FALSE(result.credibility.empty());
  EXPECT_NE(result.credibility[0].find("the residual of psi of t at 0.01 s is"), std::string::npos)
      << result.credibility[0];
  // The same excess spread over every sample (noise stated 15 % too low) is no spike: inflated.
  const UpdateResult white = AssessResidual(Ar1Noise(4000, 0.0, 1.15, 19));
  EXPECT_TRUE(white.explains_records);
  EXPECT_TRUE(white.parameters[0].determined);
}

TEST(CredibilityTest, AResidualFarBelowTheWeightsSaysTheNoiseIsOverstated) {
  // White noise half the stated level (chi^2/dof 0.25, 5 sampling std below 1 is 0.89 at
  // 4000): the weights overstate the noise and the standard deviations are twice too large;
  // said, not changed (on the safe side). At the noise's level nothing is said.
  const UpdateResult result = AssessResidual(Ar1Noise(4000, 0.0, 0.5, 14));
  EXPECT_NEAR(result.chi_square_per_dof, 0.25, 0.02);
  EXPECT_EQ(result.std_inflation, 1.0);
  EXPECT_TRUE(result.parameters[0].determined);
  ASSERT_EQ(result.credibility.size(), 1u);
  EXPECT_NE(result.credibility[0].find("that noise is overstated"), std::string::npos)
      << result.credibility[0];
  EXPECT_TRUE(AssessResidual(Ar1Noise(4000, 0.0, 1.0, 11)).credibility.empty());
}

TEST(CredibilityTest, ColouredExcessOverTheNoiseDeterminesNothing) {
  // A smaller excess, coloured (AR(1), rho = 0.8, 1.08 times the noise: chi^2/dof 1.17, spread
  // 3% over 20000 samples of correlation time 8.9): signal the model does not reproduce, which
  // no inflation makes trustworthy. Missed minima of the load drop ended at 1.15-1.34.
  const UpdateResult result = AssessResidual(Ar1Noise(20000, 0.8, 1.08, 15));
  EXPECT_GT(result.chi_square_per_dof, 1.05);
  EXPECT_LT(result.chi_square_per_dof, 1.2);
  EXPECT_FALSE(result.explains_records);
  EXPECT_FALSE(result.credible);
  EXPECT_FALSE(result.parameters[0].determined);
  EXPECT_NE(result.parameters[0].why_undetermined.find("not white"), std::string::npos);
  // Coloured at the noise's own level stays determined (ColouredResidualInflates... above), and
  // so does a white residual at the noise (WhiteResidualAtTheNoiseIsCredible).
}

// White noise plus a sinusoid at 0.3 of the sample rate: a model's mode a little off, as a
// trial's gantry left at 8 Hz. Its autocorrelations alternate in sign, so their sum (the
// correlation time) is clamped to 1, and the rule that asked for a correlation time above 1
// never fired: a trolley mass 7.5 % off gave c_lift 29,600 std from the truth, "passed".
Eigen::VectorXd OscillatingExcess(Eigen::Index count, double amplitude, double noise_std,
                                  std::uint64_t seed) {
  Eigen::VectorXd residual = Ar1Noise(count, 0.0, noise_std, seed);
  for (Eigen::Index i = 0; i < count; ++i) {
    residual[i] += amplitude * std::cos(2 * M_PI * 0.3 * static_cast<double>(i) + 0.4);
  }
  return residual;
}

TEST(CredibilityTest, AnOscillatingExcessDeterminesNothing) {
  // Amplitude 0.8 over unit noise: chi^2/dof 1 + 0.8^2 / 2 = 1.32.
  const UpdateResult result = AssessResidual(OscillatingExcess(4000, 0.8, 1.0, 16));
  EXPECT_NEAR(result.chi_square_per_dof, 1.32, 0.07);
  EXPECT_EQ(result.tests[0].correlation_time[0], 1.0);  // the clamp
  EXPECT_FALSE(result.explains_records);
  EXPECT_FALSE(result.parameters[0].determined);
  EXPECT_NE(result.parameters[0].why_undetermined.find("not white"), std::string::npos)
      << result.parameters[0].why_undetermined;
}

TEST(CredibilityTest, OneChannelsExcessDoesNotHideInThePooledChiSquare) {
  // Channel psi: the oscillating excess (1.32 of its noise); phi: white at 0.8 of its stated
  // noise (weights that overstate it, as an identification's residual may). Pooled chi^2/dof
  // (1.32 + 0.64) / 2 = 0.98: below any excess, while psi alone is far above its noise.
  TestRecord test;
  UpdateResult result = FitWithResidual(OscillatingExcess(4000, 0.8, 1.0, 17), &test);
  test.record.channels = {"psi", "phi"};
  test.record.units = {"rad", "rad"};
  test.record.values = Eigen::MatrixXd::Zero(4000, 2);
  TestFit& fit = result.tests[0];
  fit.channels = test.record.channels;
  fit.noise_std = Eigen::VectorXd::Ones(2);
  fit.noise_estimated = {false, false};
  const Eigen::VectorXd psi = fit.simulated.values.col(0);
  fit.simulated = test.record;
  fit.simulated.values.col(0) = psi;
  fit.simulated.values.col(1) = Ar1Noise(4000, 0.0, 0.8, 18);
  result.final_cost = fit.simulated.values.squaredNorm() / 2;
  AssessCredibility(result, {test}, UpdateOptions());
  EXPECT_LT(result.chi_square_per_dof, 1.05);
  EXPECT_FALSE(result.explains_records);
  EXPECT_FALSE(result.parameters[0].determined);
  ASSERT_FALSE(result.credibility.empty());
  EXPECT_NE(result.credibility[0].find("the residual of psi of t is"), std::string::npos)
      << result.credibility[0];
}

TEST(CredibilityTest, AnIntervalReachingABoundIsUndetermined) {
  // 1% std: the interval is 1e7 */ exp(0.02) = [9.80e6, 1.02e7]. A lower bound at 9.9e6 lies
  // inside it: the records allow the bound itself, so the estimate is the bound's, not theirs.
  TestRecord test;
  UpdateResult result = FitWithResidual(Ar1Noise(4000, 0.0, 1.0, 11), &test);
  result.parameters[0].lower = 9.9e6;
  result.parameters[0].upper = 1e9;
  AssessCredibility(result, {test}, UpdateOptions());
  EXPECT_FALSE(result.parameters[0].determined);
  EXPECT_NE(result.parameters[0].why_undetermined.find("reaches the lower bound"),
            std::string::npos)
      << result.parameters[0].why_undetermined;
  // The same fit with bounds outside the interval stays determined.
  result = FitWithResidual(Ar1Noise(4000, 0.0, 1.0, 11), &test);
  result.parameters[0].lower = 9e6;
  result.parameters[0].upper = 1.1e7;
  AssessCredibility(result, {test}, UpdateOptions());
  EXPECT_TRUE(result.parameters[0].determined);
}

TEST(CredibilityTest, ResidualFarAboveTheNoiseDeterminesNothing) {
  // A residual 3 times the records' noise (chi^2/dof 9 > 4): a local minimum or a missing
  // piece of the model; even a 1% std means nothing there.
  const UpdateResult result = AssessResidual(Ar1Noise(4000, 0.0, 3.0, 13));
  EXPECT_NEAR(result.chi_square_per_dof, 9.0, 0.5);
  EXPECT_FALSE(result.credible);
  EXPECT_FALSE(result.parameters[0].determined);
  EXPECT_NE(result.parameters[0].why_undetermined.find("does not explain"), std::string::npos);
}

// Which given starts the records judged (GlobalSearchResult::judged_starts), on the torsional
// oscillator's 2 s release: a Route-1 rival listed there is settled by the F-test on the minima
// instead of being reported undetermined for its initial state (MarkAlgebraicAmbiguity).
TEST(GlobalSearchTest, ListsTheGivenStartsTheRecordsJudged) {
  const std::unique_ptr<model::MechanicalModel> truth = testing::MakeOscillator();
  const TestDesign design = testing::OscillatorRelease("release", 0.01, 1e-5);
  const Measurement record =
      simulation::Simulate(*truth, design.excitation, design.simulation, design.sensors).measured;
  const TestRecord test{"release", record, design.excitation, design.sensors.noise_std};
  UpdateOptions options;
  options.quiet = true;
  options.integrator = design.simulation.integrator;
  for (const char* name : {"c_angle", "d_angle"}) {
    ParameterSetting setting;
    setting.name = name;
    setting.initial = truth->GetParameter(name);
    options.parameters.push_back(setting);
  }
  GlobalSearchOptions search;
  search.threads = 1;
  search.complete_starts = true;  // as after Route 1 solved: no design where the starts fit
  search.pole_equivalent_starts = false;
  const std::vector<SearchStart> starts = {
      // 1e-5 off: its cost within the noise's (a 2% error already starts 3 times higher, the
      // record holds 1000 times the noise), fitted on the whole record.
      {"route1 set 1", {{"c_angle", 800.008}, {"d_angle", 8.00008}}, true},
      // Twice the frequency: its cost starts far above 3 times the best, never fitted.
      {"route1 set 2", {{"c_angle", 3200.0}, {"d_angle", 8.0}}, true},
  };
  const GlobalSearchResult result =
      SearchGlobally(*truth, {test}, options, "route1", starts, search);
  ASSERT_EQ(result.best.termination, UpdateResult::Termination::kConverged);
  EXPECT_EQ(result.full_fits, 2);  // the primary and set 1; set 2 only costed
  // Costed starts first, then the fitted ones.
  EXPECT_EQ(result.judged_starts, (std::vector<std::string>{"route1 set 2", "route1 set 1"}));
  ASSERT_EQ(result.minima.size(), 1u);  // set 1 ended at the primary's minimum
  EXPECT_FALSE(result.non_unique);
}

// A caller that places something after the search (detected releases: release_profile.h) may
// know better than the fit itself whether the best given start explains the records
// (GlobalSearchOptions::explains_records). The oscillator's release with a 3 Hz hum the model
// cannot explain: asked only with complete starts and no fit explaining the records itself, of
// the least-cost fit with the search's own records and options; its yes skips the design, its
// no keeps it.
TEST(GlobalSearchTest, TheCallerJudgesTheBestGivenStartWhenItsFitDoesNot) {
  const std::unique_ptr<model::MechanicalModel> truth = testing::MakeOscillator();
  const TestDesign design = testing::OscillatorRelease("release", 0.01, 1e-5);
  Measurement record =
      simulation::Simulate(*truth, design.excitation, design.simulation, design.sensors).measured;
  for (Eigen::Index i = 0; i < record.values.rows(); ++i) {
    // 20 times the noise: a residual no fit of the oscillator explains.
    record.values(i, 0) +=
        2e-4 * std::sin(2 * M_PI * 3.0 * (record.start_time_s + i * record.sample_interval_s));
  }
  const TestRecord test{"release", record, design.excitation, design.sensors.noise_std};
  UpdateOptions options;
  options.quiet = true;
  options.integrator = design.simulation.integrator;
  for (const char* name : {"c_angle", "d_angle"}) {
    options.parameters.push_back({name, truth->GetParameter(name)});
  }
  GlobalSearchOptions search;
  search.design_starts = 2;
  search.pole_equivalent_starts = false;
  search.complete_starts = true;
  int asked = 0;
  bool answer = true;
  search.explains_records = [&](const std::vector<TestRecord>& tests, const UpdateOptions& given,
                                const UpdateResult& fit) {
    ++asked;
    EXPECT_EQ(tests.size(), 1u);
    EXPECT_EQ(given.parameters.size(), 2u);
    EXPECT_FALSE(fit.explains_records);  // else the caller is not asked
    return answer;
  };
  const GlobalSearchResult settled = SearchGlobally(*truth, {test}, options, "route1", {}, search);
  ASSERT_EQ(settled.best.termination, UpdateResult::Termination::kConverged);
  EXPECT_FALSE(settled.best.explains_records);
  EXPECT_EQ(asked, 1);
  EXPECT_EQ(settled.screened, 0);
  answer = false;
  EXPECT_EQ(SearchGlobally(*truth, {test}, options, "route1", {}, search).screened, 2);
  EXPECT_EQ(asked, 2);
  search.complete_starts = false;  // the design runs anyway: nothing to ask
  EXPECT_EQ(SearchGlobally(*truth, {test}, options, "route1", {}, search).screened, 2);
  EXPECT_EQ(asked, 2);
}

}  // namespace
}  // namespace mbid::updating
