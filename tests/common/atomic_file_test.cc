// AtomicFile: the output appears only on Commit(), and nothing is left behind otherwise.
#include "mbid/common/atomic_file.h"

#include <gtest/gtest.h>

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
