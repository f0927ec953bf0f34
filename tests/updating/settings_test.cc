// The `updating:` scenario section (read strictly) and the glue between Route 1 and Route 2.
#include "mbid/updating/settings.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "crane_fixture.h"
#include "mbid/common/error.h"

namespace mbid::updating {
namespace {

using testing::Crane;
using testing::LoadCrane;

UpdatingSettings Read(const std::string& yaml, const model::MechanicalModel& model) {
  const YamlReader root = YamlReader::FromString(yaml, "scenario.yaml");
  return ReadUpdatingSettings(root.Child("updating"), model, simulation::IntegratorOptions());
}

// The error text of reading `yaml`, or "" if it reads.
std::string ErrorOf(const std::string& yaml, const model::MechanicalModel& model) {
  try {
    Read(yaml, model);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(SettingsTest, DefaultsTuneEveryParameterFromTheModel) {
  const Crane crane = LoadCrane(testing::kReferenceScenario);
  const UpdatingSettings settings =
      MakeDefaultUpdatingSettings(*crane.model, crane.simulation.integrator);
  ASSERT_EQ(settings.options.parameters.size(), 8u);
  for (const ParameterSetting& setting : settings.options.parameters) {
    EXPECT_TRUE(std::isnan(setting.initial)) << setting.name;  // the model's (or Route 1's)
    EXPECT_TRUE(setting.log_scale);
  }
  EXPECT_TRUE(settings.options.integrator.interpolate_outputs);
  EXPECT_EQ(settings.options.jacobian, UpdateOptions::Jacobian::kSensitivities);
  EXPECT_TRUE(settings.options.speculative_jacobians);
  EXPECT_TRUE(settings.algebraic_start);
  EXPECT_TRUE(settings.noise_std.empty());
  // An empty section is the defaults: cautious first steps from starts of unknown quality,
  // Ceres-like ones from the sets that have the identified poles.
  EXPECT_EQ(Read("updating:\n", *crane.model).options.parameters.size(), 8u);
  EXPECT_EQ(settings.options.initial_trust_region_radius, 10);
  EXPECT_EQ(settings.global_search.matched_trust_region_radius, 1000);
}

TEST(SettingsTest, ReadsEveryKey) {
  const Crane crane = LoadCrane(testing::kReferenceScenario);
  const UpdatingSettings settings = Read(R"(
updating:
  parameters: [c_theta, d_theta, c_eta]
  start: {c_theta: 8.0e6}
  bounds: {c_theta: [1.0e6, 1.0e8]}
  algebraic_start: false
  jacobian: numeric
  numeric_step: 1.0e-3
  noise_std_rad: {psi: 1.0e-5, phi: 2.0e-5}
  fit_payload_mass: true
  max_iterations: 20
  parameter_tolerance: 1.0e-9
  undetermined_relative_std: 0.5
  threads: 2
  initial_trust_region_radius: 100
  speculative_jacobians: false
  continuation_fractions: [0.25, 0.5]
  integrator: {method: adams, relative_tolerance: 1.0e-7}
  sensitivity: {right_hand_side: quotients, corrector: staggered, difference_quotient: centered,
                error_control: false}
  algebraic: {starts: 20, seed: 3, fit_offset: true, ambiguity_ratio: 3, shape_significance: 0.01}
  profile: {enabled: true, sigmas: 1.5, max_fits_per_side: 4, max_iterations: 9, tolerance: 0.1}
  global_search: {threads: 3, screen_relative_tolerance: 1.0e-6}
)",
                                         *crane.model);
  const UpdateOptions& o = settings.options;
  ASSERT_EQ(o.parameters.size(), 3u);
  EXPECT_EQ(o.parameters[0].name, "c_theta");
  EXPECT_EQ(o.parameters[0].initial, 8.0e6);
  EXPECT_EQ(o.parameters[0].lower, 1.0e6);
  EXPECT_EQ(o.parameters[0].upper, 1.0e8);
  EXPECT_TRUE(std::isnan(o.parameters[1].initial));
  EXPECT_FALSE(settings.algebraic_start);
  EXPECT_EQ(o.jacobian, UpdateOptions::Jacobian::kNumeric);
  EXPECT_EQ(o.numeric_step, 1e-3);
  EXPECT_EQ(settings.noise_std.at("phi"), 2e-5);
  EXPECT_TRUE(settings.fit_payload_mass);
  EXPECT_EQ(o.max_iterations, 20);
  EXPECT_EQ(o.parameter_tolerance, 1e-9);
  EXPECT_EQ(o.undetermined_relative_std, 0.5);
  EXPECT_EQ(o.threads, 2);
  EXPECT_EQ(o.initial_trust_region_radius, 100);
  EXPECT_FALSE(o.speculative_jacobians);  // the default is true
  // A radius the file gives holds for Route 1's starts too.
  EXPECT_EQ(settings.global_search.matched_trust_region_radius, 100);
  EXPECT_EQ(o.continuation_fractions, (std::vector<double>{0.25, 0.5}));
  EXPECT_EQ(o.integrator.method, simulation::IntegratorOptions::Method::kAdams);
  EXPECT_EQ(o.integrator.relative_tolerance, 1e-7);
  EXPECT_TRUE(o.integrator.interpolate_outputs);  // kept from the default
  EXPECT_EQ(o.sensitivity.corrector, simulation::SensitivityOptions::Corrector::kStaggered);
  EXPECT_EQ(o.sensitivity.difference_quotient,
            simulation::SensitivityOptions::DifferenceQuotient::kCentered);
  EXPECT_FALSE(o.sensitivity.error_control);
  EXPECT_EQ(o.sensitivity.right_hand_side,
            simulation::SensitivityOptions::RightHandSide::kCvodesQuotients);
  // Not given: the fit's default, the state Jacobian from as many sensitivities as states.
  EXPECT_EQ(Read("updating: {}", *crane.model).options.sensitivity.right_hand_side,
            simulation::SensitivityOptions::RightHandSide::kAuto);
  EXPECT_EQ(Read("updating: {sensitivity: {right_hand_side: state_jacobian}}", *crane.model)
                .options.sensitivity.right_hand_side,
            simulation::SensitivityOptions::RightHandSide::kStateJacobian);
  EXPECT_EQ(settings.algebraic.starts, 20);
  EXPECT_EQ(settings.algebraic.seed, 3u);
  EXPECT_TRUE(settings.algebraic.fit_offset);
  EXPECT_EQ(settings.algebraic.ambiguity_ratio, 3);
  EXPECT_EQ(settings.algebraic.shape_significance, 0.01);
  EXPECT_EQ(Read("updating: {}", *crane.model).algebraic.shape_significance, 1e-3);
  EXPECT_TRUE(settings.profile.enabled);
  EXPECT_EQ(settings.profile.sigmas, 1.5);
  EXPECT_EQ(settings.profile.max_fits_per_side, 4);
  EXPECT_EQ(settings.profile.max_iterations, 9);
  EXPECT_EQ(settings.profile.tolerance, 0.1);
  EXPECT_EQ(settings.profile.threads, 3);  // the global search's workers
  EXPECT_EQ(settings.global_search.screen_relative_tolerance, 1e-6);
  EXPECT_FALSE(Read("updating: {}", *crane.model).profile.enabled);  // off by default (cost)
  // A scalar noise level applies to every channel.
  EXPECT_EQ(Read("updating: {noise_std_rad: 3.0e-5}", *crane.model).noise_std.at("psi"), 3e-5);
}

TEST(SettingsTest, ResidualNoiseIsGivenInEachChannelsUnit) {
  // scenarios/excavator-arm.yaml: inclinometers in rad, accelerometers in m/s^2.
  const Crane machine = LoadCrane(std::string(MBID_SOURCE_DIR) + "/scenarios/excavator-arm.yaml");
  const UpdatingSettings settings = Read(
      "updating: {noise_std_rad: 1.0e-5, noise_std_mps2: {a_bucket_z: 2.0e-3}}", *machine.model);
  EXPECT_EQ(settings.noise_std.at("boom_incl"), 1e-5);
  EXPECT_EQ(settings.noise_std.at("swing"), 1e-5);  // a coordinate channel, in rad
  EXPECT_EQ(settings.noise_std.at("a_bucket_z"), 2e-3);
  EXPECT_EQ(settings.noise_std.count("a_bucket_y"), 0u);  // the identification's estimate
  EXPECT_NE(ErrorOf("updating: {noise_std_rad: {a_bucket_z: 1.0e-5}}", *machine.model)
                .find("is in m/s^2, not rad"),
            std::string::npos);
}

TEST(SettingsTest, ErrorsNameTheFieldAndWhatWasExpected) {
  const Crane crane = LoadCrane(testing::kReferenceScenario);
  const model::MechanicalModel& m = *crane.model;
  EXPECT_NE(ErrorOf("updating: {paramters: [c_theta]}", m).find("did you mean 'parameters'"),
            std::string::npos);
  EXPECT_NE(ErrorOf("updating: {parameters: [c_thta]}", m).find("did you mean 'c_theta'"),
            std::string::npos);
  EXPECT_NE(ErrorOf("updating: {parameters: [c_theta, c_theta]}", m).find("twice"),
            std::string::npos);
  EXPECT_NE(ErrorOf("updating: {parameters: [c_theta], start: {c_eta: 1.0e6}}", m)
                .find("not among the tuned parameters"),
            std::string::npos);
  EXPECT_NE(ErrorOf("updating: {start: {c_theta: 1.0e6}, bounds: {c_theta: [2.0e6, 3.0e6]}}", m)
                .find("does not contain the start"),
            std::string::npos);
  EXPECT_NE(ErrorOf("updating: {bounds: {c_theta: [3.0e6, 2.0e6]}}", m).find("lower < upper"),
            std::string::npos);
  EXPECT_NE(ErrorOf("updating: {jacobian: automatic}", m).find("sensitivities"), std::string::npos);
  EXPECT_NE(ErrorOf("updating: {noise_std: 1.0e-5}", m).find("noise_std_rad"), std::string::npos);
  EXPECT_NE(ErrorOf("updating: {continuation_fractions: [0.5, 0.25]}", m).find("ascending"),
            std::string::npos);
  EXPECT_NE(ErrorOf("updating: {sensitivity: {corrector: simultanous}}", m).find("simultaneous"),
            std::string::npos);
  EXPECT_NE(ErrorOf("updating: {sensitivity: {right_hand_side: jacobian}}", m)
                .find("auto, quotients, state_jacobian"),
            std::string::npos)
      << ErrorOf("updating: {sensitivity: {right_hand_side: jacobian}}", m);
  EXPECT_NE(ErrorOf("updating: {threads: 0}", m).find("threads"), std::string::npos);
  EXPECT_NE(ErrorOf("updating: {profile: {sigma: 2}}", m).find("did you mean 'sigmas'"),
            std::string::npos);
  EXPECT_NE(ErrorOf("updating: {profile: {tolerance: 2}}", m).find("tolerance"), std::string::npos);
  EXPECT_NE(ErrorOf("updating: {global_search: {screen_relative_tolerance: 2}}", m)
                .find("screen_relative_tolerance in (0, 1)"),
            std::string::npos);
  // Errors name the file and the field.
  EXPECT_NE(
      ErrorOf("updating: {algebraic: {starts: 0}}", m).find("scenario.yaml:updating.algebraic"),
      std::string::npos);
  EXPECT_NE(ErrorOf("updating: {algebraic: {shape_significance: 1}}", m)
                .find("shape_significance: 1; expected in (0, 1)"),
            std::string::npos);
}

TEST(SettingsTest, AlgebraicStartFillsOnlyTheStartsNotGiven) {
  const Crane crane = LoadCrane(testing::kReferenceScenario);
  CharacteristicResult algebraic;
  algebraic.status = CharacteristicResult::Status::kSolved;
  algebraic.coordinates = crane.model->coordinate_names();
  CharacteristicSolution set;
  set.c = Eigen::Vector4d(4e7, 1e6, 5e6, 9e6);
  set.d = Eigen::Vector4d(5e5, 1.5e5, 4e4, 1e5);
  set.admissible = true;
  algebraic.solutions = {set};
  algebraic.chosen = 0;
  UpdatingSettings settings = Read("updating: {start: {c_theta: 8.0e6}}", *crane.model);
  std::string why;
  ASSERT_TRUE(ApplyAlgebraicStart(algebraic, settings.options, &why)) << why;
  for (const ParameterSetting& s : settings.options.parameters) {
    if (s.name == "c_theta") {
      EXPECT_EQ(s.initial, 8e6);  // explicit start wins
    } else if (s.name == "c_alpha") {
      EXPECT_EQ(s.initial, 4e7);
    } else if (s.name == "d_eta") {
      EXPECT_EQ(s.initial, 4e4);
    }
  }
  // The default bounds hold the model's value too (Route 1's c_tilt of 2.8e5 from poles that
  // missed a stiff pin's mode gave bounds [2.8e3, 2.8e7] without the scenario's 1.4e9 and the
  // truth 1e9): here c_alpha 4e7 from Route 1, 4.9e7 the model's.
  algebraic.c_reference = Eigen::Vector4d(4.9e7, 1.1e6, 5.5e6, 9.4e6);
  algebraic.d_reference = Eigen::Vector4d(5.2e5, 1.78e5, 4.4e4, 1.16e5);
  UpdatingSettings wide = Read("updating: {bounds: {c_eta: [1.0e6, 1.0e7]}}", *crane.model);
  ASSERT_TRUE(ApplyAlgebraicStart(algebraic, wide.options, &why)) << why;
  for (const ParameterSetting& s : wide.options.parameters) {
    if (s.name == "c_alpha") {
      EXPECT_DOUBLE_EQ(s.lower, 4e7 / 100);
      EXPECT_DOUBLE_EQ(s.upper, 4.9e7 * 100);
    } else if (s.name == "d_gamma") {
      EXPECT_DOUBLE_EQ(s.lower, 1.5e5 / 100);
      EXPECT_DOUBLE_EQ(s.upper, 1.78e5 * 100);
    } else if (s.name == "c_eta") {
      EXPECT_EQ(s.lower, 1e6);  // explicit bounds stay
      EXPECT_EQ(s.upper, 1e7);
    }
  }
  // A set outside explicit bounds is not used, and nothing changes.
  UpdatingSettings bounded = Read("updating: {bounds: {c_alpha: [5.0e7, 6.0e7]}}", *crane.model);
  EXPECT_FALSE(ApplyAlgebraicStart(algebraic, bounded.options, &why));
  EXPECT_NE(why.find("c_alpha"), std::string::npos);
  EXPECT_TRUE(std::isnan(bounded.options.parameters[1].initial));
  // No admissible set: no start.
  algebraic.status = CharacteristicResult::Status::kNoAdmissibleSet;
  EXPECT_FALSE(ApplyAlgebraicStart(algebraic, settings.options, &why));
}

TEST(SettingsTest, AlgebraicAmbiguityMarksTheParametersTheRivalsDisagreeOn) {
  CharacteristicResult algebraic;
  algebraic.status = CharacteristicResult::Status::kSolved;
  algebraic.coordinates = {"alpha", "gamma"};
  CharacteristicSolution chosen, rival;
  chosen.c = Eigen::Vector2d(4e7, 1e6);
  chosen.d = Eigen::Vector2d(5e5, 1e5);
  rival.c = Eigen::Vector2d(4.1e7, 4e6);  // c_alpha within 10%, c_gamma not
  rival.d = Eigen::Vector2d(5e5, 2e4);
  algebraic.solutions = {chosen, rival};
  algebraic.chosen = 0;
  algebraic.ambiguous = true;
  algebraic.rivals = {1};
  UpdateResult result;
  for (const char* name : {"c_alpha", "c_gamma", "d_alpha", "d_gamma"}) {
    ParameterEstimate estimate;
    estimate.name = name;
    result.parameters.push_back(estimate);
  }
  const std::vector<std::string> marked = MarkAlgebraicAmbiguity(algebraic, result);
  EXPECT_EQ(marked, (std::vector<std::string>{"c_gamma", "d_gamma"}));
  EXPECT_FALSE(result.Find("c_gamma").determined);
  EXPECT_THAT(result.Find("c_gamma").why_undetermined, ::testing::HasSubstr("Route 1"));
  EXPECT_TRUE(result.Find("c_alpha").determined);
  EXPECT_TRUE(result.Find("c_alpha").why_undetermined.empty());
  EXPECT_EQ(result.undetermined, marked);
  ASSERT_EQ(result.warnings.size(), 1u);

  // A rival the global search fitted on the whole records (or found far above the best cost)
  // is judged by the F-test on the minima, not by its initial-state mismatch: nothing marked.
  UpdateResult judged;
  judged.parameters = result.parameters;
  for (ParameterEstimate& estimate : judged.parameters) {
    estimate.determined = true;
    estimate.why_undetermined.clear();
  }
  EXPECT_EQ(AlgebraicStartLabel(1), "route1 set 1");
  EXPECT_TRUE(MarkAlgebraicAmbiguity(algebraic, judged, 0.1, {"route1 set 1"}).empty());
  EXPECT_TRUE(judged.Find("c_gamma").determined);
  EXPECT_TRUE(judged.undetermined.empty());
  EXPECT_TRUE(judged.warnings.empty());
  // Another start judged does not settle this rival.
  EXPECT_EQ(MarkAlgebraicAmbiguity(algebraic, judged, 0.1, {"route1 set 2", "design 1"}), marked);
}

TEST(SettingsTest, TestRecordTakesNoiseAndNuisanceSwitches) {
  const Crane crane = LoadCrane(testing::kLoadDropScenario);
  const UpdatingSettings settings = Read(
      "updating: {noise_std_rad: 1.0e-5, fit_payload_mass: true, fit_initial_deflection: true}",
      *crane.model);
  const Measurement record = testing::SimulateExact(crane, 0.2, 50.0);
  const TestRecord test = MakeTestRecord("drop", record, crane.excitation, settings);
  EXPECT_EQ(test.noise_std.size(), 2u);  // the record's channels only
  EXPECT_TRUE(test.fit_payload_mass);
  EXPECT_FALSE(test.fit_initial_deflection);  // a load drop has no deflections to fit
}

TEST(SettingsTest, OffsetsAreFittedForImportedRecordsByDefault) {
  const Crane crane = LoadCrane(testing::kReferenceScenario);
  Measurement simulated = testing::SimulateExact(crane, 0.2, 50.0);
  ASSERT_EQ(simulated.source, "simulation");
  Measurement imported = simulated;
  imported.source = "import";
  // auto: imported records get offsets, mbid's own simulations not (existing results stay).
  const UpdatingSettings defaults = Read("updating: {}", *crane.model);
  EXPECT_EQ(defaults.fit_offsets, UpdatingSettings::Offsets::kAuto);
  EXPECT_FALSE(defaults.fit_drift);
  EXPECT_TRUE(MakeTestRecord("a", imported, crane.excitation, defaults).fit_offsets);
  EXPECT_FALSE(MakeTestRecord("a", imported, crane.excitation, defaults).fit_drift);
  EXPECT_FALSE(MakeTestRecord("a", simulated, crane.excitation, defaults).fit_offsets);
  Measurement synthetic = simulated;  // mbid's synthetic_modes records: no zero error either
  synthetic.source = "synthetic";
  EXPECT_FALSE(MakeTestRecord("a", synthetic, crane.excitation, defaults).fit_offsets);
  // The drift comes with the offsets, wherever they are fitted.
  const UpdatingSettings drift = Read("updating: {fit_drift: true}", *crane.model);
  EXPECT_TRUE(MakeTestRecord("a", imported, crane.excitation, drift).fit_drift);
  EXPECT_FALSE(MakeTestRecord("a", simulated, crane.excitation, drift).fit_drift);
  const UpdatingSettings always = Read("updating: {fit_offsets: true}", *crane.model);
  EXPECT_TRUE(MakeTestRecord("a", simulated, crane.excitation, always).fit_offsets);
  const UpdatingSettings never = Read("updating: {fit_offsets: false}", *crane.model);
  EXPECT_FALSE(MakeTestRecord("a", imported, crane.excitation, never).fit_offsets);
  EXPECT_NE(ErrorOf("updating: {fit_offsets: always}", *crane.model).find("one of auto"),
            std::string::npos);
  EXPECT_NE(
      ErrorOf("updating: {fit_offsets: false, fit_drift: true}", *crane.model).find("fit_drift"),
      std::string::npos);
}

}  // namespace
}  // namespace mbid::updating
