// AtomicFile: the output appears only on Commit(), and nothing is left behind otherwise.
#include "mbid/common/atomic_file.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "test_util.h"

namespace mbid {
namespace {

using testing::CatchInputError;
using testing::TempDir;

TEST(AtomicFileTest, CommitRenamesTheTemporaryIntoPlace) {
  TempDir dir;
  const std::string path = dir.File("out.txt");
  {
    AtomicFile file(path);
    EXPECT_NE(file.temp_path(), path);
    std::ofstream(file.temp_path()) << "done";
    EXPECT_FALSE(std::filesystem::exists(path));  // not visible before Commit
    file.Commit();
  }
  EXPECT_EQ(dir.Entries(), std::vector<std::string>{"out.txt"});
  std::string text;
  std::ifstream(path) >> text;
  EXPECT_EQ(text, "done");
}

TEST(AtomicFileTest, WithoutCommitNothingIsLeftBehind) {
  TempDir dir;
  {
    AtomicFile file(dir.File("out.txt"));
    std::ofstream(file.temp_path()) << "half";
  }
  EXPECT_TRUE(dir.Entries().empty());
}

TEST(AtomicFileTest, WithoutCommitAnExistingOutputIsKept) {
  TempDir dir;
  const std::string path = dir.File("out.txt");
  testing::WriteText(path, "old");
  {
    AtomicFile file(path);
    std::ofstream(file.temp_path()) << "new";
  }
  std::string text;
  std::ifstream(path) >> text;
  EXPECT_EQ(text, "old");
  EXPECT_EQ(dir.Entries(), std::vector<std::string>{"out.txt"});
}

// A command's -o and --json: committed one by one, an interruption between the two left the
// summary naming an -o file that did not exist (a trial's Ctrl-C, 5 times in 50).
TEST(OutputSetTest, FilesAppearTogetherOnlyWhenTheSetCommits) {
  TempDir dir;
  const auto write = [&](const std::string& name, const char* text) {
    AtomicFile file(dir.File(name));
    std::ofstream(file.temp_path()) << text;
    file.Commit();
  };
  {
    OutputSet set;
    write("out.json", "{}");
    write("out.h5", "data");
    for (const std::string& entry : dir.Entries()) {  // the temporaries alone, synced
      EXPECT_NE(entry.find(".tmp-"), std::string::npos) << entry;
    }
    EXPECT_EQ(dir.Entries().size(), 2u);
    set.Commit();
  }
  std::vector<std::string> entries = dir.Entries();
  std::sort(entries.begin(), entries.end());
  EXPECT_EQ(entries, (std::vector<std::string>{"out.h5", "out.json"}));
  // Without the set's commit (a failure after both files were written): neither, no temporary.
  TempDir failed;
  {
    OutputSet set;
    AtomicFile file(failed.File("a.json"));
    std::ofstream(file.temp_path()) << "{}";
    file.Commit();
  }
  EXPECT_TRUE(failed.Entries().empty());
  // No set: each file commits at once, as before.
  write("alone.txt", "x");
  EXPECT_TRUE(std::filesystem::exists(dir.File("alone.txt")));
}

TEST(AtomicFileTest, MissingDirectoryIsAnInputError) {
  TempDir dir;
  const std::string path = dir.File("no_such_dir/out.h5");
  const InputError e = CatchInputError([&] { AtomicFile file(path); });
  EXPECT_EQ(e.source(), path);
  EXPECT_NE(std::string(e.what()).find("does not exist"), std::string::npos) << e.what();
  EXPECT_TRUE(dir.Entries().empty());
}

TEST(AtomicFileTest, CommitWithoutContentThrows) {
  TempDir dir;
  AtomicFile file(dir.File("out.txt"));
  EXPECT_THROW(file.Commit(), std::runtime_error);
  EXPECT_TRUE(dir.Entries().empty());
}

}  // namespace
}  // namespace mbid
