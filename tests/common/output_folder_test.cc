// OutputFolder: results appear whole under their final name, and nothing that was there before
// is removed unless it is an earlier result of the same kind and the caller asked to replace it.
// Also SafeFileName, and AtomicFile's refusal of non-regular targets.
#include "mbid/common/output_folder.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <set>

#include "mbid/common/atomic_file.h"
#include "test_util.h"

namespace mbid {
namespace {

namespace fs = std::filesystem;
using testing::CatchInputError;
using testing::TempDir;

// The test's notion of an earlier result: a folder holding "result.txt" and nothing else.
bool IsEarlierResult(const fs::path& folder) {
  std::set<std::string> names;
  for (const auto& entry : fs::directory_iterator(folder)) {
    names.insert(entry.path().filename().string());
  }
  names.erase(OutputFolder::kMarkerFile);
  return names == std::set<std::string>{"result.txt"};
}

std::string ReadFile(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

std::set<std::string> Entries(const fs::path& folder) {
  std::set<std::string> names;
  for (const auto& entry : fs::directory_iterator(folder)) {
    names.insert(entry.path().filename().string());
  }
  return names;
}

// A result built in the folder and committed.
void WriteResult(const fs::path& final_path, const std::string& text, bool overwrite) {
  OutputFolder folder(final_path, "test", overwrite, IsEarlierResult);
  std::ofstream(folder / "result.txt") << text;
  folder.Commit();
}

// The pid of a process that has ended (and been reaped): kill(pid, 0) gives ESRCH.
pid_t DeadPid() {
  const pid_t pid = ::fork();
  if (pid == 0) ::_exit(0);
  ::waitpid(pid, nullptr, 0);
  return pid;
}

TEST(OutputFolderTest, AppearsOnlyOnCommitWithItsMarker) {
  TempDir dir;
  const fs::path final_path = dir.File("out");
  {
    OutputFolder folder(final_path, "test", false, IsEarlierResult);
    std::ofstream(folder / "result.txt") << "new";
    EXPECT_FALSE(fs::exists(final_path));  // not visible before Commit
    folder.Commit();
  }
  EXPECT_EQ(ReadFile(final_path / "result.txt"), "new");
  EXPECT_TRUE(OutputFolder::HasMarker(final_path, "test"));
  EXPECT_FALSE(OutputFolder::HasMarker(final_path, "run"));        // another kind
  EXPECT_EQ(Entries(dir.File("")), std::set<std::string>{"out"});  // no staging folder left
}

TEST(OutputFolderTest, WithoutCommitNothingIsLeft) {
  TempDir dir;
  {
    OutputFolder folder(dir.File("out"), "test", false, IsEarlierResult);
    std::ofstream(folder / "result.txt") << "half";
  }
  EXPECT_TRUE(dir.Entries().empty());
}

TEST(OutputFolderTest, AForeignFolderIsRefusedAndKeptEvenWithOverwrite) {
  TempDir dir;
  const fs::path final_path = dir.File("mine");
  fs::create_directories(final_path);
  testing::WriteText((final_path / "thesis.tex").string(), "years of work");
  for (const bool overwrite : {false, true}) {
    const InputError e = CatchInputError([&] { WriteResult(final_path, "new", overwrite); });
    EXPECT_EQ(e.source(), final_path.string());
    EXPECT_NE(std::string(e.what()).find("another output folder"), std::string::npos) << e.what();
    EXPECT_EQ(Entries(final_path), std::set<std::string>{"thesis.tex"});
    EXPECT_EQ(ReadFile(final_path / "thesis.tex"), "years of work");
    EXPECT_EQ(Entries(dir.File("")), std::set<std::string>{"mine"});
  }
}

TEST(OutputFolderTest, AnEarlierResultIsReplacedOnlyWithOverwrite) {
  TempDir dir;
  const fs::path final_path = dir.File("out");
  WriteResult(final_path, "old", false);
  const InputError e = CatchInputError([&] { WriteResult(final_path, "new", false); });
  EXPECT_NE(std::string(e.what()).find("--overwrite"), std::string::npos) << e.what();
  EXPECT_EQ(ReadFile(final_path / "result.txt"), "old");

  WriteResult(final_path, "new", true);
  EXPECT_EQ(ReadFile(final_path / "result.txt"), "new");
  EXPECT_EQ(Entries(dir.File("")), std::set<std::string>{"out"});  // the old one is gone
}

TEST(OutputFolderTest, AnEarlierResultWithAForeignFileIsKept) {
  TempDir dir;
  const fs::path final_path = dir.File("out");
  WriteResult(final_path, "old", false);
  testing::WriteText((final_path / "notes.txt").string(), "mine");
  EXPECT_THROW(WriteResult(final_path, "new", true), InputError);
  EXPECT_EQ(ReadFile(final_path / "notes.txt"), "mine");
  EXPECT_EQ(ReadFile(final_path / "result.txt"), "old");
}

TEST(OutputFolderTest, AnEmptyFolderIsUsedWithoutOverwrite) {
  TempDir dir;
  const fs::path final_path = dir.File("empty");
  fs::create_directories(final_path);
  WriteResult(final_path, "new", false);
  EXPECT_EQ(ReadFile(final_path / "result.txt"), "new");
}

TEST(OutputFolderTest, AFileOrSymlinkInThePlaceIsRefused) {
  TempDir dir;
  testing::WriteText(dir.File("file"), "x");
  EXPECT_THROW(WriteResult(dir.File("file"), "new", true), InputError);
  EXPECT_EQ(ReadFile(dir.File("file")), "x");
  WriteResult(dir.File("target"), "old", false);
  fs::create_directory_symlink(dir.File("target"), dir.File("link"));
  EXPECT_THROW(WriteResult(dir.File("link"), "new", true), InputError);
  EXPECT_EQ(ReadFile(dir.File("target/result.txt")), "old");
}

TEST(OutputFolderTest, DotAndTrailingSlashNameTheFolderItself) {
  TempDir dir;
  const fs::path final_path = dir.File("mine");
  fs::create_directories(final_path);
  testing::WriteText((final_path / "data.csv").string(), "1,2");
  // "mine/." and "mine/" are "mine": refused like it, never a subfolder or its parent.
  for (const std::string suffix : {"/.", "/", "/sub/.."}) {
    EXPECT_THROW(WriteResult(final_path.string() + suffix, "new", true), InputError) << suffix;
  }
  EXPECT_EQ(Entries(final_path), std::set<std::string>{"data.csv"});
  EXPECT_EQ(Entries(dir.File("")), std::set<std::string>{"mine"});
}

TEST(OutputFolderTest, AFolderThatAppearsDuringTheRunIsNotReplaced) {
  TempDir dir;
  const fs::path final_path = dir.File("out");
  OutputFolder folder(final_path, "test", true, IsEarlierResult);
  std::ofstream(folder / "result.txt") << "new";
  fs::create_directories(final_path);
  testing::WriteText((final_path / "theirs.txt").string(), "theirs");
  EXPECT_THROW(folder.Commit(), InputError);
  EXPECT_EQ(Entries(final_path), std::set<std::string>{"theirs.txt"});
}

TEST(OutputFolderTest, LeftoversOfDeadProcessesAreCleanedOthersKept) {
  TempDir dir;
  const fs::path parent = dir.File("");
  const pid_t dead = DeadPid();
  const auto make = [&](const std::string& name, bool marker) {
    fs::create_directories(parent / name);
    testing::WriteText((parent / name / "result.txt").string(), name);
    if (marker) {
      testing::WriteText((parent / name / OutputFolder::kMarkerFile).string(),
                         R"({"format": "mbid-output", "kind": "test"})");
    }
  };
  const std::string stale = ".x.tmp-" + std::to_string(dead);           // removed
  const std::string foreign = ".y.tmp-" + std::to_string(dead);         // no marker: not ours
  const std::string running = ".z.tmp-" + std::to_string(::getppid());  // a live process
  const std::string aside = ".prev.old-" + std::to_string(dead);        // results renamed aside
  make(stale, true);
  make(foreign, false);
  testing::WriteText((parent / foreign / "notes.txt").string(), "not a result");
  make(running, true);
  make(aside, true);
  WriteResult(parent / "out", "new", false);
  EXPECT_EQ(Entries(parent), (std::set<std::string>{foreign, running, "prev", "out"}));
  EXPECT_EQ(ReadFile(parent / "prev" / "result.txt"), aside);  // renamed back, not deleted
}

TEST(SafeFileNameTest, NeverAPathOrAHiddenName) {
  EXPECT_EQ(SafeFileName("crane", "s.yaml", "name"), "crane");
  EXPECT_EQ(SafeFileName("..", "s.yaml", "name"), "_.");
  EXPECT_EQ(SafeFileName(".", "s.yaml", "name"), "_");
  EXPECT_EQ(SafeFileName("a/b\\c", "s.yaml", "name"), "a_b_c");
  EXPECT_EQ(SafeFileName("line\nbreak\x7f", "s.yaml", "name"), "line_break_");
  // Shell characters, spaces and Unicode are ordinary file names once no shell is involved.
  EXPECT_EQ(SafeFileName("crane;touch X $(y) `z` kran\u00e4", "s.yaml", "name"),
            "crane;touch X $(y) `z` kran\u00e4");
  const InputError e = CatchInputError([] { SafeFileName("", "s.yaml", "name"); });
  EXPECT_EQ(e.field(), "name");
}

TEST(SafeFileNameTest, LongNamesAreCutAtACharacterBoundary) {
  std::string name;
  for (int i = 0; i < 150; ++i) name += "\u00e4";  // 2 bytes each: 300 bytes
  const std::string safe = SafeFileName(name, "s.yaml", "name");
  EXPECT_EQ(safe.size(), 200u);  // the 200-byte cap falls between two 2-byte characters
  const std::string odd = SafeFileName("x" + name, "s.yaml", "name");
  EXPECT_EQ(odd.size(), 199u);  // "x" shifts the boundary: the split character is dropped
}

TEST(AtomicFileTest, ADeviceIsNotReplaced) {
  const InputError e = CatchInputError([] { AtomicFile file("/dev/null"); });
  EXPECT_NE(std::string(e.what()).find("not a regular file"), std::string::npos) << e.what();
  EXPECT_TRUE(fs::is_character_file("/dev/null"));
}

}  // namespace
}  // namespace mbid
