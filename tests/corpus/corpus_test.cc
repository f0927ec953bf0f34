// The bad-input and fault corpus: every case in tests/corpus/*.yaml runs the built `mbid` in a
// folder of its own (no shell: fork + exec) and checks the contract for bad input and faults:
// the exit code, one error line naming what is wrong, and that nothing the folder held before
// was changed or removed and nothing but the named outputs appeared. Case format:
// tests/corpus/README.md.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/mount.h>
#include <sys/wait.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace mbid::testing {
namespace {

namespace fs = std::filesystem;

const std::string kMbid = std::string(MBID_BINARY_DIR) + "/app/mbid";
const fs::path kSource = MBID_SOURCE_DIR;

std::string ReadBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string Expand(std::string text) {
  const std::pair<std::string, std::string> names[] = {
      {"{scenarios}", (kSource / "scenarios").string()},
      {"{data}", (kSource / "tests" / "data").string()}};
  for (const auto& [from, to] : names) {
    for (size_t at = text.find(from); at != std::string::npos; at = text.find(from, at)) {
      text.replace(at, from.size(), to);
      at += to.size();
    }
  }
  return text;
}

struct Command {
  std::vector<std::string> args;
  std::map<std::string, std::string> env;
  int exit = 0;
};

struct Case {
  std::string name;
  std::string file;  // the corpus file that defines it
  YAML::Node files;
  YAML::Node derived;           // files made from the set-up commands' outputs
  std::vector<Command> before;  // set-up commands, each must exit 0
  Command command;
  std::vector<std::string> message;  // substrings of the one error line
  std::vector<std::string> creates;  // paths the command may create (prefixes)
  std::string crash_at;              // MBID_TEST_CRASH_AT for the command
  std::vector<Command> after;        // recovery commands after a crash
  int tmpfs_kb = 0;                  // a full disk: a tmpfs of this size mounted at disk/
};

Command ReadCommand(const YAML::Node& node) {
  Command command;
  for (const auto& arg : node["args"]) command.args.push_back(Expand(arg.as<std::string>()));
  if (node["env"]) {
    for (const auto& item : node["env"]) {
      command.env[item.first.as<std::string>()] = Expand(item.second.as<std::string>());
    }
  }
  command.exit = node["exit"] ? node["exit"].as<int>() : 0;
  return command;
}

std::vector<Case> LoadCases() {
  std::vector<Case> cases;
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(kSource / "tests" / "corpus")) {
    if (entry.path().extension() == ".yaml") files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  for (const fs::path& file : files) {
    for (const YAML::Node& node : YAML::LoadFile(file.string())) {
      Case one;
      one.name = node["name"].as<std::string>();
      one.file = file.filename().string();
      // A missing key is a zombie node in yaml-cpp, which must not be copied.
      if (node["files"]) one.files = node["files"];
      if (node["derived"]) one.derived = node["derived"];
      if (node["before"]) {
        for (const auto& step : node["before"]) one.before.push_back(ReadCommand(step));
      }
      one.command = ReadCommand(node);
      if (node["message"]) {
        if (node["message"].IsSequence()) {
          for (const auto& part : node["message"]) one.message.push_back(part.as<std::string>());
        } else {
          one.message.push_back(node["message"].as<std::string>());
        }
      }
      if (node["creates"]) {
        for (const auto& path : node["creates"]) one.creates.push_back(path.as<std::string>());
      }
      one.crash_at = node["crash_at"] ? node["crash_at"].as<std::string>() : "";
      if (node["after"]) {
        for (const auto& step : node["after"]) one.after.push_back(ReadCommand(step));
      }
      one.tmpfs_kb = node["tmpfs_kb"] ? node["tmpfs_kb"].as<int>() : 0;
      cases.push_back(one);
    }
  }
  return cases;
}

struct Outcome {
  int exit = -1;  // the exit status, or 128 + signal
  std::string out, err;
};

// fork + exec of mbid in `dir`, standard output and error to files: no shell in between.
Outcome RunMbid(const fs::path& dir, const Command& command, const std::string& crash_at = "") {
  const fs::path out = dir.parent_path() / (dir.filename().string() + ".stdout");
  const fs::path err = dir.parent_path() / (dir.filename().string() + ".stderr");
  std::vector<std::string> args = {kMbid};
  args.insert(args.end(), command.args.begin(), command.args.end());
  const pid_t pid = ::fork();
  if (pid == 0) {
    if (::chdir(dir.c_str()) != 0) ::_exit(126);
    const int out_fd = ::open(out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int err_fd = ::open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (out_fd < 0 || err_fd < 0) ::_exit(126);
    ::dup2(out_fd, 1);
    ::dup2(err_fd, 2);
    for (const auto& [name, value] : command.env) ::setenv(name.c_str(), value.c_str(), 1);
    if (!crash_at.empty()) ::setenv("MBID_TEST_CRASH_AT", crash_at.c_str(), 1);
    std::vector<char*> argv;
    for (std::string& arg : args) argv.push_back(arg.data());
    argv.push_back(nullptr);
    ::execv(kMbid.c_str(), argv.data());
    ::_exit(127);
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  Outcome outcome;
  outcome.exit = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  outcome.out = ReadBytes(out);
  outcome.err = ReadBytes(err);
  fs::remove(out);
  fs::remove(err);
  return outcome;
}

// "6e ff 00" -> the three bytes: what YAML text cannot carry (invalid UTF-8, NUL).
std::string Hex(const std::string& text) {
  std::istringstream hex(text);
  std::string bytes, byte;
  while (hex >> byte) bytes += static_cast<char>(std::stoi(byte, nullptr, 16));
  return bytes;
}

void WriteFiles(const fs::path& dir, const YAML::Node& files) {
  if (!files) return;
  for (const auto& item : files) {
    const fs::path path = dir / item.first.as<std::string>();
    fs::create_directories(path.parent_path());
    const YAML::Node& spec = item.second;
    if (spec.IsScalar()) {
      std::ofstream(path, std::ios::binary) << Expand(spec.as<std::string>());
      continue;
    }
    if (spec["folder"]) {
      fs::create_directories(path);
      continue;
    }
    std::string bytes;
    if (spec["copy"]) bytes = ReadBytes(kSource / spec["copy"].as<std::string>());
    if (spec["from"]) bytes = ReadBytes(dir / spec["from"].as<std::string>());
    if (spec["text"]) bytes = Expand(spec["text"].as<std::string>());
    if (spec["hex"]) bytes = Hex(spec["hex"].as<std::string>());
    if (spec["repeat"]) {
      const std::string unit = Expand(spec["repeat"].as<std::string>());
      for (int i = 0; i < spec["times"].as<int>(); ++i) bytes += unit;
    }
    if (spec["replace"]) {
      for (const auto& pair : spec["replace"]) {
        const std::string from = Expand(pair[0].as<std::string>());
        const std::string to = pair[1].IsMap() ? Hex(pair[1]["hex"].as<std::string>())
                                               : Expand(pair[1].as<std::string>());
        const size_t at = bytes.find(from);
        if (at == std::string::npos) {
          ADD_FAILURE() << path << ": '" << from << "' not found in the copied file";
          continue;
        }
        bytes.replace(at, from.size(), to);
      }
    }
    if (spec["truncate"]) bytes.resize(std::min(bytes.size(), spec["truncate"].as<size_t>()));
    if (spec["zero"]) {  // [first, end) bytes zeroed, as a lost write leaves them
      const size_t end = std::min(bytes.size(), spec["zero"][1].as<size_t>());
      for (size_t i = spec["zero"][0].as<size_t>(); i < end; ++i) bytes[i] = '\0';
    }
    std::ofstream(path, std::ios::binary) << bytes;
  }
}

// Every file and folder under `dir`, with the bytes of each file.
std::map<std::string, std::string> Snapshot(const fs::path& dir) {
  std::map<std::string, std::string> entries;
  for (const auto& entry : fs::recursive_directory_iterator(dir)) {
    const std::string name = fs::relative(entry.path(), dir).string();
    entries[name] = entry.is_regular_file() ? ReadBytes(entry.path()) : std::string("<folder>");
  }
  return entries;
}

bool Allowed(const std::string& name, const std::vector<std::string>& creates) {
  for (const std::string& prefix : creates) {
    if (name == prefix || name.rfind(prefix + "/", 0) == 0) return true;
  }
  return false;
}

bool IsTemporary(const std::string& name) {
  return name.find(".tmp-") != std::string::npos || name.find(".old-") != std::string::npos ||
         name.find(".unsealed.") != std::string::npos;
}

// The one error line the contract asks for ("mbid: error: <file>[:<field>]: ..." and kin).
std::vector<std::string> ErrorLines(const std::string& err) {
  std::vector<std::string> lines;
  std::istringstream in(err);
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("mbid: error:", 0) == 0 || line.rfind("mbid: numerical failure:", 0) == 0 ||
        line.rfind("mbid: failure:", 0) == 0) {
      lines.push_back(line);
    }
  }
  return lines;
}

class CorpusTest : public ::testing::TestWithParam<Case> {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("mbid_corpus_" + std::to_string(::getpid()) + "_" + GetParam().name);
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (mounted_) ::umount((dir_ / "disk").c_str());
    fs::remove_all(dir_);
  }

  fs::path dir_;
  bool mounted_ = false;
};

TEST_P(CorpusTest, ExitCodeMessageAndNothingLost) {
  const Case& one = GetParam();
  SCOPED_TRACE(one.file + ": " + one.name);
  if (one.tmpfs_kb > 0) {
    fs::create_directories(dir_ / "disk");
    const std::string options = "size=" + std::to_string(one.tmpfs_kb) + "k";
    if (::mount("tmpfs", (dir_ / "disk").c_str(), "tmpfs", 0, options.c_str()) != 0) {
      GTEST_SKIP() << "cannot mount a tmpfs here (needs root): " << std::strerror(errno);
    }
    mounted_ = true;
  }
  WriteFiles(dir_, one.files);
  for (const Command& step : one.before) {
    const Outcome set_up = RunMbid(dir_, step);
    ASSERT_EQ(set_up.exit, step.exit) << "set-up command failed: " << set_up.err;
  }
  WriteFiles(dir_, one.derived);
  const std::map<std::string, std::string> before = Snapshot(dir_);

  const Outcome outcome = RunMbid(dir_, one.command, one.crash_at);
  if (!one.crash_at.empty()) {
    ASSERT_EQ(outcome.exit, 128 + SIGKILL)
        << "the crash point '" << one.crash_at << "' was not reached: " << outcome.err;
  } else {
    EXPECT_EQ(outcome.exit, one.command.exit) << outcome.err;
    EXPECT_LT(outcome.exit, 128) << "killed by a signal: " << outcome.err;
    if (one.command.exit != 0) {
      const std::vector<std::string> lines = ErrorLines(outcome.err);
      ASSERT_EQ(lines.size(), 1u) << "expected one error line in:\n" << outcome.err;
      for (const std::string& part : one.message) {
        EXPECT_NE(lines[0].find(part), std::string::npos)
            << "'" << part << "' not in: " << lines[0];
      }
      if (one.command.exit == 2) {  // invalid input says what was expected (the contract)
        EXPECT_NE(lines[0].find("; expected"), std::string::npos)
            << "the line says what was expected: " << lines[0];
      }
    }
  }

  // Nothing the folder held was changed or removed; nothing unexpected appeared (a crash may
  // leave temporaries, which the recovery run must clean).
  const std::map<std::string, std::string> after = Snapshot(dir_);
  for (const auto& [name, bytes] : before) {
    if (Allowed(name, one.creates)) continue;  // outputs the command may replace
    const auto it = after.find(name);
    ASSERT_NE(it, after.end()) << name << " was removed";
    EXPECT_TRUE(it->second == bytes) << name << " was changed";
  }
  for (const auto& [name, bytes] : after) {
    if (before.count(name) || Allowed(name, one.creates)) continue;
    if (!one.crash_at.empty() && IsTemporary(name)) continue;
    ADD_FAILURE() << name << " appeared";
  }

  for (const Command& step : one.after) {
    const Outcome recovery = RunMbid(dir_, step);
    EXPECT_EQ(recovery.exit, step.exit) << "recovery: " << recovery.err;
  }
  if (!one.after.empty()) {
    for (const auto& [name, bytes] : Snapshot(dir_)) {
      EXPECT_FALSE(IsTemporary(name)) << name << " left behind after the recovery run";
    }
  }
}

// Shown by gtest for a failing case instead of the object's bytes.
void PrintTo(const Case& one, std::ostream* out) { *out << one.file << ": " << one.name; }

std::string CaseName(const ::testing::TestParamInfo<Case>& info) {
  std::string name = info.param.name;
  for (char& c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  }
  return name;
}

INSTANTIATE_TEST_SUITE_P(Corpus, CorpusTest, ::testing::ValuesIn(LoadCases()), CaseName);

}  // namespace
}  // namespace mbid::testing
