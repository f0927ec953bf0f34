// What mbid may do to the user's files: an existing folder is never removed (only an earlier
// run's results, and only with --overwrite), a scenario's name never chooses where results go
// nor runs a command, SIGTERM/SIGINT and kill -9 leave no staging folders, and absurd worker
// counts are refused.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "command_test.h"

namespace {

using mbid::testing::CommandResult;
using mbid::testing::kMbid;
using mbid::testing::ReadText;
namespace fs = std::filesystem;

const std::string kReference = std::string(MBID_SOURCE_DIR) + "/scenarios/reference-crane.yaml";

// `text` as one word for /bin/sh, whatever it holds.
std::string ShellQuote(const std::string& text) {
  std::string quoted = "'";
  for (const char c : text) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

std::set<std::string> Entries(const fs::path& folder) {
  std::set<std::string> names;
  for (const auto& entry : fs::directory_iterator(folder)) {
    names.insert(entry.path().filename().string());
  }
  return names;
}

// Figures the report links that exist as PNG files.
int DrawnFigures(const fs::path& out) {
  const std::string report = ReadText(out / "report.md");
  int figures = 0;
  for (size_t at = report.find("]("); at != std::string::npos; at = report.find("](", at + 2)) {
    const std::string name = report.substr(at + 2, report.find(')', at) - at - 2);
    if (ReadText(out / name).substr(1, 3) == "PNG") ++figures;
  }
  return figures;
}

class OutputSafetyTest : public mbid::testing::CommandTest {
 protected:
  void SetUp() override {
    CommandTest::SetUp();
    work_ = dir_ / "work";
    fs::create_directories(work_);
  }

  // The reference scenario, 5 s instead of 8 for speed (as cli_test's run), with `from`
  // replaced by `to`.
  fs::path Scenario(const std::string& from = "", const std::string& to = "",
                    const std::string& duration = "5") const {
    const fs::path path = CommandTest::WriteVariant(kReference, "scenario.yaml", from, to);
    std::string text = ReadText(path);
    text.replace(text.find("  duration_s: 8"), 15, "  duration_s: " + duration);
    std::ofstream(path) << text;
    return path;
  }

  // `mbid run SCENARIO <arguments>` from inside work_ (where results/ goes).
  CommandResult RunIn(const fs::path& scenario, const std::string& arguments) const {
    return Run("run " + ShellQuote(scenario.string()) + " --quiet " + arguments,
               "cd " + ShellQuote(work_.string()) + " && ");
  }

  fs::path work_;
};

TEST_F(OutputSafetyTest, AForeignFolderIsRefusedAndUntouched) {
  const fs::path scenario = Scenario();
  const fs::path mine = work_ / "mine";
  fs::create_directories(mine);
  Write("work/mine/thesis.tex", "years of work");
  for (const std::string flags : {"", " --overwrite"}) {
    const CommandResult result = RunIn(scenario, "-o " + mine.string() + flags);
    EXPECT_EQ(result.exit_code, 2) << result.err;  // invalid input (interfaces.md)
    EXPECT_EQ(result.err.rfind("mbid: error: " + mine.string() + ": ", 0), 0u) << result.err;
    EXPECT_NE(result.err.find("another output folder"), std::string::npos) << result.err;
    EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << result.err;
    EXPECT_EQ(Entries(mine), std::set<std::string>{"thesis.tex"});
    EXPECT_EQ(ReadText(mine / "thesis.tex"), "years of work");
    EXPECT_EQ(Entries(work_), std::set<std::string>{"mine"});  // no staging folder left
  }
}

TEST_F(OutputSafetyTest, DotAndDotDotAreRefusedAndUntouched) {
  const fs::path scenario = Scenario();
  Write("work/data.csv", "1,2");
  for (const std::string out : {".", "..", "./", "results/.."}) {
    const CommandResult result = RunIn(scenario, "-o " + out + " --overwrite");
    EXPECT_EQ(result.exit_code, 2) << out << ": " << result.err;
    EXPECT_EQ(ReadText(work_ / "data.csv"), "1,2") << out;
  }
  // results/ may be made (the parent of "results/.."), nothing else.
  std::set<std::string> left = Entries(work_);
  left.erase("results");
  EXPECT_EQ(left, std::set<std::string>{"data.csv"});
  EXPECT_EQ(Entries(dir_), (std::set<std::string>{"work", "scenario.yaml"}));
}

TEST_F(OutputSafetyTest, AnEarlierRunIsReplacedOnlyWithOverwriteAndWholly) {
  const fs::path out = work_ / "out";
  ASSERT_EQ(RunIn(Scenario(), "-o " + out.string()).exit_code, 0);
  // As today's version wrote it (no marker): recognised by run.h5 and summary.json.
  fs::remove(out / ".mbid-output");
  const std::set<std::string> before = Entries(out);
  const std::string summary_before = ReadText(out / "summary.json");

  const fs::path shorter = Scenario("", "", "4");  // a different result: 4 s instead of 5
  const CommandResult refused = RunIn(shorter, "-o " + out.string());
  EXPECT_EQ(refused.exit_code, 2) << refused.err;
  EXPECT_NE(refused.err.find("--overwrite"), std::string::npos) << refused.err;
  EXPECT_NE(refused.err.find(out.string()), std::string::npos) << refused.err;
  EXPECT_EQ(Entries(out), before);
  EXPECT_EQ(ReadText(out / "summary.json"), summary_before);

  const CommandResult replaced = RunIn(shorter, "-o " + out.string() + " --overwrite");
  ASSERT_EQ(replaced.exit_code, 0) << replaced.err;
  const auto summary = nlohmann::json::parse(ReadText(out / "summary.json"));
  const auto old_summary = nlohmann::json::parse(summary_before);
  // 100 Hz sampling (reference-crane.yaml): 4 s and 5 s give different sample counts.
  EXPECT_LT(summary["simulation"]["samples"].get<int>(),
            old_summary["simulation"]["samples"].get<int>());
  EXPECT_TRUE(fs::exists(out / ".mbid-output"));
  EXPECT_EQ(Entries(work_), std::set<std::string>{"out"});  // old results and staging gone

  // An earlier run with the user's own file in it is not an mbid folder any more.
  Write("work/out/notes.txt", "mine");
  const CommandResult kept = RunIn(shorter, "-o " + out.string() + " --overwrite");
  EXPECT_EQ(kept.exit_code, 2) << kept.err;
  EXPECT_EQ(ReadText(out / "notes.txt"), "mine");
  EXPECT_TRUE(fs::exists(out / "run.h5"));
}

struct NameCase {
  const char* test_name;
  const char* name;    // the scenario's name (YAML single-quoted)
  const char* folder;  // the folder it gives under results/
};

// Names that once chose the place ("..", "a/b") or ran a command through the shell or gnuplot.
const NameCase kNames[] = {
    {"DotDot", "..", "_."},
    {"Dot", ".", "_"},
    {"Slash", "a/b", "a_b"},
    {"Semicolons", "crane;touch X;x", "crane;touch X;x"},
    {"DollarParenthesis", "$(touch Y)", "$(touch Y)"},
    {"Backquotes", "`touch Z`", "`touch Z`"},
    {"SpaceAndUnicode", "Kran \u00e4 \u8d77\u91cd\u673a", "Kran \u00e4 \u8d77\u91cd\u673a"},
};

class ScenarioNameTest : public OutputSafetyTest, public ::testing::WithParamInterface<NameCase> {};

TEST_P(ScenarioNameTest, ResultsGoUnderResultsAndNothingRuns) {
  const NameCase& name = GetParam();
  const fs::path scenario =
      Scenario("name: reference-crane", std::string("name: '") + name.name + "'");
  const CommandResult result = RunIn(scenario, "");
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_EQ(Entries(work_), std::set<std::string>{"results"});  // no X, Y or Z
  EXPECT_EQ(Entries(dir_), (std::set<std::string>{"work", "scenario.yaml"}));
  EXPECT_EQ(Entries(work_ / "results"), std::set<std::string>{name.folder});
  const fs::path out = work_ / "results" / name.folder;
  EXPECT_EQ(nlohmann::json::parse(ReadText(out / "summary.json"))["scenario"], name.name);
  EXPECT_GE(DrawnFigures(out), 9);  // as cli_test's run: every figure of the report is drawn
}

INSTANTIATE_TEST_SUITE_P(Names, ScenarioNameTest, ::testing::ValuesIn(kNames),
                         [](const ::testing::TestParamInfo<NameCase>& param_info) {
                           return std::string(param_info.param.test_name);
                         });

TEST_F(OutputSafetyTest, AnOutputThatNamesAnInputOrAnotherOutputIsRefused) {
  const fs::path scenario = Scenario("", "", "2");
  const std::string h5 = (work_ / "rec.h5").string(), csv = (work_ / "rec.csv").string();
  ASSERT_EQ(
      Run("simulate " + scenario.string() + " --quiet -o " + h5 + " --export " + csv).exit_code, 0);
  const std::string csv_text = ReadText(csv), h5_bytes = ReadText(h5);
  const std::string scenario_text = ReadText(scenario);
  // The summary written over the record it summarises.
  CommandResult result = Run("identify " + csv + " --quiet --json " + csv);
  EXPECT_EQ(result.exit_code, 2) << result.err;
  EXPECT_NE(result.err.find(csv + ": the --json output is the input DATA " + csv),
            std::string::npos)
      << result.err;
  EXPECT_EQ(ReadText(csv), csv_text);
  // The HDF5 output over its input: by the same name, another spelling and a link.
  fs::create_symlink(h5, work_ / "alias.h5");
  for (const std::string& name :
       {h5, (work_ / "." / "rec.h5").string(), (work_ / "alias.h5").string()}) {
    result = Run("identify " + h5 + " --quiet -o " + name);
    EXPECT_EQ(result.exit_code, 2) << name << ": " << result.err;
    EXPECT_EQ(ReadText(h5), h5_bytes) << name;
  }
  // Two outputs of one name: one would be lost; nothing is written.
  const std::string both = (work_ / "both.h5").string();
  result = Run("identify " + h5 + " --quiet -o " + both + " --json " + both);
  EXPECT_EQ(result.exit_code, 2) << result.err;
  EXPECT_NE(result.err.find("is also the output of -o"), std::string::npos) << result.err;
  EXPECT_FALSE(fs::exists(both));
  // The scenario is an input too, and so are update's records.
  result = Run("simulate " + scenario.string() + " --quiet -o " + scenario.string());
  EXPECT_EQ(result.exit_code, 2) << result.err;
  EXPECT_EQ(ReadText(scenario), scenario_text);
  result = Run("update " + scenario.string() + " " + h5 + " --quiet --json " + h5);
  EXPECT_EQ(result.exit_code, 2) << result.err;
  EXPECT_EQ(ReadText(h5), h5_bytes);
  // Names of their own still work.
  result = Run("identify " + csv + " --quiet --json " + (work_ / "modes.json").string());
  EXPECT_EQ(result.exit_code, 0) << result.err;
}

TEST_F(OutputSafetyTest, OutputPathsWithShellCharactersWorkAndRunNothing) {
  // Space, ';', $(...), backquotes, a quote (gnuplot's string quoting) and Unicode at once.
  const fs::path out = work_ / "out dir;$(touch W)`touch V`'q' \u00e4";
  const CommandResult result = RunIn(Scenario(), "-o " + ShellQuote(out.string()));
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_EQ(Entries(work_), std::set<std::string>{out.filename().string()});  // no W, no V
  EXPECT_EQ(Entries(dir_), (std::set<std::string>{"work", "scenario.yaml"}));
  EXPECT_GE(DrawnFigures(out), 9);  // as above
}

// The pid of a process that has ended (and been reaped): kill(pid, 0) gives ESRCH.
pid_t DeadPid() {
  const pid_t pid = ::fork();
  if (pid == 0) ::_exit(0);
  ::waitpid(pid, nullptr, 0);
  return pid;
}

TEST_F(OutputSafetyTest, StagingFoldersOfDeadRunsAreCleaned) {
  const fs::path results = work_ / "results";
  const std::string stale = ".reference-crane.tmp-" + std::to_string(DeadPid());
  fs::create_directories(results / stale);
  Write("work/results/" + stale + "/.mbid-output", R"({"format": "mbid-output", "kind": "run"})");
  Write("work/results/" + stale + "/run.h5.tmp-1-0", "half a file");
  // A failing run (CVODES gives up at once, as in cli_test) still cleans up on its way.
  const fs::path scenario =
      Scenario("absolute_tolerance: 1.0e-10}", "absolute_tolerance: 1.0e-10, max_steps: 5}");
  const CommandResult result = RunIn(scenario, "");
  EXPECT_EQ(result.exit_code, 3) << result.err;  // numerical failure
  EXPECT_TRUE(Entries(results).empty());
}

// Starts `mbid run` in the background, sends `signal` once `ready` holds, and returns the wait
// status.
int RunAndSignal(const std::vector<std::string>& arguments, int signal,
                 const std::function<bool()>& ready) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int null = ::open("/dev/null", O_WRONLY);
    ::dup2(null, STDOUT_FILENO);
    ::dup2(null, STDERR_FILENO);
    // As from a terminal: the test runner may have started us with SIGINT ignored.
    std::signal(SIGINT, SIG_DFL);
    std::signal(SIGTERM, SIG_DFL);
    std::vector<char*> argv{const_cast<char*>(kMbid.c_str())};
    for (const std::string& argument : arguments) {
      argv.push_back(const_cast<char*>(argument.c_str()));
    }
    argv.push_back(nullptr);
    ::execv(kMbid.c_str(), argv.data());
    ::_exit(127);
  }
  // Poll every 2 ms for at most 60 s (a loaded CI machine is slow, never that slow).
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (std::chrono::steady_clock::now() < deadline) {
    int status = 0;
    if (::waitpid(pid, &status, WNOHANG) == pid) return status;  // finished before the signal
    if (ready()) {
      ::kill(pid, signal);
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  return status;
}

// The staging folder's entries (none if it does not exist yet).
std::set<std::string> StagingEntries(const fs::path& parent) {
  std::error_code error;
  for (const auto& entry : fs::directory_iterator(parent, error)) {
    if (entry.path().filename().string().rfind(".out.tmp-", 0) == 0) {
      std::set<std::string> names;
      for (const auto& inner : fs::directory_iterator(entry.path(), error)) {
        names.insert(inner.path().filename().string());
      }
      return names;
    }
  }
  return {};
}

TEST_F(OutputSafetyTest, SigtermDuringTheReportLeavesNoStagingFolder) {
  const fs::path out = work_ / "out";
  const fs::path scenario = Scenario();
  // Late in the run: the staging folder holds more than its marker (run.h5 or figures), and
  // gnuplot may be writing into it.
  const int status = RunAndSignal({"run", scenario.string(), "-o", out.string()}, SIGTERM,
                                  [&] { return StagingEntries(work_).size() > 1; });
  ASSERT_TRUE(WIFSIGNALED(status)) << "exit status " << WEXITSTATUS(status);
  EXPECT_EQ(WTERMSIG(status), SIGTERM);  // the parent sees the signal, as without clean-up
  EXPECT_TRUE(Entries(work_).empty());
}

TEST_F(OutputSafetyTest, SigintAtTheStartLeavesNoStagingFolder) {
  const fs::path out = work_ / "out";
  const fs::path scenario = Scenario();
  const int status = RunAndSignal({"run", scenario.string(), "-o", out.string()}, SIGINT,
                                  [&] { return !StagingEntries(work_).empty(); });
  ASSERT_TRUE(WIFSIGNALED(status)) << "exit status " << WEXITSTATUS(status);
  EXPECT_EQ(WTERMSIG(status), SIGINT);
  EXPECT_TRUE(Entries(work_).empty());
}

// `mbid run ... 2>&1 | true`: the progress's reader is gone at once. Before, SIGPIPE ended the
// run and left its staging folder; now the writes fail and the results are written whole.
TEST_F(OutputSafetyTest, AClosedProgressPipeNeitherKillsTheRunNorLeavesAStagingFolder) {
  const fs::path out = work_ / "out";
  const std::string command =
      kMbid + " run " + Scenario().string() + " -o " + out.string() + " 2>&1 | true";
  ASSERT_EQ(std::system(command.c_str()), 0);
  EXPECT_TRUE(fs::exists(out / "summary.json"));
  EXPECT_TRUE(StagingEntries(work_).empty());
  for (const auto& entry : fs::directory_iterator(work_)) {
    EXPECT_EQ(entry.path().filename().string().rfind(".out.tmp-", 0), std::string::npos)
        << entry.path();
  }
}

TEST_F(OutputSafetyTest, AbsurdWorkerCountIsInvalidInput) {
  const fs::path campaign = Write("c.yaml", "name: c\nbase: " + kReference + "\nsweep:\n" +
                                                "  - grid:\n      simulation.duration_s: [1, 2]\n");
  const CommandResult result =
      Run("campaign " + campaign.string() + " -o " + (work_ / "o").string() + " --workers 100000");
  EXPECT_EQ(result.exit_code, 2) << result.err;
  EXPECT_EQ(result.err.rfind("mbid: error: --workers: ", 0), 0u) << result.err;
  EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << result.err;
  EXPECT_TRUE(Entries(work_).empty());
}

TEST_F(OutputSafetyTest, AFullDiskIsAFailureAndLeavesNothing) {
  // A file-size limit fails writes (EFBIG) as a full disk does (ENOSPC). 100 blocks (50 or
  // 100 KiB by the shell's block size) hold the figures but not run.h5 (about 200 kB).
  const CommandResult result =
      Run("run " + Scenario().string() + " --quiet -o " + (work_ / "out").string(),
          "ulimit -f 100 && ");
  EXPECT_EQ(result.exit_code, 1) << result.err;  // not 139 (SIGSEGV in HDF5) nor 153 (SIGXFSZ)
  EXPECT_EQ(result.err.rfind("mbid: failure: cannot write ", 0), 0u) << result.err;
  EXPECT_TRUE(Entries(work_).empty());
}

TEST_F(OutputSafetyTest, ACaseFileThatCannotBeWrittenEndsTheCampaignCleanly) {
  // Case files are written by one committer thread while the workers compute: when it fails (a
  // file-size limit, as a full disk), the workers must stop and the command end with the
  // failure, not hang waiting to hand over their cases. 100 blocks (50 or 100 KiB by the
  // shell's block size) hold the manifest, not a simulated case's file (about 150 kB).
  const fs::path campaign =
      Write("c.yaml", "name: c\nbase: " + kReference + "\nsteps: [simulate, identify]\n" +
                          "sweep:\n  - grid:\n      simulation.duration_s: [4, 5, 6, 7, 8, 9]\n");
  const CommandResult result = Run(
      "campaign " + campaign.string() + " -o " + (work_ / "o").string() + " --workers 2 --quiet",
      "ulimit -f 100 && ");
  EXPECT_EQ(result.exit_code, 1) << result.err;  // not 153 (SIGXFSZ)
  EXPECT_EQ(result.err.rfind("mbid: failure: cannot write ", 0), 0u) << result.err;
  EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << result.err;
  EXPECT_TRUE(fs::exists(work_ / "o" / "campaign.json"));  // the folder stays resumable
  EXPECT_FALSE(fs::exists(work_ / "o" / "campaign.h5"));
}

TEST_F(OutputSafetyTest, AMergeThatCannotBeWrittenIsAFailureAndResumable) {
  // The cases' files fit, the merged campaign.h5 does not: HDF5 1.10.8 crashes (SIGSEGV in its
  // object copy) when the file system refuses a write, so the merge runs in a child process
  // and its crash is a failure with one line. 200 blocks (100 or 200 KiB) hold a modes-only
  // case file (about 30 kB), not six of them merged.
  const fs::path campaign =
      Write("c.yaml", "name: c\nbase: " + kReference + "\nsweep:\n" +
                          "  - grid:\n      simulation.duration_s: [4, 5, 6, 7, 8, 9]\n");
  const std::string arguments =
      "campaign " + campaign.string() + " -o " + (work_ / "o").string() + " --quiet";
  const CommandResult full = Run(arguments + " --workers 2", "ulimit -f 200 && ");
  EXPECT_EQ(full.exit_code, 1) << full.err;  // not 139 (SIGSEGV)
  EXPECT_EQ(full.err.rfind("mbid: failure: cannot write ", 0), 0u) << full.err;
  EXPECT_NE(full.err.find("campaign.h5"), std::string::npos) << full.err;
  EXPECT_EQ(std::count(full.err.begin(), full.err.end(), '\n'), 1) << full.err;
  EXPECT_FALSE(fs::exists(work_ / "o" / "campaign.h5"));
  // With room again, --resume merges the committed cases.
  const CommandResult resumed = Run(arguments + " --resume");
  EXPECT_EQ(resumed.exit_code, 0) << resumed.err;
  EXPECT_TRUE(fs::exists(work_ / "o" / "campaign.h5"));
}

TEST_F(OutputSafetyTest, AWorkerThreadThatCannotStartEndsTheCampaignCleanly) {
  // New threads get stacks of `ulimit -s` (2 GB here); in 3 GB of address space the second
  // cannot start. std::thread then throws, which once ended in std::terminate (exit 134).
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "AddressSanitizer maps terabytes of shadow memory: no run under ulimit -v";
#endif
  const fs::path campaign = Write("c.yaml", "name: c\nbase: " + kReference + "\nsweep:\n" +
                                                "  - grid:\n      simulation.duration_s: [1, 2]\n");
  const CommandResult result =
      Run("campaign " + campaign.string() + " -o " + (work_ / "o").string() + " --workers 2",
          "ulimit -s 2000000 && ulimit -v 3000000 && ");
  EXPECT_EQ(result.exit_code, 1) << result.err;
  EXPECT_NE(result.err.find("mbid: failure: cannot start worker thread"), std::string::npos)
      << result.err;
  EXPECT_TRUE(fs::exists(work_ / "o" / "campaign.json"));  // the folder stays resumable
}

}  // namespace
