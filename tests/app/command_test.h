#pragma once

// Runs the built mbid binary as users' scripts do, in a fresh folder per test.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace mbid::testing {

namespace fs = std::filesystem;

inline const std::string kMbid = std::string(MBID_BINARY_DIR) + "/app/mbid";

inline std::string ReadText(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

struct CommandResult {
  int exit_code = -1;
  std::string out;
  std::string err;
};

class CommandTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const ::testing::TestInfo* info = ::testing::UnitTest::GetInstance()->current_test_info();
    // Parametrized tests are named "Suite/Test/Param": one folder, not nested ones; the process
    // id keeps two concurrent runs of the suite apart.
    std::string name = std::string(info->test_suite_name()) + "_" + info->name();
    std::replace(name.begin(), name.end(), '/', '_');
    dir_ = fs::temp_directory_path() / ("mbid_" + std::to_string(::getpid()) + "_" + name);
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // `mbid <arguments>` with standard output and error captured; `prefix` goes before the
  // binary (e.g. "mpiexec -n 2 ").
  CommandResult Run(const std::string& arguments, const std::string& prefix = "") const {
    const fs::path out = dir_ / "stdout.txt";
    const fs::path err = dir_ / "stderr.txt";
    const std::string command =
        prefix + kMbid + " " + arguments + " > " + out.string() + " 2> " + err.string();
    const int status = std::system(command.c_str());
    CommandResult result;
    result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    result.out = ReadText(out);
    result.err = ReadText(err);
    fs::remove(out);
    fs::remove(err);
    return result;
  }

  // `source` with `from` replaced by `to` (which must occur; nothing if `from` is empty),
  // written into the test's folder as `name`.
  fs::path WriteVariant(const fs::path& source, const std::string& name,
                        const std::string& from = "", const std::string& to = "") const {
    std::string text = ReadText(source);
    if (!from.empty()) {
      const size_t at = text.find(from);
      EXPECT_NE(at, std::string::npos) << from;
      if (at != std::string::npos) text.replace(at, from.size(), to);
    }
    const fs::path path = dir_ / name;
    std::ofstream(path) << text;
    return path;
  }

  // `text` written into the test's folder as `name`.
  fs::path Write(const std::string& name, const std::string& text) const {
    std::ofstream(dir_ / name) << text;
    return dir_ / name;
  }

  fs::path dir_;
};

}  // namespace mbid::testing
