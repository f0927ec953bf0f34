// <mbid/mbid.h> as a library user calls it: closed-form records, the verdict, errors, and the
// folder rules of `mbid run -o` when the cycle is asked to write its results.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "mbid/mbid.h"

namespace {

namespace fs = std::filesystem;

const std::string kReference = std::string(MBID_SOURCE_DIR) + "/scenarios/reference-crane.yaml";

// y = exp(-0.3 t) cos(2 pi 2 t) + 0.5 exp(-0.8 t) sin(2 pi 5.5 t), 2000 samples at 5 ms.
mbid::Measurement TwoModes() {
  mbid::Measurement m;
  m.channels = {"x"};
  m.units = {"m"};
  m.sample_interval_s = 0.005;
  m.values.resize(2000, 1);
  for (int j = 0; j < 2000; ++j) {
    const double t = j * m.sample_interval_s;
    m.values(j, 0) = std::exp(-0.3 * t) * std::cos(2 * M_PI * 2.0 * t) +
                     0.5 * std::exp(-0.8 * t) * std::sin(2 * M_PI * 5.5 * t);
  }
  return m;
}

// scenarios/reference-crane.yaml as text, its 8 s test shortened to `duration_s`, `extra` appended
// (another section).
std::string ReferenceText(int duration_s, const std::string& extra = "") {
  std::ifstream in(kReference);
  std::stringstream text;
  text << in.rdbuf();
  std::string yaml = text.str();
  yaml.replace(yaml.find("duration_s: 8"), 13, "duration_s: " + std::to_string(duration_s));
  return yaml + extra;
}

TEST(FacadeTest, IdentifyRecoversClosedFormModes) {
  const mbid::ModalResult result = mbid::Identify(TwoModes());
  ASSERT_EQ(result.modes.size(), 2u);
  // Noise-free: the poles come back to 1e-6 relative.
  EXPECT_NEAR(result.modes[0].frequency_hz, 2.0, 2e-6);
  EXPECT_NEAR(result.modes[0].decay_rate_per_s, 0.3, 3e-7);
  EXPECT_NEAR(result.modes[1].frequency_hz, 5.5, 5.5e-6);
  EXPECT_NEAR(result.modes[1].decay_rate_per_s, 0.8, 8e-7);
  // damping ratio = decay / |lambda| by definition.
  EXPECT_NEAR(result.modes[0].damping_ratio, 0.3 / std::hypot(0.3, 2 * M_PI * 2.0), 1e-7);
}

// A hammer record (a two-storey shear frame hit at the roof for 10 ms): IdentifyTest analyses it
// after the pulse, as the cycle does; Identify alone cannot know the pulse and starts at the
// record's start, where a fast-decaying extra "mode" absorbs it (4 modes, unreliable).
TEST(FacadeTest, IdentifyTestStartsAfterTheForcing) {
  const mbid::Scenario frame = mbid::LoadScenarioFromText(R"(name: frame
model:
  type: multibody
  bodies:
    f1: {parent: ground, joint: {type: prismatic, coordinates: [x1], axis: [1, 0, 0]}, mass_kg: 1000.0, inertia_kgm2: [100, 100, 100]}
    f2: {parent: f1, joint: {type: prismatic, coordinates: [x2], axis: [1, 0, 0]}, mass_kg: 1000.0, inertia_kgm2: [100, 100, 100]}
  springs:
    x1: {stiffness_N_per_m: 1.0e6, damping_Ns_per_m: 200.0}
    x2: {stiffness_N_per_m: 1.0e6, damping_Ns_per_m: 200.0}
  points: {roof: {body: f2, at_m: [0, 0, 0]}}
  outputs: {a_roof: {type: acceleration, point: roof, direction: [1, 0, 0]}}
excitation: {type: impulse, point: roof, force_N: [20000, 0, 0], duration_s: 0.01}
simulation: {duration_s: 5}
sensors: {sample_rate_hz: 200, channels: [a_roof], noise_std_mps2: 1.0e-3, seed: 3}
)",
                                                          "frame.yaml");
  const mbid::Measurement record = mbid::Simulate(frame);
  const mbid::ModalResult after = mbid::IdentifyTest(record, frame);
  EXPECT_TRUE(after.reliable);
  ASSERT_EQ(after.modes.size(), 2u);
  // The closed form: w^2 = (k/m) (3 -+ sqrt(5)) / 2 with k/m = 1000 1/s^2: 3.1105 and 8.1434 Hz
  // undamped; the dampers lower them by under 1e-5. 1e-4: the record is the simulation's.
  for (const auto& [k, sign] : {std::pair<size_t, double>{0, -1.0}, {1, 1.0}}) {
    const double f = std::sqrt(1000.0 * (3 + sign * std::sqrt(5.0)) / 2) / (2 * M_PI);
    EXPECT_NEAR(after.modes[k].frequency_hz, f, 1e-4 * f) << k;
  }
  // The pulse counted as free decay: not the machine's modes, and flagged.
  const mbid::ModalResult from_start = mbid::Identify(record);
  EXPECT_FALSE(from_start.reliable);
}

// A trial's machine (a sprung carriage, a cab pitching on it at 40 % damping) hit at the roof,
// its hammer blow 10 % smaller in the model's test than in the record's: the fit made up for it
// with the dampers (d_pitch 8 standard deviations off), chi^2/dof 1.76 and white was taken for a
// noise level stated too low, every parameter determined, and `mbid run` said "passed". The
// misfit sits in the samples under the pulse (33 times the noise in one): now nothing is
// determined. With the blow right, every parameter is.
TEST(FacadeTest, AHammerBlowOfTheWrongSizeDeterminesNothing) {
  const mbid::Scenario cab = mbid::LoadScenarioFromText(R"(name: cab
model:
  type: multibody
  bodies:
    carriage: {parent: ground, joint: {type: prismatic, coordinates: [bounce], axis: [0, 0, 1], in_parent_m: [0, 0, 0.6]}, mass_kg: 800.0, com_m: [0, 0, 0.1], inertia_kgm2: [200, 300, 400]}
    cab: {parent: carriage, joint: {type: revolute, coordinates: [pitch], axis: [0, 1, 0], in_parent_m: [0, 0, 0.4]}, mass_kg: 400.0, com_m: [0.5, 0, 0.8], inertia_kgm2: [80, 100, 90]}
  springs:
    bounce: {stiffness_N_per_m: 1.0e6, damping_Ns_per_m: 2000.0}
    pitch: {stiffness_Nm_per_rad: 2.0e5, damping_Nms_per_rad: 8000.0}
  points: {roof: {body: cab, at_m: [0.5, 0, 1.5]}}
  outputs:
    a_roof_x: {type: acceleration, point: roof, direction: [1, 0, 0]}
    a_roof_z: {type: acceleration, point: roof, direction: [0, 0, 1]}
excitation: {type: impulse, point: roof, force_N: [3300, 0, -3300], duration_s: 0.01}
simulation: {duration_s: 5}
sensors: {sample_rate_hz: 200, channels: [a_roof_x, a_roof_z], noise_std_mps2: 0.05, seed: 1}
updating: {global_search: {enabled: false}}
)",
                                                        "cab.yaml");
  const mbid::Measurement record = mbid::Simulate(cab);
  const mbid::UpdateResult right = mbid::Update(cab, {record});
  EXPECT_TRUE(right.credible) << ::testing::PrintToString(right.credibility);
  EXPECT_TRUE(right.undetermined.empty()) << ::testing::PrintToString(right.undetermined);
  mbid::simulation::Excitation weaker = cab.excitation;
  weaker.get<mbid::simulation::Impulse>().target.force_N /= 1.1;
  const mbid::UpdateResult wrong = mbid::Update(cab, {record}, {weaker});
  EXPECT_FALSE(wrong.credible);
  EXPECT_EQ(wrong.undetermined.size(), 4u) << ::testing::PrintToString(wrong.undetermined);
  ASSERT_FALSE(wrong.credibility.empty());
  EXPECT_NE(wrong.credibility.front().find("times its spread elsewhere"), std::string::npos)
      << wrong.credibility.front();
}

// A fit that ends at a parameter's bound may be a local minimum the bound made (a trial's arm on
// a sprung base: c_bounce at its upper bound, c_shoulder "determined" 9 standard deviations
// off). Here a torsional oscillator's fit (3e-3 rad noise against a 0.01 rad release) is held
// where it starts (one iteration, no step), d_angle at its upper bound, 10 against the truth 8:
// chi^2/dof 1.04, white, and c_angle was "determined". The bound's profile holds d inside,
// re-fits c, and fits better (at d = 7.4), so c is no longer determined by a fit that is no
// minimum of the record.
TEST(FacadeTest, AFitEndingAtABoundThatIsNoMinimumDeterminesNothing) {
  const std::string oscillator = R"(name: osc
model:
  type: torsional_oscillator
  inertia_kgm2: 2.0
  joints: {angle: {stiffness_Nm_per_rad: 800.0, damping_Nms_per_rad: 8.0}}
excitation: {type: initial_deflection, deflection_rad: {angle: 0.01}}
simulation: {duration_s: 2}
sensors: {sample_rate_hz: 100, channels: [angle], noise_std_rad: 3.0e-3, seed: 1}
)";
  const mbid::Measurement record =
      mbid::Simulate(mbid::LoadScenarioFromText(oscillator, "osc.yaml"));
  const mbid::Scenario held = mbid::LoadScenarioFromText(oscillator + R"(updating:
  algebraic_start: false
  start: {c_angle: 800.0, d_angle: 10.0}
  bounds: {d_angle: [0.1, 10.0]}
  max_iterations: 1
  initial_trust_region_radius: 1.0e-12
  function_tolerance: 0.99
  global_search: {enabled: false}
)",
                                                         "held.yaml");
  const mbid::UpdateResult result = mbid::Update(held, {record});
  ASSERT_TRUE(result.converged);
  EXPECT_DOUBLE_EQ(result.parameters.at("d_angle").value, 10.0);
  const mbid::ParameterValue& c = result.parameters.at("c_angle");
  EXPECT_FALSE(c.determined);
  EXPECT_NE(c.why_undetermined.find("the fit ended at a bound in a local minimum"),
            std::string::npos)
      << c.why_undetermined;
}

// A trial's turntable (0.31 Hz) carrying a stiff slider (19.86 Hz): the slider's accelerometers
// see its mode modulated by the turn, f3 -+ f1 at 19.56 and 20.23 Hz, which the identification
// names as combination tones. They sit 1.5-1.8 % from the mode and were counted as modes "the
// record cannot separate": the run was inconclusive though every joint came out determined.
TEST(FacadeTest, CombinationTonesBesideAModeAreNotCloseModes) {
  const mbid::Scenario table = mbid::LoadScenarioFromText(R"(name: stiffsoft
model:
  type: multibody
  bodies:
    table: {parent: ground, joint: {type: revolute, coordinates: [turn], axis: [0, 0, 1], in_parent_m: [0, 0, 1]}, mass_kg: 3000.0, inertia_kgm2: [3000, 3000, 5000]}
    slider: {parent: table, joint: {type: prismatic, coordinates: [slide], axis: [1, 1, 0], in_parent_m: [2, 0, 0.3]}, mass_kg: 100.0, inertia_kgm2: [5, 5, 5]}
  springs:
    turn: {stiffness_Nm_per_rad: 2.0e4, damping_Nms_per_rad: 600.0}
    slide: {stiffness_N_per_m: 1.5e6, damping_Ns_per_m: 400.0}
  points: {s: {body: slider, at_m: [0, 0, 0]}, rim: {body: table, at_m: [1.5, 0, 0]}}
  outputs:
    a_rim: {type: acceleration, point: rim, direction: [0, 1, 0]}
    a_s_x: {type: acceleration, point: s, direction: [1, 0, 0]}
    a_s_y: {type: acceleration, point: s, direction: [0, 1, 0]}
excitation: {type: initial_deflection, deflection_rad: {turn: 0.01}, deflection_m: {slide: 0.0005}}
simulation: {duration_s: 20}
sensors: {sample_rate_hz: 100, channels: [a_rim, a_s_x, a_s_y], noise_std_mps2: 0.002, seed: 1}
)",
                                                          "stiffsoft.yaml");
  const mbid::ModalResult modes = mbid::Identify(mbid::Simulate(table));
  int tones = 0;
  for (const auto& mode : modes.modes) tones += !mode.combination.empty();
  EXPECT_GE(tones, 2);
  EXPECT_TRUE(modes.reliable) << ::testing::PrintToString(modes.reasons);
}

// An arm on a tilted revolute joint, released from 0.01 rad, with an angle, a displacement and
// an acceleration at its tip: the outputs' geometry makes harmonics no linear mode has, so the
// identification's modes leave 55 and 4.4 times the record's noise in two channels (unreliable,
// rightly); the exact model, tuned, leaves the sensors' noise in every channel. An audit's
// machines with such sensors were all inconclusive, the model right to 1e-6. A model whose
// damping is 10 % off (not tuned) does not pass. One local fit each (test time).
TEST(FacadeTest, AModelThatExplainsWhatItsModesDoNotPasses) {
  const std::string arm = R"(name: arm
model:
  type: multibody
  bodies:
    arm:
      parent: ground
      joint: {type: revolute, coordinates: [q1], axis: [1, 2, 2], in_parent_m: [0.5, -0.2, 2.0], in_parent_rotation_deg: [{z: 30}], in_body_m: [0.1, 0, 0]}
      mass_kg: 250.0
      com_m: [0.5, 0.2, -0.3]
      inertia_kgm2: [20.0, 30.0, 25.0, 2.0, -1.5, 3.0]
  springs:
    q1: {stiffness_Nm_per_rad: 4.0e5, damping_Nms_per_rad: DAMPING}
  points: {tip: {body: arm, at_m: [1.1, 0.3, -0.5]}}
  outputs:
    q1: {type: coordinate, coordinate: q1}
    dx: {type: displacement, point: tip, direction: [1, 0, 0], frame: ground}
    ag: {type: acceleration, point: tip, direction: [0, 0, 1], frame: ground}
excitation: {type: initial_deflection, deflection_rad: {q1: 0.01}}
simulation: {duration_s: 2}
sensors: {sample_rate_hz: 200, channels: [q1, dx, ag], noise_std_rad: 1.0e-6, noise_std_m: 1.0e-7, noise_std_mps2: 1.0e-5, seed: 3}
updating: {parameters: PARAMETERS, algebraic_start: false, start: START, global_search: {enabled: false}}
)";
  const auto with = [&arm](const std::string& damping, const std::string& parameters,
                           const std::string& start) {
    std::string text = arm;
    text.replace(text.find("DAMPING"), 7, damping);
    text.replace(text.find("PARAMETERS"), 10, parameters);
    text.replace(text.find("START"), 5, start);
    return text;
  };
  // Route 1 on: its joint set is the other start the verdict's uniqueness needs with the search
  // off (one local fit alone leaves other minima unasked).
  std::string exact_text = with("300.0", "[c_q1, d_q1]", "{c_q1: 2.5e5, d_q1: 600.0}");
  exact_text.replace(exact_text.find("algebraic_start: false"), 22, "algebraic_start: true");
  const mbid::Scenario exact = mbid::LoadScenarioFromText(exact_text, "arm.yaml");
  const mbid::ValidationResult right = mbid::RunValidationCycle(exact);
  EXPECT_FALSE(right.identified.reliable);
  EXPECT_EQ(right.verdict, mbid::Verdict::kPassed) << ::testing::PrintToString(right.reasons);
  // Route 1 off too: one local fit from one start, the minimum's uniqueness unasked (an audit's
  // symmetric machine passed so with its joints swapped): inconclusive, saying so.
  const mbid::ValidationResult alone = mbid::RunValidationCycle(mbid::LoadScenarioFromText(
      with("300.0", "[c_q1, d_q1]", "{c_q1: 2.5e5, d_q1: 600.0}"), "arm-alone.yaml"));
  EXPECT_EQ(alone.verdict, mbid::Verdict::kInconclusive);
  EXPECT_NE(::testing::PrintToString(alone.reasons).find("uniqueness was not checked"),
            std::string::npos)
      << ::testing::PrintToString(alone.reasons);
  // The same record, a model with d_q1 10 % high and only c_q1 tuned.
  const mbid::Measurement record = mbid::Simulate(exact);
  const mbid::Scenario off =
      mbid::LoadScenarioFromText(with("330.0", "[c_q1]", "{c_q1: 2.5e5}"), "arm-off.yaml");
  const mbid::UpdateResult wrong = mbid::Update(off, {record});
  EXPECT_FALSE(wrong.credible) << ::testing::PrintToString(wrong.credibility);
}

TEST(FacadeTest, VerdictsReadAsTheContractWritesThem) {
  EXPECT_EQ(mbid::ToString(mbid::Verdict::kPassed), "passed");
  EXPECT_EQ(mbid::ToString(mbid::Verdict::kFailed), "failed");
  EXPECT_EQ(mbid::ToString(mbid::Verdict::kInconclusive), "inconclusive");
}

TEST(FacadeTest, BadInputIsAnInputErrorWithOneLine) {
  try {
    mbid::LoadScenario("no-such-scenario.yaml");
    FAIL() << "no error";
  } catch (const mbid::InputError& error) {
    const std::string message = error.what();
    EXPECT_EQ(message.rfind("no-such-scenario.yaml:", 0), 0u) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos);
  }
  const mbid::Scenario scenario = mbid::LoadScenario(kReference);
  EXPECT_THROW(mbid::Update(scenario, {}), mbid::InputError);
  mbid::Measurement bad = TwoModes();
  bad.values(10, 0) = std::nan("");
  EXPECT_THROW(mbid::Identify(bad), mbid::InputError);
}

// The identification: and updating: sections are read and checked when the scenario loads, like
// every other section: a typo there fails every command, naming the file and the key.
TEST(FacadeTest, ATypoInTheUpdatingOrIdentificationSectionFailsAtLoad) {
  for (const auto& [section, key] :
       {std::pair<std::string, std::string>{"updating: {paramters: [c_alpha]}\n", "paramters"},
        {"identification: {methd: prony-svd}\n", "methd"}}) {
    try {
      mbid::LoadScenarioFromText(ReferenceText(8, section), "typo.yaml");
      ADD_FAILURE() << "no error for " << section;
    } catch (const mbid::InputError& error) {
      const std::string message = error.what();
      EXPECT_NE(message.find("typo.yaml"), std::string::npos) << message;
      EXPECT_NE(message.find(key), std::string::npos) << message;
    }
  }
  // Read at load, the same as reading the section again for the scenario's model.
  const mbid::Scenario scenario = mbid::LoadScenario(kReference);
  EXPECT_EQ(scenario.updating.options.parameters.size(),
            scenario.ReadUpdating(*scenario.MakeModel()).options.parameters.size());
}

// Two load drops of the reference crane, 650 and 1300 kg, each tuned with its own payload:
// the fit explains both to the noise (chi^2/dof near 1) and c_alpha stays within 4 of its
// standard deviations of the truth the records were simulated with. Told the scenario's 650 kg
// for both, the 1300 kg record cannot be explained: chi^2/dof far above 1.
TEST(FacadeTest, UpdateTunesEachRecordWithItsOwnExcitation) {
  std::ifstream file(std::string(MBID_SOURCE_DIR) + "/scenarios/reference-crane-load-drop.yaml");
  std::stringstream text;
  text << file.rdbuf() << "updating:\n  global_search: {enabled: false}\n";  // one fit: quick
  mbid::Scenario scenario = mbid::LoadScenarioFromText(text.str(), "load-drop.yaml");
  scenario.simulation.duration_s = 4.0;  // 12+ periods of the slowest mode
  const double truth = scenario.MakeModel()->GetParameter("c_alpha");
  mbid::Scenario heavier = scenario;
  heavier.excitation.get<mbid::simulation::LoadDrop>().payload_mass_kg = 1300.0;
  heavier.sensors.seed = 2;
  const std::vector<mbid::Measurement> records{mbid::Simulate(scenario), mbid::Simulate(heavier)};
  const mbid::UpdateResult own =
      mbid::Update(scenario, records, {scenario.excitation, heavier.excitation});
  EXPECT_GT(own.chi_square_per_dof, 0.8);
  EXPECT_LT(own.chi_square_per_dof, 1.25);
  const mbid::ParameterValue& c_alpha = own.parameters.at("c_alpha");
  EXPECT_LT(std::abs(c_alpha.value - truth), 4 * c_alpha.std) << c_alpha.value << " vs " << truth;
  const mbid::UpdateResult same = mbid::Update(scenario, records);
  EXPECT_GT(same.chi_square_per_dof, 10 * own.chi_square_per_dof);
  EXPECT_THROW(mbid::Update(scenario, records, {scenario.excitation}), mbid::InputError);
}

// updating.profile.enabled reaches UpdateResult::parameters: on the reference record (4 s) every
// joint's profile interval is closed and brackets its estimate; without it, NaN.
TEST(FacadeTest, UpdateCarriesTheProfileIntervalsTheScenarioAsksFor) {
  const mbid::Scenario scenario = mbid::LoadScenarioFromText(
      ReferenceText(4, "updating: {profile: {enabled: true}}\n"), "profile.yaml");
  const std::vector<mbid::Measurement> records{mbid::Simulate(scenario)};
  const mbid::UpdateResult result = mbid::Update(scenario, records);
  ASSERT_EQ(result.parameters.size(), 8u);
  for (const auto& [name, p] : result.parameters) {
    SCOPED_TRACE(name);
    EXPECT_LT(p.profile_lower, p.value);
    EXPECT_GT(p.profile_upper, p.value);
    EXPECT_FALSE(p.profile_lower_open || p.profile_upper_open);
  }
  const mbid::UpdateResult plain = mbid::Update(mbid::LoadScenario(kReference), records);
  EXPECT_TRUE(std::isnan(plain.parameters.at("c_alpha").profile_lower));
}

// A profile open on both sides makes the verdict inconclusive, naming the parameter: bounds on
// d_eta of +-0.45% around the truth lie inside its 1-sigma range on the 4 s record (relative
// std ~1-2%), so the cost cannot rise to the 2-sigma threshold before either bound.
TEST(FacadeTest, AnOpenProfileMakesTheVerdictInconclusive) {
  const mbid::ValidationResult result = mbid::RunValidationCycle(mbid::LoadScenarioFromText(
      ReferenceText(4, "updating: {profile: {enabled: true}, bounds: {d_eta: [43800, 44200]}}\n"),
      "open-profile.yaml"));
  EXPECT_EQ(result.verdict, mbid::Verdict::kInconclusive);
  const mbid::ParameterValue& d_eta = result.updated.parameters.at("d_eta");
  EXPECT_TRUE(d_eta.profile_lower_open && d_eta.profile_upper_open);
  EXPECT_FALSE(d_eta.determined);
  bool named = false;
  for (const std::string& reason : result.reasons) {
    named = named || (reason.find("d_eta") != std::string::npos &&
                      reason.find("profile") != std::string::npos);
  }
  EXPECT_TRUE(named) << ::testing::PrintToString(result.reasons);
  // The other parameters' profiles close well inside their bounds: still determined.
  EXPECT_TRUE(result.updated.parameters.at("c_alpha").determined);
}

// A pendulum on a spring of 100 N m/rad and the given damping, released from 0.01 rad and
// recorded 4 s at 100 Hz: a scenario without its name.
std::string Pendulum(double damping) {
  return fmt::format(R"(model:
  type: multibody
  bodies:
    bob: {{parent: ground, joint: {{type: revolute, coordinates: [swing], axis: [0, 1, 0]}},
          mass_kg: 10.0, com_m: [0, 0, -0.5], inertia_kgm2: [0.2, 0.2, 0.05]}}
  springs:
    swing: {{stiffness_Nm_per_rad: 100.0, damping_Nms_per_rad: {}}}
  outputs:
    angle: {{type: coordinate, coordinate: swing}}
excitation: {{type: initial_deflection, deflection_rad: {{swing: 0.01}}}}
simulation: {{duration_s: 4}}
sensors: {{sample_rate_hz: 100, channels: [angle], noise_std_rad: 1.0e-5, seed: 3}}
)",
                     damping);
}

// An overdamped machine (what damper sizing designs): a pendulum on a joint at 1.5 times critical
// damping, sqrt((c + m g L) J) = sqrt((100 + 10 * 9.81 * 0.5) * 3.05) = 20.06, d = 3 * 20.06 =
// 60.18, rings at no frequency, and `update` and `run` stopped at "no modes found" (exit 3). The
// time-domain fit needs no modes: both joint parameters come back within 3 standard deviations;
// the run is inconclusive (no identification), not a failure to run.
TEST(FacadeTest, AnOverdampedMachineIsTunedWithoutModes) {
  const std::string text = "name: pendulum\n" + Pendulum(60.18) +
                           R"(updating: {noise_std_rad: 1.0e-5, global_search: {enabled: false},
           start: {c_swing: 80.0, d_swing: 50.0}}
)";
  const mbid::Scenario scenario = mbid::LoadScenarioFromText(text, "overdamped.yaml");
  const mbid::UpdateResult tuned = mbid::Update(scenario, {mbid::Simulate(scenario)});
  const mbid::ParameterValue& c = tuned.parameters.at("c_swing");
  const mbid::ParameterValue& d = tuned.parameters.at("d_swing");
  EXPECT_NEAR(c.value, 100.0, 3 * c.std);
  EXPECT_NEAR(d.value, 60.18, 3 * d.std);
  EXPECT_TRUE(c.determined && d.determined);
  const mbid::ValidationResult run = mbid::RunValidationCycle(scenario);
  EXPECT_EQ(run.verdict, mbid::Verdict::kInconclusive);
  EXPECT_NE(::testing::PrintToString(run.reasons).find("an overdamped machine"), std::string::npos)
      << ::testing::PrintToString(run.reasons);
}

// An arm on a pin (stiffness and damping given) carrying a pendulum, both angles measured: the
// model section of a scenario.
std::string ArmAndBob(double pin_stiffness, double pin_damping) {
  return fmt::format(R"(model:
  type: multibody
  bodies:
    arm: {{parent: ground, joint: {{type: revolute, coordinates: [pin], axis: [0, 1, 0]}},
          mass_kg: 10.0, com_m: [0.5, 0, 0], inertia_kgm2: [0.1, 0.9, 0.9]}}
    bob: {{parent: arm, joint: {{type: revolute, coordinates: [swing], axis: [0, 1, 0],
          in_parent_m: [1.0, 0, 0]}}, mass_kg: 2.0, com_m: [0, 0, -0.5],
          inertia_kgm2: [0.02, 0.02, 0.01]}}
  springs:
    pin: {{stiffness_Nm_per_rad: {}, damping_Nms_per_rad: {}}}
    swing: {{stiffness_Nm_per_rad: 20.0, damping_Nms_per_rad: 0.2}}
  outputs:
    arm_angle: {{type: coordinate, coordinate: pin}}
    bob_angle: {{type: coordinate, coordinate: swing}}
)",
                     pin_stiffness, pin_damping);
}

// A stiff pin at 45.9 Hz sampled at 100 Hz, started where its mode is at 54.5 Hz (above Nyquist,
// the samples show it at 45.5 Hz): the fit ended at the alias (c_pin 622605 against 450000, 53.6
// Hz), where before no start came from below Nyquist (a trial's mast pin, "passed" 38 of its
// standard deviations off). The joint sets with the best end's modes moved to their aliases are
// fitted too: the truth fits lower (cost 211 against 447 at the alias, the F-test separates them)
// and is the result. Route 1 and the pole-equivalent sets are off, one design point: the alias
// sets alone reach it.
TEST(FacadeTest, AModeAboveNyquistIsAlsoFittedAtItsAlias) {
  const std::string text =
      "name: pin-and-bob\n" + ArmAndBob(4.5e5, 30.0) +
      R"(excitation: {type: initial_deflection, deflection_rad: {pin: 0.001, swing: 0.05}}
simulation: {duration_s: 2}
sensors: {sample_rate_hz: 100, channels: [arm_angle, bob_angle], noise_std_rad: 1.0e-5, seed: 3}
updating: {noise_std_rad: 1.0e-5, algebraic_start: false,
           global_search: {design_starts: 1, pole_equivalent_starts: false},
           start: {c_pin: 6.3e5, d_pin: 40.0, c_swing: 15.0, d_swing: 0.25}}
)";
  const mbid::Scenario scenario = mbid::LoadScenarioFromText(text, "pin.yaml");
  const mbid::UpdateResult tuned = mbid::Update(scenario, {mbid::Simulate(scenario)});
  const mbid::ParameterValue& c = tuned.parameters.at("c_pin");
  EXPECT_NEAR(c.value, 4.5e5, 3 * c.std);
  EXPECT_TRUE(c.determined) << c.why_undetermined;
  EXPECT_FALSE(tuned.non_unique);
  EXPECT_EQ(tuned.search.aliased, 1);
  EXPECT_EQ(tuned.search.minima.front().starts.front().rfind("alias set", 0), 0u);
}

// A two-link arm released from 0.04 and -0.08 rad (modes 0.568 and 1.306 Hz): its quadratic terms
// shift the mean by the faster mode squared, decaying at twice its rate with no frequency, fitted
// as a pole at 0.035 Hz, less than a cycle in the record. That made every such free decay
// unreliable ("a trend or drift cannot be told from it") and the run inconclusive, mbid's own
// simulated test too. It is the tone f5 - f5 (twice f5's decay), a warning, and the run passes.
TEST(FacadeTest, TheMeanShiftOfALinkagesFreeDecayIsNoDrift) {
  const std::string text = R"(name: two-links
model:
  type: multibody
  gravity_mps2: 9.81
  bodies:
    b0: {parent: ground, joint: {type: revolute, coordinates: [q1], axis: [0, -1, 0]},
         mass_kg: 300.0, com_m: [1.7320508, 0, 1.0], inertia_kgm2: [400.0, 400.0, 400.0]}
    b1: {parent: b0, joint: {type: revolute, coordinates: [q2], axis: [0, -1, 0],
         in_parent_m: [3.4641016, 0, 2.0]}, mass_kg: 120.0, com_m: [0.9575556, 0, -0.8034845],
         inertia_kgm2: [62.5, 62.5, 62.5]}
  springs:
    q1: {stiffness_Nm_per_rad: 60000.0, damping_Nms_per_rad: 500.0}
    q2: {stiffness_Nm_per_rad: 12000.0, damping_Nms_per_rad: 100.0}
  points:
    tip: {body: b1, at_m: [1.9151111, 0, -1.6069690]}
  outputs:
    th1: {type: elevation, body: b0, direction: [1, 0, 0]}
    th2: {type: elevation, body: b1, direction: [1, 0, 0]}
    w2: {type: angular_velocity, body: b1, axis: [0, -1, 0], frame: ground}
    atx: {type: acceleration, point: tip, direction: [1, 0, 0], frame: ground}
    atz: {type: acceleration, point: tip, direction: [0, 0, 1], frame: ground}
excitation: {type: initial_deflection, deflection_rad: {q1: 0.04, q2: -0.08}}
simulation: {duration_s: 10}
sensors: {sample_rate_hz: 500, channels: [th1, th2, w2, atx, atz], noise_std_rad: 1.0e-4,
          noise_std_radps: 5.0e-4, noise_std_mps2: 5.0e-3}
)";
  const mbid::ValidationResult run =
      mbid::RunValidationCycle(mbid::LoadScenarioFromText(text, "two-links.yaml"));
  EXPECT_EQ(run.verdict, mbid::Verdict::kPassed) << ::testing::PrintToString(run.reasons);
  bool mean_shift = false;
  for (const auto& mode : run.cycle.tests.front().identified.modes) {
    mean_shift = mean_shift || (mode.frequency_hz < 0.1 && mode.combination == "f5 - f5");
  }
  EXPECT_TRUE(mean_shift);
}

// A logger started 0.25 s after the release: the record begins mid-swing, where the test as the
// scenario states it starts at rest, and no re-simulation can match it. The exact model "failed"
// (a trial's two-link arm, K = -0.44), telling the user the model is wrong; nothing is known of
// it: inconclusive, naming the late start and the way out (the release instant).
TEST(FacadeTest, ARecordThatStartsAfterTheReleaseIsNoFailureOfTheModel) {
  const std::string pendulum = "name: pendulum\n" + Pendulum(2.0);
  const mbid::Measurement full = mbid::Simulate(mbid::LoadScenarioFromText(pendulum, "p.yaml"));
  const std::filesystem::path folder =
      std::filesystem::temp_directory_path() / ("mbid_late_" + std::to_string(::getpid()));
  std::filesystem::create_directories(folder);
  {
    std::ofstream out(folder / "late.csv");
    out << "time,angle\n";
    for (Eigen::Index j = 25; j < full.samples(); ++j) {  // from 0.25 s on, its time from 0
      out << fmt::format("{:.2f},{:.17g}\n", 0.01 * static_cast<double>(j - 25), full.values(j, 0));
    }
  }
  const mbid::ValidationResult run = mbid::RunValidationCycle(mbid::LoadScenarioFromText(
      pendulum + "record: {file: " + (folder / "late.csv").string() + "}\n", "late.yaml"));
  std::filesystem::remove_all(folder);
  EXPECT_EQ(run.verdict, mbid::Verdict::kInconclusive);
  EXPECT_NE(::testing::PrintToString(run.reasons).find("the record starts in motion"),
            std::string::npos)
      << ::testing::PrintToString(run.reasons);
}

// `pendulum`'s record logged from 1 s before its release, held at its deflection, with the
// channels `reversed` (one flag per channel) turned over; the cycle's result on it.
mbid::ValidationResult RunReversed(const std::string& pendulum, const std::vector<bool>& reversed) {
  const mbid::Measurement full = mbid::Simulate(mbid::LoadScenarioFromText(pendulum, "p.yaml"));
  const std::filesystem::path folder =
      std::filesystem::temp_directory_path() / ("mbid_reversed_" + std::to_string(::getpid()));
  std::filesystem::create_directories(folder);
  {
    std::ofstream out(folder / "reversed.csv");
    out << "time," << fmt::format("{}", fmt::join(full.channels, ",")) << "\n";
    for (Eigen::Index j = 0; j < 100 + full.samples(); ++j) {
      const Eigen::Index k = j < 100 ? 0 : j - 100;
      out << fmt::format("{:.2f}", 0.01 * static_cast<double>(j));
      for (Eigen::Index c = 0; c < full.values.cols(); ++c) {
        out << fmt::format(
            ",{:.17g}", reversed[static_cast<size_t>(c)] ? -full.values(k, c) : full.values(k, c));
      }
      out << "\n";
    }
  }
  const mbid::ValidationResult run = mbid::RunValidationCycle(mbid::LoadScenarioFromText(
      pendulum + "record: {file: " + (folder / "reversed.csv").string() + "}\n", "rev.yaml"));
  std::filesystem::remove_all(folder);
  return run;
}

// The same pendulum logged from 1 s before its release, its sensor mounted reversed and the
// reversal not stated: over a record that rests before the release found in it, a sensor's sign
// (or a model) the record refutes fails. It was "inconclusive", asking whether the logger had
// started after the release (a trial's jib inclinometer, K = -0.9997). With a second, correct
// sensor that the fit follows, K = -1 on the reversed one, and the reason names the sign.
TEST(FacadeTest, ARecordCutAtAReleaseFoundInItIsNoLateStart) {
  std::string pendulum = "name: pendulum\n" + Pendulum(2.0);
  const mbid::ValidationResult alone = RunReversed(pendulum, {true});
  EXPECT_EQ(alone.verdict, mbid::Verdict::kFailed) << ::testing::PrintToString(alone.reasons);
  EXPECT_EQ(::testing::PrintToString(alone.reasons).find("starts in motion"), std::string::npos);

  const std::string one = "    angle: {type: coordinate, coordinate: swing}\n";
  const std::string channels = "channels: [angle]";
  const std::string noise = "noise_std_rad: 1.0e-5";
  ASSERT_NE(pendulum.find(one), std::string::npos);
  pendulum.replace(pendulum.find(one), one.size(),
                   one + "    second: {type: coordinate, coordinate: swing}\n");
  pendulum.replace(pendulum.find(channels), channels.size(), "channels: [angle, second]");
  // The second sensor 100 times noisier: the fit follows the first, as a trial's fit followed
  // its other three channels.
  pendulum.replace(pendulum.find(noise), noise.size(),
                   "noise_std_rad: {angle: 1.0e-5, second: 1.0e-3}");
  const mbid::ValidationResult run = RunReversed(pendulum, {false, true});
  const std::string reasons = ::testing::PrintToString(run.reasons);
  EXPECT_EQ(run.verdict, mbid::Verdict::kFailed) << reasons;
  EXPECT_NE(reasons.find("K(second) = -"), std::string::npos) << reasons;
  EXPECT_NE(reasons.find("a sensor mounted reversed"), std::string::npos) << reasons;
}

// A pendulum (2 m pin, 50 kg, 1.10 Hz) deflected 0.01 rad in sensor noise of 0.02 rad, twice its
// swing: the identification takes a 20.2 Hz noise peak for the mode and says it is unreliable.
// Route 1 solved on that pole, and its one set "fitting the records to their noise" skipped the
// design: c_q1 = 794746 +- 10629 for 2000, determined (a trial's seed 31). Sets from doubtful
// poles are no longer all the sets: the design runs and finds the 1.1 Hz minimum, which the
// F-test prefers (cost 604.4 against 622.1).
TEST(FacadeTest, PolesOfAnUnreliableIdentificationDoNotSettleTheSearch) {
  const auto scenario = [](double c, double d, int seed) {
    return fmt::format(R"(name: pendulum
model:
  type: multibody
  bodies:
    arm: {{parent: ground, joint: {{type: revolute, coordinates: [q1], axis: [0, 1, 0],
           in_parent_m: [0, 0, 2.0]}}, mass_kg: 50.0, com_m: [0, 0, -1.0],
           inertia_kgm2: [2.0, 2.0, 0.5]}}
  springs:
    q1: {{stiffness_Nm_per_rad: {}, damping_Nms_per_rad: {}}}
  outputs:
    ang: {{type: coordinate, coordinate: q1}}
excitation: {{type: initial_deflection, deflection_rad: {{q1: 0.01}}}}
simulation: {{duration_s: 12}}
sensors: {{sample_rate_hz: 100, channels: [ang], noise_std_rad: 2.0e-2, seed: {}}}
)",
                       c, d, seed);
  };
  const mbid::Measurement record =
      mbid::Simulate(mbid::LoadScenarioFromText(scenario(2000, 14.4, 31), "truth.yaml"));
  const mbid::Scenario design = mbid::LoadScenarioFromText(scenario(2600, 10.08, 1), "d.yaml");
  EXPECT_FALSE(mbid::Identify(record).reliable);
  const mbid::UpdateResult tuned = mbid::Update(design, {record});
  const mbid::ParameterValue& c = tuned.parameters.at("c_q1");
  // Determined or not, a value reported within 4 of its standard deviations of the truth.
  EXPECT_LT(std::abs(c.value - 2000), 4 * c.std) << c.value << " +- " << c.std;
}

// No whole-record fit converging within its iterations was exit 3, "no local fit converged" (a
// trial's two springs in series: 20 of 20 records, where 178 iterations converged and left every
// parameter rightly undetermined). The least-cost end goes on for three times the iterations:
// here the pendulum from 30 % off with 2 iterations a fit, which no fit finishes in.
TEST(FacadeTest, AFitThatRunsOutOfIterationsGoesOnOnce) {
  const mbid::Scenario truth = mbid::LoadScenarioFromText("name: p\n" + Pendulum(2.0), "t.yaml");
  const mbid::Scenario design = mbid::LoadScenarioFromText(
      "name: p\n" + Pendulum(2.0) +
          "updating: {noise_std_rad: 1.0e-5, max_iterations: 2, algebraic_start: false,\n"
          "           start: {c_swing: 130.0, d_swing: 2.6}, global_search: {design_starts: 2}}\n",
      "d.yaml");
  const mbid::UpdateResult tuned = mbid::Update(design, {mbid::Simulate(truth)});
  EXPECT_TRUE(tuned.converged);
  EXPECT_TRUE(::testing::PrintToString(tuned.search.notes).find("went on for up to 6") !=
              std::string::npos)
      << ::testing::PrintToString(tuned.search.notes);
  const mbid::ParameterValue& c = tuned.parameters.at("c_swing");
  EXPECT_NEAR(c.value, 100.0, 4 * c.std);
}

// A test deflecting the swing 0.05 rad and the pin not at all, both deflections fitted: the pin's
// came out near 0 with a std of a few urad, "undetermined" for a relative std of its own value
// (a trial's 2e-6 +- 5e-6 rad, "rank 8 of 8"). It is relative to the test's largest deflection of
// its unit: known to be small, determined.
TEST(FacadeTest, ADeflectionFittedNearZeroIsKnownToBeSmall) {
  const std::string text =
      "name: swing\n" + ArmAndBob(2.0e3, 3.0) +
      R"(excitation: {type: initial_deflection, deflection_rad: {pin: 0.0, swing: 0.05}}
simulation: {duration_s: 3}
sensors: {sample_rate_hz: 100, channels: [arm_angle, bob_angle], noise_std_rad: 1.0e-5, seed: 3}
updating: {noise_std_rad: 1.0e-5, fit_initial_deflection: true, global_search: {enabled: false}}
)";
  const mbid::Scenario scenario = mbid::LoadScenarioFromText(text, "swing.yaml");
  const mbid::UpdateResult tuned = mbid::Update(scenario, {mbid::Simulate(scenario)});
  const mbid::ParameterValue& pin = tuned.parameters.at("record 1:deflection_pin");
  EXPECT_NEAR(pin.value, 0.0, 4 * pin.std);
  EXPECT_LT(pin.std, 1e-3 * 0.05);  // the records know it to a thousandth of the test's size
  EXPECT_TRUE(pin.determined) << pin.why_undetermined;
}

// A cart on a spring at 1.5 times critical damping (poles -2.78 and -26.2 1/s) carrying a swinging
// arm (1.198 Hz): a record from an independent simulator (an audit's own planar multibody code,
// energy conserved to 1e-11; 250 Hz, 6 s, the cart in mm, three accelerometers; truth c_x 40000,
// d_x 16000, c_th 3000, d_th 40). The modes hold no overdamped motion: K(acx) = 0.539 made the
// identification unreliable and the run inconclusive, though the fit was exact. The tuned model,
// credible, explains the record to its noise: passed, every parameter within 3 stds.
TEST(FacadeTest, AnOverdampedJointBesideAnOscillatingOnePasses) {
  const std::string text = R"(name: cart-and-arm
model:
  type: multibody
  gravity_mps2: 9.81
  bodies:
    b0: {parent: ground, joint: {type: prismatic, coordinates: [x], axis: [1, 0, 0]},
         mass_kg: 500.0, com_m: [0, 0, 0], inertia_kgm2: [50.0, 50.0, 50.0]}
    b1: {parent: b0, joint: {type: revolute, coordinates: [th], axis: [0, -1, 0],
         in_parent_m: [0, 0, 0.5]}, mass_kg: 80.0, com_m: [0.5303300858899107, 0, -0.5303300858899107],
         inertia_kgm2: [15.0, 15.0, 15.0]}
  springs:
    x: {stiffness_N_per_m: 56000.0, damping_Ns_per_m: 9600.0}
    th: {stiffness_Nm_per_rad: 1950.0, damping_Nms_per_rad: 56.0}
  points:
    p_acx: {body: b0, at_m: [0, 0, 0]}
    p_tip: {body: b1, at_m: [1.0606601717798214, 0, -1.0606601717798214]}
  outputs:
    xc: {type: coordinate, coordinate: x}
    acx: {type: acceleration, point: p_acx, direction: [1, 0, 0], frame: ground}
    atx: {type: acceleration, point: p_tip, direction: [1, 0, 0], frame: ground}
    atz: {type: acceleration, point: p_tip, direction: [0, 0, 1], frame: ground}
excitation: {type: initial_deflection, deflection_m: {x: 0.02}, deflection_rad: {th: 0.05}}
simulation: {duration_s: 6}
)";
  const mbid::ValidationResult run = mbid::RunValidationCycle(
      mbid::LoadScenarioFromText(text + "record: {file: " + std::string(MBID_SOURCE_DIR) +
                                     "/tests/data/machines/cart_overdamped_arm.csv}\n",
                                 "cart.yaml"));
  EXPECT_EQ(run.verdict, mbid::Verdict::kPassed) << ::testing::PrintToString(run.reasons);
  for (const auto& [name, truth] : std::map<std::string, double>{
           {"c_x", 40000}, {"d_x", 16000}, {"c_th", 3000}, {"d_th", 40}}) {
    const mbid::ParameterValue& p = run.updated.parameters.at(name);
    EXPECT_NEAR(p.value, truth, 3 * p.std) << name;
  }
}

// `passed` needs a credible fit. Weights that state the noise 30 % low (7e-6 rad against the
// record's 1e-5) leave a white excess, chi^2/dof about 2, taken for a noise level stated too low:
// the standard deviations are inflated by about 1.4, but the fit is not credible (a trial's hammer
// blow 10 % off had passed the same way), so no joint is determined (interfaces.md: `determined`
// needs a credible fit; a hanger's mass 30 % off was "determined" 3046 stds off so). Inconclusive,
// with the credibility's reason.
TEST(FacadeTest, AFitThatIsNotCredibleDoesNotPass) {
  const mbid::ValidationResult result = mbid::RunValidationCycle(mbid::LoadScenarioFromText(
      ReferenceText(4, "updating: {noise_std_rad: 7.0e-6, global_search: {enabled: false}}\n"),
      "understated.yaml"));
  EXPECT_FALSE(result.updated.credible);
  EXPECT_EQ(result.updated.undetermined.size(), 8u)
      << ::testing::PrintToString(result.updated.undetermined);
  EXPECT_NE(result.updated.parameters.at("c_alpha").why_undetermined.find("not credible"),
            std::string::npos);
  EXPECT_EQ(result.verdict, mbid::Verdict::kInconclusive);
  bool named = false;
  for (const std::string& reason : result.reasons) {
    named = named || reason.find("the fit is not credible") != std::string::npos;
  }
  EXPECT_TRUE(named) << ::testing::PrintToString(result.reasons);
}

// A channel whose noise alone keeps K below the threshold fails the verdict (the contract's
// rule), and the reason says so; a model that cannot fit fails without that remark.
TEST(FacadeTest, TooLittleSignalIsInconclusiveNotAFailure) {
  const std::string quick = "updating: {global_search: {enabled: false}}\n";
  std::string noisy = ReferenceText(4, quick);
  // 40 times the reference's noise: psi's re-simulation correlates at 0.85 (measured), its
  // residual at the noise (0.000416 against 0.000423).
  noisy.replace(noisy.find("noise_std_rad: 1.0e-05"), 22, "noise_std_rad: 4.0e-04");
  const mbid::ValidationResult weak =
      mbid::RunValidationCycle(mbid::LoadScenarioFromText(noisy, "noisy.yaml"));
  // The model explains psi to its noise: the channel cannot judge it, which is no failure.
  EXPECT_EQ(weak.verdict, mbid::Verdict::kInconclusive);
  ASSERT_FALSE(weak.reasons.empty());
  EXPECT_EQ(weak.reasons[0].rfind("K(psi) = ", 0), 0u) << weak.reasons[0];
  EXPECT_NE(weak.reasons[0].find("too little signal"), std::string::npos) << weak.reasons[0];
  // c_alpha held 30 times below the truth: phi's K 0.91 with a residual far above the noise.
  const mbid::ValidationResult wrong = mbid::RunValidationCycle(mbid::LoadScenarioFromText(
      ReferenceText(2,
                    "updating: {global_search: {enabled: false}, algebraic_start: false, "
                    "bounds: {c_alpha: [1.0e6, 2.0e6]}, start: {c_alpha: 1.5e6}}\n"),
      "wrong.yaml"));
  EXPECT_EQ(wrong.verdict, mbid::Verdict::kFailed);
  bool below = false;
  for (const std::string& reason : wrong.reasons) {
    if (reason.rfind("K(", 0) != 0) continue;
    below = true;
    EXPECT_EQ(reason.find("too little signal"), std::string::npos) << reason;
  }
  EXPECT_TRUE(below) << ::testing::PrintToString(wrong.reasons);
}

TEST(FacadeTest, TheCycleInMemoryPassesTheReferenceAndWritesNothing) {
  const fs::path cwd = fs::temp_directory_path() / "mbid_facade_cycle";
  fs::remove_all(cwd);
  fs::create_directories(cwd);
  const fs::path before = fs::current_path();
  fs::current_path(cwd);
  const mbid::ValidationResult result = mbid::RunValidationCycle(mbid::LoadScenario(kReference));
  fs::current_path(before);
  // The reference crane's own simulated test validates (docs/validation.md).
  EXPECT_EQ(result.verdict, mbid::Verdict::kPassed);
  EXPECT_TRUE(result.reasons.empty());
  ASSERT_EQ(result.correlation.size(), 2u);  // psi and phi
  for (const auto& [channel, k] : result.correlation) EXPECT_GE(k, result.min_correlation);
  EXPECT_EQ(result.updated.parameters.count("c_alpha"), 1u);
  EXPECT_GT(result.updated.parameters.at("c_alpha").std, 0.0);
  EXPECT_TRUE(fs::is_empty(cwd));  // no results/ folder, no figures
  fs::remove_all(cwd);
}

TEST(FacadeTest, AFolderOfTheUsersIsNeverReplaced) {
  const fs::path dir = fs::temp_directory_path() / "mbid_facade_folder";
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir / "thesis.tex") << "years of work";
  mbid::ValidationOptions options;
  options.output_folder = dir.string();
  options.overwrite = true;
  EXPECT_THROW(mbid::RunValidationCycle(mbid::LoadScenario(kReference), options), mbid::InputError);
  std::ifstream in(dir / "thesis.tex");
  std::string text;
  std::getline(in, text);
  EXPECT_EQ(text, "years of work");
  fs::remove_all(dir);
}

}  // namespace
