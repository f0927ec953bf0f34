// Machines from descriptions through the command line: the excavator's whole cycle, the crane's
// two spellings, and bad descriptions stopped with one line and nothing written.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "command_test.h"
#include "mbid/common/hdf5_io.h"

namespace mbid::testing {
namespace {

const fs::path kScenarios = fs::path(MBID_SOURCE_DIR) / "scenarios";

class MachineCliTest : public CommandTest {};

// A cart on a prismatic spring (1e6 N/m, 1000 kg: 5.03 Hz), released from 10 mm.
constexpr const char* kSlide = R"(model:
  type: multibody
  bodies:
    cart: {parent: ground, joint: {type: prismatic, coordinates: [x], axis: [1, 0, 0]}, mass_kg: 1000.0, inertia_kgm2: [100, 100, 100]}
  springs:
    x: {stiffness_N_per_m: 1.0e6, damping_Ns_per_m: 2000.0}
  outputs: {x_cart: {type: coordinate, coordinate: x}}
excitation: {type: initial_deflection, deflection_m: {x: 0.01}}
)";

TEST_F(MachineCliTest, ExcavatorRunPassesAndRecoversItsJoints) {
  const fs::path out = dir_ / "excavator";
  const CommandResult result =
      Run("run " + (kScenarios / "excavator-arm.yaml").string() + " -o " + out.string());
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const nlohmann::json summary = nlohmann::json::parse(ReadText(out / "summary.json"));
  EXPECT_TRUE(summary["validation"]["passed"].get<bool>());
  EXPECT_EQ(summary["updating"]["termination"], "converged");
  // The scenario's springs are the truth of the simulated test. A tuned value within 4 of its
  // standard deviations (the issue's bound for "determined"); the units from the model.
  const std::map<std::string, double> truth{{"c_swing", 3.0e7}, {"c_boom", 6.4e7},
                                            {"c_stick", 2.5e7}, {"d_swing", 2.0e5},
                                            {"d_boom", 3.0e5},  {"d_stick", 8.0e4}};
  for (const auto& [name, value] : truth) {
    const nlohmann::json& p = summary["updating"]["parameters"][name];
    EXPECT_LT(std::abs(p["value"].get<double>() - value), 4 * p["std"].get<double>()) << name;
    EXPECT_EQ(p["units"], name[0] == 'c' ? "N*m/rad" : "N*m*s/rad") << name;
  }
}

TEST_F(MachineCliTest, CraneShorthandAndDescriptionGiveTheSameModes) {
  const fs::path a = dir_ / "a.json", b = dir_ / "b.json";
  ASSERT_EQ(Run("modes " + (kScenarios / "reference-crane.yaml").string() + " --json " + a.string())
                .exit_code,
            0);
  ASSERT_EQ(Run("modes " + (kScenarios / "reference-crane-description.yaml").string() + " --json " +
                b.string())
                .exit_code,
            0);
  const nlohmann::json ja = nlohmann::json::parse(ReadText(a));
  const nlohmann::json jb = nlohmann::json::parse(ReadText(b));
  ASSERT_EQ(ja["modes"].size(), 4u);
  ASSERT_EQ(jb["modes"].size(), 4u);
  for (size_t k = 0; k < 4; ++k) {
    const double fa = ja["modes"][k]["frequency_hz"].get<double>();
    EXPECT_NEAR(jb["modes"][k]["frequency_hz"].get<double>(), fa, 1e-12 * fa) << k;
  }
}

// `mbid modes` says where a machine rests under its attached payload (an audit set initial
// deflections about the loaded rest without knowing it): an arm horizontal at q = 0 on a
// 5000 N m/rad spring preloaded against the arm's own weight (50 kg, 1 m out), a 100 kg payload
// 2 m out. At the arm's angle theta the spring balances both weights' moments beyond the
// preload: c |theta| = M g L cos(theta) + m g l (cos(theta) - 1), solved here by bisection.
TEST_F(MachineCliTest, ModesSayWhereAPayloadRestsTheMachine) {
  const std::string machine = R"(name: arm
model:
  type: multibody
  gravity_mps2: 9.81
  bodies:
    arm: {parent: ground, joint: {type: revolute, coordinates: [q], axis: [0, -1, 0]},
          mass_kg: 50.0, com_m: [1.0, 0, 0], inertia_kgm2: [1.0, 20.0, 20.0]}
  springs:
    q: {stiffness_Nm_per_rad: 5000.0, damping_Nms_per_rad: 20.0}
  points:
    tip: {body: arm, at_m: [2.0, 0, 0]}
  outputs:
    angle: {type: coordinate, coordinate: q}
  payload_point: tip
)";
  const fs::path loaded = Write("loaded.yaml", machine + "  payload_mass_kg: 100.0\n");
  const fs::path json = dir_ / "modes.json";
  const CommandResult modes = Run("modes " + loaded.string() + " --json " + json.string());
  ASSERT_EQ(modes.exit_code, 0) << modes.err;
  double low = 0, high = 0.5;  // c theta - m g L cos(theta) changes sign in [0, 0.5]
  for (int k = 0; k < 100; ++k) {
    const double mid = 0.5 * (low + high);
    const double balance =
        5000 * mid - 100 * 9.81 * 2.0 * std::cos(mid) - 50 * 9.81 * 1.0 * (std::cos(mid) - 1);
    (balance > 0 ? high : low) = mid;
  }
  const double rest = nlohmann::json::parse(ReadText(json))["rest"]["q"].get<double>();
  EXPECT_NEAR(std::abs(rest), low, 1e-9 * low);  // 0.36 rad
  EXPECT_NE(modes.out.find("under its attached payload (q = "), std::string::npos) << modes.out;
  // Without a payload the machine rests at q = 0: nothing more is said.
  const fs::path bare = Write("bare.yaml", machine);
  const fs::path bare_json = dir_ / "bare.json";
  const CommandResult unloaded = Run("modes " + bare.string() + " --json " + bare_json.string());
  ASSERT_EQ(unloaded.exit_code, 0) << unloaded.err;
  EXPECT_FALSE(nlohmann::json::parse(ReadText(bare_json)).contains("rest"));
  EXPECT_NE(unloaded.out.find("linearized at rest\n"), std::string::npos) << unloaded.out;
}

// A free coordinate (the swing without its drive's spring: a vertical axis, so gravity does not
// drive it) is a rigid-body motion: two poles at 0, reported as such; the cycle still runs,
// with Route 1 skipped and named why.
TEST_F(MachineCliTest, FreeCoordinateIsARigidBodyMotion) {
  const fs::path scenario =
      WriteVariant(kScenarios / "excavator-arm.yaml", "free.yaml",
                   "    swing: {stiffness_Nm_per_rad: 3.0e7, damping_Nms_per_rad: 2.0e5}\n", "");
  const fs::path json = dir_ / "modes.json";
  ASSERT_EQ(Run("modes " + scenario.string() + " --json " + json.string()).exit_code, 0);
  const nlohmann::json modes = nlohmann::json::parse(ReadText(json))["modes"];
  int rigid = 0;
  for (const nlohmann::json& mode : modes) rigid += mode.value("rigid_body", false) ? 1 : 0;
  EXPECT_EQ(rigid, 2);
  EXPECT_EQ(modes.size(), 4u);  // boom and stick ring, the swing's double pole at 0
  // By ascending frequency, as the contract lists modes: the poles at 0 first (they came last).
  for (size_t k = 1; k < modes.size(); ++k) {
    EXPECT_LE(modes[k - 1]["frequency_hz"].get<double>(), modes[k]["frequency_hz"].get<double>())
        << k;
  }
  // No rest to start from, and none asked for (the start-far-from-rest check once failed here).
  const CommandResult simulated =
      Run("simulate " + scenario.string() + " -o " + (dir_ / "free.h5").string());
  EXPECT_EQ(simulated.exit_code, 0) << simulated.err;
  // One local fit (CI time): the global search's design would add 6 s and nothing this test
  // looks at.
  std::ofstream(scenario, std::ios::app) << "updating: {global_search: {enabled: false}}\n";
  const CommandResult run =
      Run("run " + scenario.string() + " -o " + (dir_ / "run").string() + " --progress");
  EXPECT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.err.find("Route 1 (eq. 7): skipped; coordinate 'swing' has no spring"),
            std::string::npos)
      << run.err;
}

// A hammer test of a three-storey shear frame (prismatic floors, one roof accelerometer): the
// 10 ms pulse sits at the record's very start, where no release detection can see it. A record
// mbid simulated carries its test, so `identify` analyses the free decay after the pulse, as
// `run` does; from the record start a fourth mode (57 Hz, decay 200 1/s) absorbed the pulse and
// the 8.9 Hz mode came out 0.46% off, 8 of its standard deviations (measured).
TEST_F(MachineCliTest, IdentifyStartsAHammerRecordAfterThePulse) {
  const fs::path scenario = dir_ / "frame.yaml";
  std::ofstream(scenario) << R"(name: frame
model:
  type: multibody
  bodies:
    f1: {parent: ground, joint: {type: prismatic, coordinates: [x1], axis: [1, 0, 0]}, mass_kg: 1000.0, inertia_kgm2: [100, 100, 100]}
    f2: {parent: f1, joint: {type: prismatic, coordinates: [x2], axis: [1, 0, 0]}, mass_kg: 1000.0, inertia_kgm2: [100, 100, 100]}
    f3: {parent: f2, joint: {type: prismatic, coordinates: [x3], axis: [1, 0, 0]}, mass_kg: 1000.0, inertia_kgm2: [100, 100, 100]}
  springs:
    x1: {stiffness_N_per_m: 1.2e6, damping_Ns_per_m: 300.0}
    x2: {stiffness_N_per_m: 1.0e6, damping_Ns_per_m: 200.0}
    x3: {stiffness_N_per_m: 0.8e6, damping_Ns_per_m: 200.0}
  points: {roof: {body: f3, at_m: [0, 0, 0]}}
  outputs:
    a_roof: {type: acceleration, point: roof, direction: [1, 0, 0]}
excitation: {type: impulse, point: roof, force_N: [20000, 0, 0], duration_s: 0.01}
simulation: {duration_s: 6}
sensors: {sample_rate_hz: 200, channels: [a_roof], noise_std_mps2: 2.0e-3, seed: 4}
)";
  const fs::path record = dir_ / "frame.h5", modes = dir_ / "modes.json", found = dir_ / "id.json";
  const fs::path csv = dir_ / "frame.csv";
  ASSERT_EQ(Run("simulate " + scenario.string() + " -o " + record.string() + " --json " +
                modes.string() + " --export " + csv.string())
                .exit_code,
            0);
  const CommandResult identify =
      Run("identify " + record.string() + " --progress --json " + found.string());
  ASSERT_EQ(identify.exit_code, 0) << identify.err;
  EXPECT_NE(identify.err.find("free decay after the impulse that ends at 0.01 s"),
            std::string::npos)
      << identify.err;
  const nlohmann::json exact = nlohmann::json::parse(ReadText(modes))["modes"];
  const nlohmann::json result = nlohmann::json::parse(ReadText(found));
  EXPECT_TRUE(result["reliable"].get<bool>()) << result["reasons"];
  // The contract's release_time_s is where the free decay starts: the blow's end, not the
  // record's start (0 before).
  EXPECT_EQ(result["release"], "forcing end");
  EXPECT_DOUBLE_EQ(result["release_time_s"].get<double>(), 0.01);
  ASSERT_EQ(result["modes"].size(), 3u);
  for (size_t k = 0; k < 3; ++k) {
    // 1e-4 relative: at this noise the identified frequencies' standard deviations are 1e-6 to
    // 7e-6 of them (measured); the record is the nonlinear simulation, the exact modes linear.
    const double f = exact[k]["frequency_hz"].get<double>();
    EXPECT_NEAR(result["modes"][k]["frequency_hz"].get<double>(), f, 1e-4 * f) << k;
  }
  // Updating fits the whole record, the blow included: its jump is the model's, no glitch.
  const fs::path tuned = dir_ / "tuned.json";
  const CommandResult hammer_update = Run("update " + scenario.string() + " " + record.string() +
                                          " --quiet --json " + tuned.string());
  ASSERT_EQ(hammer_update.exit_code, 0) << hammer_update.err;
  const nlohmann::json credibility = nlohmann::json::parse(ReadText(tuned))["credibility"];
  EXPECT_TRUE(credibility["credible"].get<bool>()) << credibility;
  const nlohmann::json tuned_json = nlohmann::json::parse(ReadText(tuned));
  EXPECT_DOUBLE_EQ(tuned_json["release_time_s"].get<double>(), 0.01);
  // The file's own entry agrees (it said 0, the test's start, which is now test_start_s).
  EXPECT_DOUBLE_EQ(tuned_json["release"][0]["release_time_s"].get<double>(), 0.01);
  EXPECT_DOUBLE_EQ(tuned_json["release"][0]["test_start_s"].get<double>(), 0.0);

  // --release none still analyses from the record's start, as the user asks.
  const CommandResult none =
      Run("identify " + record.string() + " --release none --json " + found.string());
  EXPECT_EQ(none.err.find("free decay after the impulse"), std::string::npos) << none.err;

  // The same record as a logger writes it: 0.5 s of pre-trigger at rest before the blow, no
  // mark of mbid. The blow's start is found only to about a sample (0.5025 s here, measured),
  // and half a sample ruined the fit: the user must give it.
  std::istringstream exported(ReadText(csv));
  std::ostringstream logger;
  logger << "time,a_roof\n";
  for (int j = 0; j < 100; ++j) logger << j * 0.005 << "," << (j % 2 ? 1e-3 : -1e-3) << "\n";
  for (std::string line; std::getline(exported, line);) {
    if (line.empty() || line[0] == '#' || line.rfind("time", 0) == 0) continue;
    const size_t comma = line.find(',');
    logger << std::stod(line.substr(0, comma)) + 0.5 << line.substr(comma) << "\n";
  }
  const fs::path triggered = dir_ / "logger.csv";
  std::ofstream(triggered) << logger.str();
  const CommandResult update = Run("update " + scenario.string() + " " + triggered.string() +
                                   " --unit a_roof=m/s^2 --json " + (dir_ / "up.json").string());
  EXPECT_EQ(update.exit_code, 2) << update.err;
  EXPECT_NE(update.err.find("release_time_s: the record rests until about 0.5"), std::string::npos)
      << update.err;
  EXPECT_FALSE(fs::exists(dir_ / "up.json"));
}

// A load drop on a frame whose floors slide horizontally: the payload's weight acts along no
// compliant coordinate, so the simulated test does not move the machine. Nothing to identify
// (exit 3), and the message says why.
TEST_F(MachineCliTest, ATestThatDoesNotMoveTheMachineSaysSo) {
  const fs::path scenario = dir_ / "still.yaml";
  std::ofstream(scenario) << R"(name: still
model:
  type: multibody
  bodies:
    f1: {parent: ground, joint: {type: prismatic, coordinates: [x1], axis: [1, 0, 0]}, mass_kg: 1000.0, inertia_kgm2: [100, 100, 100]}
  springs:
    x1: {stiffness_N_per_m: 1.0e6, damping_Ns_per_m: 200.0}
  points: {roof: {body: f1, at_m: [0, 0, 0]}}
  payload_point: roof
  outputs: {a_roof: {type: acceleration, point: roof, direction: [1, 0, 0]}}
excitation: {type: load_drop, payload_mass_kg: 500}
simulation: {duration_s: 2}
sensors: {sample_rate_hz: 100, channels: [a_roof], noise_std_mps2: 1.0e-3, seed: 1}
)";
  const CommandResult run = Run("run " + scenario.string() + " -o " + (dir_ / "run").string());
  EXPECT_EQ(run.exit_code, 3) << run.err;
  EXPECT_NE(run.err.find("no modes found"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("the simulated test barely moves the machine"), std::string::npos)
      << run.err;
  EXPECT_FALSE(fs::exists(dir_ / "run"));
}

// Finite but absurd values stop at load with exit 2 and one line, before anything allocates:
// a mass that would overflow Simbody's inertia shift (refused at its key, above 1e9 kg), a record
// of 8e12 samples, a record of 1.
TEST_F(MachineCliTest, AbsurdValuesAreInvalidInputNotCrashes) {
  const struct {
    const char* from;
    const char* to;
    const char* key_path;
  } cases[] = {{"mass_kg: 15160.0", "mass_kg: 1.0e308", "model.base.mass_kg"},
               {"sample_rate_hz: 100", "sample_rate_hz: 1.0e12", "simulation.duration_s, sensors"},
               {"sample_rate_hz: 100", "sample_rate_hz: 1.0e-9", "simulation.duration_s, sensors"},
               {"duration_s: 8", "duration_s: 1.0e15", "simulation.duration_s, sensors"}};
  for (const auto& bad : cases) {
    const fs::path scenario =
        WriteVariant(kScenarios / "reference-crane.yaml", "absurd.yaml", bad.from, bad.to);
    const fs::path out = dir_ / "absurd.h5";
    const CommandResult result = Run("simulate " + scenario.string() + " -o " + out.string());
    EXPECT_EQ(result.exit_code, 2) << bad.to << ": " << result.err;
    EXPECT_NE(result.err.find(scenario.string() + ":" + bad.key_path), std::string::npos)
        << result.err;
    EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << result.err;
    EXPECT_FALSE(fs::exists(out)) << bad.to;
  }
}

// A coordinate channel that `mbid simulate` writes (a joint encoder) is accepted by `mbid
// update`, which fits it like an output: the luffing stiffness comes back within 4 std.
TEST_F(MachineCliTest, UpdateTakesTheCoordinateChannelsSimulateWrites) {
  const fs::path scenario = WriteVariant(kScenarios / "reference-crane.yaml", "encoder.yaml",
                                         "channels: [psi, phi]", "channels: [psi, phi, theta]");
  const fs::path record = dir_ / "encoder.h5";
  ASSERT_EQ(Run("simulate " + scenario.string() + " -o " + record.string()).exit_code, 0);
  const fs::path json = dir_ / "update.json";
  const CommandResult result = Run("update " + (kScenarios / "reference-crane.yaml").string() +
                                   " " + record.string() + " --json " + json.string());
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_NE(result.out.find("theta) ="), std::string::npos) << result.out;
  const nlohmann::json c_theta = nlohmann::json::parse(ReadText(json))["parameters"]["c_theta"];
  EXPECT_LT(std::abs(c_theta["value"].get<double>() - 9.4e6), 4 * c_theta["std"].get<double>());
}

// A slide released from a deflection of 10 mm, its deflection fitted as a nuisance parameter:
// a length, reported in m (it was labelled rad), and recovered within 4 of its std.
TEST_F(MachineCliTest, AFittedSlideDeflectionIsALength) {
  const fs::path scenario = dir_ / "slide.yaml";
  std::ofstream(scenario) << "name: slide\n"
                          << kSlide << R"(simulation: {duration_s: 2}
sensors: {sample_rate_hz: 200, channels: [x_cart], noise_std_m: 1.0e-5, seed: 3}
updating: {fit_initial_deflection: true, global_search: {enabled: false}}
)";
  const fs::path record = dir_ / "slide.h5";
  ASSERT_EQ(Run("simulate " + scenario.string() + " -o " + record.string()).exit_code, 0);
  const fs::path json = dir_ / "update.json";
  const CommandResult result =
      Run("update " + scenario.string() + " " + record.string() + " --json " + json.string());
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const nlohmann::json parameters = nlohmann::json::parse(ReadText(json))["parameters"];
  const std::string name = record.string() + ":deflection_x";
  ASSERT_TRUE(parameters.contains(name)) << parameters.dump();
  EXPECT_EQ(parameters[name]["units"], "m");
  EXPECT_NEAR(parameters[name]["value"].get<double>(), 0.01,
              4 * parameters[name]["std"].get<double>());
}

// A trial's description without `sensors:` was refused for "unknown channel 'psi'", the crane's
// channels, in a line naming no file. Its channels are now its outputs, as with a `sensors:`
// that lists none; and its initial deflection, a length, is labelled m (it was rad).
TEST_F(MachineCliTest, ADescriptionWithoutSensorsRecordsItsOutputs) {
  const fs::path scenario = dir_ / "bare.yaml";
  std::ofstream(scenario) << "name: bare\n" << kSlide << "simulation: {duration_s: 1}\n";
  const fs::path record = dir_ / "bare.h5";
  const CommandResult result = Run("simulate " + scenario.string() + " -o " + record.string());
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const H5Reader reader(record.string());
  EXPECT_EQ(reader.ReadMeasurement().channels, std::vector<std::string>{"x_cart"});
  EXPECT_EQ(reader.ReadUnits("/truth", "initial_q"), "m");
  EXPECT_DOUBLE_EQ(reader.ReadVector("/truth", "initial_q")(0), 0.01);
}

// A trial's case: a payload attached in the description rests the machine away from q = 0,
// and initial_deflection's coordinates count from q = 0: 3 mrad given, the release was 60 mrad
// from rest, silently. simulate now says so; without the payload it says nothing.
TEST_F(MachineCliTest, ADeflectionFarFromTheLoadedRestIsWarnedOf) {
  const auto arm = [&](double payload_kg) {
    const fs::path scenario = dir_ / "arm.yaml";
    std::ofstream(scenario) << R"(name: arm
model:
  type: multibody
  bodies:
    link: {parent: ground, joint: {type: revolute, coordinates: [q], axis: [0, 1, 0]}, mass_kg: 50.0, com_m: [0.5, 0, 0], inertia_kgm2: [1, 4, 4]}
  springs:
    q: {stiffness_Nm_per_rad: 3000.0, damping_Nms_per_rad: 15.0}
  points:
    tip: {body: link, at_m: [1, 0, 0]}
  payload_point: tip
  payload_mass_kg: )" << payload_kg
                            << R"(
  outputs: {q_out: {type: coordinate, coordinate: q}}
excitation: {type: initial_deflection, deflection_rad: {q: 0.003}}
simulation: {duration_s: 1}
)";
    return Run("simulate " + scenario.string() + " -o " + (dir_ / "arm.h5").string() +
               " --overwrite");
  };
  // 20 kg at 1 m on 3000 N m/rad: a rest about 20 * 9.81 / 3000 = 0.065 rad from q = 0.
  const CommandResult loaded = arm(20);
  ASSERT_EQ(loaded.exit_code, 0) << loaded.err;
  EXPECT_NE(loaded.err.find("from where the machine rests with its attached payload"),
            std::string::npos)
      << loaded.err;
  // mbid run says it too, among its warnings.
  const CommandResult run = Run("run " + (dir_ / "arm.yaml").string() + " -o " +
                                (dir_ / "arm-run").string() + " --quiet");
  EXPECT_NE(run.err.find("from where the machine rests with its attached payload"),
            std::string::npos)
      << run.err;
  const CommandResult bare = arm(0);
  ASSERT_EQ(bare.exit_code, 0) << bare.err;
  EXPECT_EQ(bare.err.find("warning"), std::string::npos) << bare.err;
  // A load drop whose payload no spring holds: 2e5 kg at 1 m on 3000 N m/rad would sag
  // 2e5 * 9.81 / 3000 = 654 rad on the spring alone (an audit's 1e9 kg started at -9805 rad,
  // unsaid); loaded gradually the arm hangs down at 1.569 rad, and a tenth of it at 1.555.
  const fs::path heavy = dir_ / "heavy.yaml";
  std::string text = ReadText(dir_ / "arm.yaml");
  text.replace(
      text.find("excitation: {type: initial_deflection, deflection_rad: {q: 0.003}}"),
      std::string("excitation: {type: initial_deflection, deflection_rad: {q: 0.003}}").size(),
      "excitation: {type: load_drop, payload_mass_kg: 2.0e5}");
  std::ofstream(heavy) << text;
  const CommandResult dropped =
      Run("simulate " + heavy.string() + " -o " + (dir_ / "heavy.h5").string());
  ASSERT_EQ(dropped.exit_code, 0) << dropped.err;
  EXPECT_NE(dropped.err.find("no spring holds that load, the machine hangs in its geometry"),
            std::string::npos)
      << dropped.err;
}

struct BadMachine {
  const char* name;
  const char* from;
  const char* to;
  const char* key_path;
};

class BadMachineTest : public CommandTest, public ::testing::WithParamInterface<BadMachine> {};

TEST_P(BadMachineTest, ExitsTwoWithOneLineAndWritesNothing) {
  const BadMachine& bad = GetParam();
  const fs::path scenario =
      WriteVariant(kScenarios / "excavator-arm.yaml", "machine.yaml", bad.from, bad.to);
  const fs::path json = dir_ / "modes.json";
  const CommandResult result = Run("modes " + scenario.string() + " --json " + json.string());
  EXPECT_EQ(result.exit_code, 2) << result.err;
  EXPECT_NE(result.err.find(scenario.string() + ":" + bad.key_path), std::string::npos)
      << result.err;
  EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << result.err;
  EXPECT_FALSE(fs::exists(json));
}

INSTANTIATE_TEST_SUITE_P(
    Contract, BadMachineTest,
    ::testing::Values(
        BadMachine{"UnknownParameter", "\"boom_length_m / 2\"", "\"boom_lenght_m / 2\"",
                   "model.bodies.boom.com_m[0]"},
        BadMachine{"ParentBelow", "parent: boom, joint: {type: revolute, coordinates: [stick]",
                   "parent: bucket, joint: {type: revolute, coordinates: [stick]",
                   "model.bodies.stick.parent"},
        // The boom's body gone (here renamed with its coordinate): the stick's parent is
        // named, not the boom spring that lost its coordinate.
        BadMachine{"ParentMissing",
                   "boom:  {parent: upper, joint: {type: revolute, coordinates: [boom]",
                   "lift:  {parent: upper, joint: {type: revolute, coordinates: [lift]",
                   "model.bodies.stick.parent"},
        // YAML's NaN is a number to YAML: said so, not as a parser's complaint about ".nan ".
        BadMachine{"NanMass", "mass_kg: 1800.0", "mass_kg: .nan",
                   "model.bodies.boom.mass_kg: '.nan' is not finite"},
        BadMachine{"ZeroAxis", "coordinates: [swing], axis: [0, 0, 1]",
                   "coordinates: [swing], axis: [0, 0, 0]", "model.bodies.upper.joint.axis"},
        BadMachine{"TriangleInequality", "[40.0, 700.0, 700.0]", "[40.0, 700.0, 1700.0]",
                   "model.bodies.stick.inertia_kgm2"},
        BadMachine{"SensorKeyOfAbsentUnit", "noise_std_mps2: 2.0e-03", "noise_std_m: 2.0e-03",
                   "sensors.noise_std_m"},
        BadMachine{"SensorUnitOfAnotherChannel", "noise_std_rad: 1.0e-05",
                   "noise_std_rad: {a_bucket_z: 1.0e-3}", "sensors.noise_std_rad.a_bucket_z"}),
    [](const ::testing::TestParamInfo<BadMachine>& param_info) {
      return std::string(param_info.param.name);
    });

}  // namespace
}  // namespace mbid::testing
