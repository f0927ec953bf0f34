// `mbid campaign` as scripts and clusters use it: the same file bit for bit for 1 or 2 workers
// and for 2 MPI ranks, kill -9 in the middle and --resume, failing cases recorded, and bad
// campaign files rejected with one line naming the file and field.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "../app/command_test.h"

namespace {

namespace fs = std::filesystem;

const std::string kScenarios = std::string(MBID_SOURCE_DIR) + "/scenarios";

using mbid::testing::CommandResult;
using mbid::testing::kMbid;
using mbid::testing::ReadText;

// A small campaign on the reference crane, cheap enough for CI: 2 s records at 50 Hz (a few
// CVODES steps per sample), identification on, one value out of range (95 deg, a failing case).
std::string SmallCampaign() {
  return "name: small\nbase: " + kScenarios + R"(/reference-crane-load-drop.yaml
seed: 11
steps: [simulate, identify]
set:
  simulation.duration_s: 2
  sensors.sample_rate_hz: 50
sweep:
  - grid:
      model.configuration.boom_elevation_deg: [10, 40, 95]
  - latin_hypercube:
      samples: 2
      ranges:
        excitation.payload_mass_kg: [400, 1200]
)";
}

class CampaignCliTest : public mbid::testing::CommandTest {};

TEST_F(CampaignCliTest, OneAndTwoWorkersGiveTheSameFileBitForBit) {
  const fs::path campaign = Write("small.yaml", SmallCampaign());
  const CommandResult one =
      Run("campaign " + campaign.string() + " -o " + (dir_ / "one").string() + " --workers 1");
  ASSERT_EQ(one.exit_code, 0) << one.err;  // failing cases do not fail the campaign
  const CommandResult two = Run("campaign " + campaign.string() + " -o " + (dir_ / "two").string() +
                                " --workers 2 --quiet");
  ASSERT_EQ(two.exit_code, 0) << two.err;
  EXPECT_TRUE(two.err.empty()) << two.err;  // --quiet
  const std::string h5 = ReadText(dir_ / "one" / "campaign.h5");
  ASSERT_GT(h5.size(), 10000u) << "6 cases with records and identification";
  EXPECT_TRUE(h5 == ReadText(dir_ / "two" / "campaign.h5")) << "campaign.h5 differs";
  EXPECT_EQ(ReadText(dir_ / "one" / "summary.csv"), ReadText(dir_ / "two" / "summary.csv"));
  // The outcome on standard output; no progress where standard error is no terminal.
  EXPECT_NE(one.out.find("6 cases, 6 run now in "), std::string::npos) << one.out;
  EXPECT_EQ(one.err.find("mbid: campaign"), std::string::npos) << one.err;
  // The per-case files are merged and gone; the summary has one row per case (+ header).
  EXPECT_FALSE(fs::exists(dir_ / "one" / "cases"));
  const std::string csv = ReadText(dir_ / "one" / "summary.csv");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 7);
  EXPECT_NE(csv.find("identified.mode1.frequency_hz"), std::string::npos);
  EXPECT_NE(csv.find("identified.mode1.combination"), std::string::npos);  // empty: a mode
  // Whether the data support each case's modes, beside them (docs/campaigns.md).
  EXPECT_NE(csv.find("identified.modes,identified.reliable,identified.reasons,"), std::string::npos)
      << csv.substr(0, csv.find('\n'));
  // The two 95 deg cases failed with their reason, and only they.
  EXPECT_NE(csv.find("case_0004,4,invalid_input,scenario,"), std::string::npos) << csv;
  EXPECT_NE(csv.find("case_0005,5,invalid_input,scenario,"), std::string::npos) << csv;
  EXPECT_NE(csv.find("(-90, 90)"), std::string::npos) << csv;
  EXPECT_EQ(csv.find(",numerical_failure,"), std::string::npos) << csv;
  EXPECT_TRUE(fs::exists(dir_ / "one" / "report.md"));
}

TEST_F(CampaignCliTest, NumericalFailureIsRecordedAndTheCampaignGoesOn) {
  // One internal step between samples is too few for CVODES: that case fails, the other runs.
  const fs::path campaign =
      Write("steps.yaml", "name: steps\nbase: " + kScenarios + R"(/reference-crane.yaml
steps: [simulate]
set: {simulation.duration_s: 1, sensors.sample_rate_hz: 20}
sweep:
  - list:
      simulation.integrator.max_steps: [100000, 1]
)");
  const CommandResult result =
      Run("campaign " + campaign.string() + " -o " + (dir_ / "out").string());
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const std::string csv = ReadText(dir_ / "out" / "summary.csv");
  EXPECT_NE(csv.find("case_0000,0,ok,"), std::string::npos) << csv;
  EXPECT_NE(csv.find("case_0001,1,numerical_failure,simulate,"), std::string::npos) << csv;
  EXPECT_NE(csv.find("CVODES"), std::string::npos) << csv;
  EXPECT_NE(result.out.find(", 1 failed (see summary.csv)"), std::string::npos) << result.out;
}

// Starts mbid in the background and kills it with SIGKILL as soon as `ready` holds.
bool RunAndKill(const std::vector<std::string>& arguments, const std::function<bool()>& ready) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int null = ::open("/dev/null", O_WRONLY);
    ::dup2(null, STDOUT_FILENO);
    ::dup2(null, STDERR_FILENO);
    std::vector<char*> argv{const_cast<char*>(kMbid.c_str())};
    for (const std::string& argument : arguments)
      argv.push_back(const_cast<char*>(argument.c_str()));
    argv.push_back(nullptr);
    ::execv(kMbid.c_str(), argv.data());
    ::_exit(127);
  }
  // Poll every 2 ms for at most 60 s (a loaded CI machine is slow, never that slow).
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  bool killed = false;
  while (std::chrono::steady_clock::now() < deadline) {
    int status = 0;
    if (::waitpid(pid, &status, WNOHANG) == pid) return false;  // finished before the kill
    if (ready()) {
      ::kill(pid, SIGKILL);
      killed = true;
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  return killed && WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL;
}

int CountCommitted(const fs::path& cases) {
  int count = 0;
  std::error_code error;
  for (const auto& entry : fs::directory_iterator(cases, error)) {
    const std::string name = entry.path().filename().string();
    if (entry.path().extension() == ".h5" && name.find("unsealed") == std::string::npos) ++count;
  }
  return count;
}

TEST_F(CampaignCliTest, KillNineThenResumeFinishesTheRestAndGivesTheSameFile) {
  // 12 load drops of 8 s at 100 Hz (about 70 ms each): after the second commit the other
  // ten take more than half a second, time enough to kill in the middle.
  const fs::path campaign =
      Write("kill.yaml", "name: kill\nbase: " + kScenarios + R"(/reference-crane-load-drop.yaml
steps: [simulate]
sweep:
  - grid:
      model.configuration.boom_elevation_deg: [5, 15, 25, 35, 45, 55]
  - repeat: 2
)");
  const fs::path killed = dir_ / "killed";
  ASSERT_TRUE(RunAndKill({"campaign", campaign.string(), "-o", killed.string(), "--workers", "2"},
                         [&] { return CountCommitted(killed / "cases") >= 2; }))
      << "the campaign ended before it could be killed";
  const int committed = CountCommitted(killed / "cases");
  EXPECT_GE(committed, 2);
  EXPECT_LT(committed, 12);
  EXPECT_FALSE(fs::exists(killed / "campaign.h5"));  // never a partial campaign file

  // A power cut after a commit can leave zeroed blocks behind a committed name (case files are
  // not fsynced): zero 4 KiB in the middle of one, keeping its size and name.
  fs::path damaged;
  for (const auto& entry : fs::directory_iterator(killed / "cases")) {
    const std::string name = entry.path().filename().string();
    if (name.find("unsealed") == std::string::npos && name.find(".tmp-") == std::string::npos) {
      damaged = entry.path();
      break;
    }
  }
  ASSERT_FALSE(damaged.empty());
  const auto size = fs::file_size(damaged);
  ASSERT_GT(size, 8192u);
  {
    std::fstream file(damaged, std::ios::in | std::ios::out | std::ios::binary);
    file.seekp(static_cast<std::streamoff>(size / 2));
    const std::string zeros(4096, '\0');
    file.write(zeros.data(), static_cast<std::streamsize>(zeros.size()));
  }
  const std::string damaged_name = damaged.filename().string();  // "<id>.<crc>.h5"
  const std::string damaged_id = damaged_name.substr(0, damaged_name.find('.'));

  // Without --resume the folder is refused; with it the rest runs, the damaged case again.
  EXPECT_EQ(Run("campaign " + campaign.string() + " -o " + killed.string()).exit_code, 2);
  const CommandResult resumed = Run("campaign " + campaign.string() + " -o " + killed.string() +
                                    " --resume --workers 2 --progress");
  ASSERT_EQ(resumed.exit_code, 0) << resumed.err;
  EXPECT_NE(resumed.err.find("resuming: "), std::string::npos) << resumed.err;
  EXPECT_NE(resumed.err.find("case " + damaged_id + ": damaged file (CRC-32"), std::string::npos)
      << resumed.err;
  EXPECT_NE(resumed.err.find("computed again"), std::string::npos) << resumed.err;

  const CommandResult whole =
      Run("campaign " + campaign.string() + " -o " + (dir_ / "whole").string() + " --quiet");
  ASSERT_EQ(whole.exit_code, 0) << whole.err;
  EXPECT_TRUE(ReadText(killed / "campaign.h5") == ReadText(dir_ / "whole" / "campaign.h5"))
      << "the resumed campaign differs from an uninterrupted one";
  // Resuming a finished campaign does nothing.
  const CommandResult again =
      Run("campaign " + campaign.string() + " -o " + killed.string() + " --resume");
  EXPECT_EQ(again.exit_code, 0);
  EXPECT_NE(again.out.find("already complete"), std::string::npos) << again.out;
}

// A folder as a crash can leave it: the manifest, a committed case file cut short by a lost
// write (a power cut after the rename: its CRC-32 no longer matches), an unsealed case and a
// temporary of a case being written. The resume redoes those cases and gives the uninterrupted
// file. Files of the user's are never removed: a note in cases/ (the resume deleted everything
// else of no case's name), one named like a temporary but not one of this program's, and one
// beside the results; cases/ stays only because the note is in it.
TEST_F(CampaignCliTest, ResumeRedoesTemporariesAndDamagedCaseFilesAndLeavesTheUsersFiles) {
  const fs::path campaign = Write("small.yaml", SmallCampaign());
  const fs::path out = dir_ / "out";
  ASSERT_EQ(
      Run("campaign " + campaign.string() + " -o " + (dir_ / "whole").string() + " -q").exit_code,
      0);
  fs::create_directories(out / "cases");
  fs::copy_file(dir_ / "whole" / "campaign.json", out / "campaign.json");
  Write("out/cases/case_0001.0badc0de.h5", "HDF5 but cut short");
  Write("out/cases/case_0002.unsealed.h5", "a case killed before its rename");
  Write("out/cases/case_0003.unsealed.h5.tmp-12345-0", "half a case");
  Write("out/cases/notes.txt", "mine");
  Write("out/cases/plan.tmp-draft", "mine too");
  Write("out/readme.md", "and mine");
  // A figure's temporary and its scratch files, of a process killed while drawing it (a
  // re-audit found the scratch files left after the resume).
  for (const char* scratch : {"", ".dat", ".gp", ".log"}) {
    Write(std::string("out/modes.png.tmp-12345-7") + scratch, "a figure being drawn");
  }
  const CommandResult result =
      Run("campaign " + campaign.string() + " -o " + out.string() + " --resume");
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_NE(result.err.find("case case_0001: damaged file"), std::string::npos) << result.err;
  EXPECT_TRUE(ReadText(out / "campaign.h5") == ReadText(dir_ / "whole" / "campaign.h5"));
  EXPECT_EQ(ReadText(out / "cases" / "notes.txt"), "mine");
  EXPECT_EQ(ReadText(out / "cases" / "plan.tmp-draft"), "mine too");
  EXPECT_EQ(ReadText(out / "readme.md"), "and mine");
  std::vector<std::string> left;
  for (const auto& entry : fs::directory_iterator(out / "cases")) {
    left.push_back(entry.path().filename().string());
  }
  std::sort(left.begin(), left.end());
  EXPECT_EQ(left, (std::vector<std::string>{"notes.txt", "plan.tmp-draft"}));
  for (const auto& entry : fs::directory_iterator(out)) {
    EXPECT_EQ(entry.path().filename().string().find(".tmp-"), std::string::npos) << entry.path();
  }
}

// model.parameters is a free map: a misspelt swept parameter became one more that nothing
// used, and the "sweep" gave identical cases. Refused with the declared names (exit 2, no
// folder); spelt right, the cases differ.
TEST_F(CampaignCliTest, ASweptParameterMustBeOneTheBaseDeclares) {
  const auto sweep = [&](const std::string& name, const std::string& out) {
    const fs::path campaign =
        Write(name + ".yaml", "name: lengths\nbase: " + kScenarios +
                                  "/reference-crane-description.yaml\nsteps: [modes]\nsweep:\n"
                                  "  - grid:\n      model.parameters." +
                                  name + ": [9.0, 11.0]\n");
    return Run("campaign " + campaign.string() + " -o " + (dir_ / out).string() + " -q");
  };
  const CommandResult typo = sweep("boom_lenght_m", "typo");
  EXPECT_EQ(typo.exit_code, 2) << typo.err;
  EXPECT_NE(typo.err.find("boom_lenght_m.yaml:sweep[0].grid.model.parameters.boom_lenght_m: "
                          "'boom_lenght_m' is not a parameter of the base scenario's model"),
            std::string::npos)
      << typo.err;
  EXPECT_NE(typo.err.find("did you mean 'boom_length_m'?"), std::string::npos) << typo.err;
  EXPECT_FALSE(fs::exists(dir_ / "typo"));
  const CommandResult right = sweep("boom_length_m", "right");
  ASSERT_EQ(right.exit_code, 0) << right.err;
  // The first mode's frequency (column exact.mode1.frequency_hz) of the two cases: a 10 m boom
  // 9 or 11 m long, the crane's first mode 0.64 and 0.52 Hz (measured).
  std::istringstream lines(ReadText(dir_ / "right" / "summary.csv"));
  std::string header, row;
  std::getline(lines, header);
  std::vector<std::string> columns;
  for (std::stringstream cells(header); std::getline(cells, row, ',');) columns.push_back(row);
  const auto column = std::find(columns.begin(), columns.end(), "exact.mode1.frequency_hz");
  ASSERT_NE(column, columns.end()) << header;
  std::vector<double> first_mode;
  while (std::getline(lines, row)) {
    std::stringstream cells(row);
    std::string cell;
    for (auto k = columns.begin(); k <= column; ++k) std::getline(cells, cell, ',');
    first_mode.push_back(std::stod(cell));
  }
  ASSERT_EQ(first_mode.size(), 2u);
  EXPECT_GT(first_mode[0] - first_mode[1], 0.05);  // a longer boom swings slower
}

TEST_F(CampaignCliTest, AFolderKilledBeforeItsManifestStartsAfresh) {
  // Killed after creating the folder and before committing the manifest: an empty cases/ and
  // a temporary of the manifest. Neither a fresh start nor --resume may refuse it.
  const fs::path campaign = Write("small.yaml", SmallCampaign());
  ASSERT_EQ(
      Run("campaign " + campaign.string() + " -o " + (dir_ / "whole").string() + " -q").exit_code,
      0);
  for (const std::string flag : {"", " --resume"}) {
    const fs::path out = dir_ / ("half" + std::to_string(flag.size()));
    fs::create_directories(out / "cases");
    Write(fs::relative(out, dir_).string() + "/campaign.json.tmp-4242-0", "{\"form");
    const CommandResult result =
        Run("campaign " + campaign.string() + " -o " + out.string() + " -q" + flag);
    ASSERT_EQ(result.exit_code, 0) << flag << ": " << result.err;
    EXPECT_TRUE(ReadText(out / "campaign.h5") == ReadText(dir_ / "whole" / "campaign.h5"));
  }
  // Anything else in the folder is the user's: refused, untouched.
  const fs::path other = dir_ / "other";
  fs::create_directories(other / "cases");
  Write("other/notes.txt", "mine");
  const CommandResult refused = Run("campaign " + campaign.string() + " -o " + other.string());
  EXPECT_EQ(refused.exit_code, 2) << refused.err;
  EXPECT_EQ(ReadText(other / "notes.txt"), "mine");
}

TEST_F(CampaignCliTest, ResumeRefusesADifferentCampaign) {
  const fs::path campaign = Write("small.yaml", SmallCampaign());
  ASSERT_EQ(
      Run("campaign " + campaign.string() + " -o " + (dir_ / "out").string() + " -q").exit_code, 0);
  std::string changed = SmallCampaign();
  changed.replace(changed.find("seed: 11"), 8, "seed: 12");
  Write("small.yaml", changed);
  const CommandResult result =
      Run("campaign " + campaign.string() + " -o " + (dir_ / "out").string() + " --resume");
  EXPECT_EQ(result.exit_code, 2) << result.err;
  EXPECT_NE(result.err.find("campaign.json:fingerprint"), std::string::npos) << result.err;
}

TEST_F(CampaignCliTest, TwoMpiRanksGiveTheSameFileAsOneProcess) {
#ifndef MBID_MPIEXEC
  GTEST_SKIP() << "mbid was built without MPI (OpenMPI not found by CMake): no MPI test";
#else
  if (std::system("command -v " MBID_MPIEXEC " > /dev/null 2>&1") != 0) {
    GTEST_SKIP() << MBID_MPIEXEC " not found: no MPI test";
  }
  // Root in containers, 2 ranks on a machine that may have fewer cores: allowed for the test
  // only (users on clusters need none of this).
  ::setenv("OMPI_ALLOW_RUN_AS_ROOT", "1", 1);
  ::setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1", 1);
  ::setenv("OMPI_MCA_rmaps_base_oversubscribe", "1", 1);
  const fs::path campaign = Write("small.yaml", SmallCampaign());
  const CommandResult local =
      Run("campaign " + campaign.string() + " -o " + (dir_ / "local").string() + " -q");
  ASSERT_EQ(local.exit_code, 0) << local.err;
  const CommandResult mpi =
      Run("campaign " + campaign.string() + " -o " + (dir_ / "mpi").string() + " --progress",
          std::string(MBID_MPIEXEC) + " -n 2 ");
  ASSERT_EQ(mpi.exit_code, 0) << mpi.err;
  EXPECT_NE(mpi.err.find("on 2 ranks"), std::string::npos) << mpi.err;
  EXPECT_TRUE(ReadText(dir_ / "local" / "campaign.h5") == ReadText(dir_ / "mpi" / "campaign.h5"))
      << "the MPI campaign file differs from the local one";
  EXPECT_EQ(ReadText(dir_ / "local" / "summary.csv"), ReadText(dir_ / "mpi" / "summary.csv"));
#endif
}

struct BadCampaign {
  const char* name;
  const char* from;  // text of SmallCampaign() to replace ("" = append `to`)
  const char* to;
  const char* source;    // the file the message must name: "campaign" or "base"
  const char* field;     // the field it must name
  const char* expected;  // a phrase it must contain
};

void PrintTo(const BadCampaign& bad, std::ostream* os) { *os << bad.name; }

const BadCampaign kBadCampaigns[] = {
    {"UnknownKeySuggestsClosest", "seed: 11", "sed: 11", "campaign", "sed", "seed"},
    {"UnknownStep", "steps: [simulate, identify]", "steps: [simulate, identfy]", "campaign",
     "steps[1]", "identify"},
    {"SweptKeyTypo", "boom_elevation_deg: [10", "boom_elevaton_deg: [10", "campaign",
     "sweep[0].grid.model.configuration.boom_elevaton_deg", "boom_elevation_deg"},
    {"SweptKeyWithoutUnit", "excitation.payload_mass_kg: [400", "excitation.payload_mass: [400",
     "campaign", "sweep[1].latin_hypercube.ranges.excitation.payload_mass", "payload_mass_kg"},
    {"UnknownFactor", "  - grid:", "  - grids:", "campaign", "sweep[0].grids", "grid"},
    {"EmptyGridValues", "[10, 40, 95]", "[]", "campaign",
     "sweep[0].grid.model.configuration.boom_elevation_deg", "list of values"},
    {"ReversedRange", "[400, 1200]", "[1200, 400]", "campaign",
     "sweep[1].latin_hypercube.ranges.excitation.payload_mass_kg", "low < high"},
    {"ListLengthsDiffer",
     "  - latin_hypercube:\n      samples: 2\n      ranges:\n        "
     "excitation.payload_mass_kg: [400, 1200]",
     "  - list:\n      excitation.payload_mass_kg: [400, 1200]\n      sensors.seed: [1, 2, 3]",
     "campaign", "sweep[1].list.sensors.seed", "as many values"},
    {"SetValueInvalid", "  sensors.sample_rate_hz: 50", "  sensors.sample_rate_hz: -50", "campaign",
     "set.sensors.sample_rate_hz", "> 0"},
    {"KeyBothSetAndSwept", "  sensors.sample_rate_hz: 50",
     "  model.configuration.boom_elevation_deg: 20", "campaign",
     "set.model.configuration.boom_elevation_deg", "either in set or in the sweep"},
    {"MissingBaseFile", "/reference-crane-load-drop.yaml", "/no-such-scenario.yaml", "campaign",
     "base", "relative paths start at the campaign file"},
    {"LawsVariableNotSwept", "",
     "study: laws\nlaws:\n  variables: [model.gravity_mps2]\n  "
     "quantities: [truth.c_theta]\n",
     "campaign", "laws.variables", "swept keys"},
    {"LawsNeedUpdate", "",
     "study: laws\nlaws:\n  variables: "
     "[model.configuration.boom_elevation_deg]\n  quantities: [updated.c_theta]\n",
     "campaign", "laws.quantities", "update"},
    // Counted before anything is built: two billion copies would allocate tens of gigabytes.
    {"RepeatBeyondTheCap", "  - grid:", "  - repeat: 2000000000\n  - grid:", "campaign",
     "sweep[0].repeat", "1 to 1000000"},
    {"GridBeyondTheCap", "[10, 40, 95]",
     "[10, 40, 95]\n      model.configuration.slew_deg: [0, 1, 2, 3, 4, 5, 6, 7, 8, 9]\n"
     "      model.gravity_mps2: [9.8, 9.81, 9.82, 9.83, 9.84, 9.85, 9.86, 9.87, 9.88, 9.89]\n"
     "      sensors.seed: [1, 2, 3, 4, 5, 6, 7, 8, 9, 10]\n"
     "      sensors.noise_std_rad: [1, 2, 3, 4, 5, 6, 7, 8, 9, 10]\n"
     "      excitation.payload_mass_kg: [1, 2, 3, 4, 5, 6, 7, 8, 9, 10]\n"
     "      simulation.duration_s: [1, 2, 3, 4, 5, 6, 7, 8, 9, 10]",
     "campaign", "sweep[0].grid", "at most 1000000 cases"},
    {"DamperSizingWithSweep", "",
     "study: damper_sizing\ndamper_sizing:\n  joints: [theta]\n  "
     "range_Nms_per_rad: [1.0e4, 1.0e6]\n  targets: {min_damping_ratio: 0.1}\n",
     "campaign", "sweep", "no sweep"},
};

class BadCampaignTest : public CampaignCliTest,
                        public ::testing::WithParamInterface<BadCampaign> {};

TEST_P(BadCampaignTest, FailsWithOneLineNamingTheFileAndField) {
  const BadCampaign& bad = GetParam();
  std::string text = SmallCampaign();
  if (std::string(bad.from).empty()) {
    text += bad.to;
  } else {
    const size_t at = text.find(bad.from);
    ASSERT_NE(at, std::string::npos) << bad.from;
    text.replace(at, std::string(bad.from).size(), bad.to);
  }
  const fs::path campaign = Write("bad.yaml", text);
  const fs::path out = dir_ / "out";
  const CommandResult result = Run("campaign " + campaign.string() + " -o " + out.string());
  EXPECT_EQ(result.exit_code, 2) << result.err;  // invalid input (interfaces.md)
  const std::string source = std::string(bad.source) == "campaign"
                                 ? campaign.string()
                                 : kScenarios + "/reference-crane-load-drop.yaml";
  EXPECT_EQ(result.err.rfind("mbid: error: " + source + ":" + bad.field + ":", 0), 0u)
      << result.err;
  EXPECT_NE(result.err.find("expected"), std::string::npos) << result.err;
  EXPECT_NE(result.err.find(bad.expected), std::string::npos) << result.err;
  EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << result.err;
  EXPECT_FALSE(fs::exists(out)) << "nothing is written for a bad campaign";
}

INSTANTIATE_TEST_SUITE_P(Rules, BadCampaignTest, ::testing::ValuesIn(kBadCampaigns),
                         [](const ::testing::TestParamInfo<BadCampaign>& param_info) {
                           return std::string(param_info.param.name);
                         });

TEST_F(CampaignCliTest, BadFlagsAndFoldersAreInvalidInput) {
  const fs::path campaign = Write("small.yaml", SmallCampaign());
  EXPECT_EQ(Run("campaign " + campaign.string() + " -o " + (dir_ / "o").string() + " --workers 0")
                .exit_code,
            2);
  EXPECT_EQ(Run("campaign " + campaign.string()).exit_code, 2);  // -o is required
  fs::create_directories(dir_ / "not-empty");
  Write("not-empty/file.txt", "x");
  const CommandResult result =
      Run("campaign " + campaign.string() + " -o " + (dir_ / "not-empty").string());
  EXPECT_EQ(result.exit_code, 2) << result.err;
  EXPECT_NE(result.err.find("not a campaign folder"), std::string::npos) << result.err;
  const CommandResult missing =
      Run("campaign " + (dir_ / "nope.yaml").string() + " -o " + (dir_ / "o").string());
  EXPECT_EQ(missing.exit_code, 2) << missing.err;
  // --overwrite, which every command accepts, was ignored here: a campaign is resumed, never
  // replaced, and the message says so (exit 2, nothing written).
  const CommandResult overwrite =
      Run("campaign " + campaign.string() + " -o " + (dir_ / "ow").string() + " --overwrite");
  EXPECT_EQ(overwrite.exit_code, 2) << overwrite.err;
  EXPECT_NE(overwrite.err.find("--overwrite: a campaign folder is never replaced; expected "
                               "--resume"),
            std::string::npos)
      << overwrite.err;
  EXPECT_FALSE(fs::exists(dir_ / "ow"));
  // --threads, as structure's, is --workers (it was "not expected: 0 --threads"), and its range
  // is said in the numbers it has (not "0 to 1.8e308" written out).
  const CommandResult threads =
      Run("campaign " + campaign.string() + " -o " + (dir_ / "t").string() + " --threads 0");
  EXPECT_EQ(threads.exit_code, 2);
  EXPECT_NE(threads.err.find("--workers: Value 0 not in range 1 to 1048576"), std::string::npos)
      << threads.err;
}

}  // namespace
