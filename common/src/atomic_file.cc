#include "mbid/common/atomic_file.h"

#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <stdexcept>
#include <system_error>

#include "mbid/common/error.h"

namespace mbid {
namespace {

namespace fs = std::filesystem;

// Unique per process and object, in the target's directory so that the rename stays atomic.
std::string MakeTempPath(const std::string& path) {
  static std::atomic<unsigned> counter{0};
  return path + ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(counter++);
}

}  // namespace

AtomicFile::AtomicFile(std::string path) : path_(std::move(path)) {
  if (path_.empty()) {
    throw InputError("(output)", "", "empty output path", "a file name");
  }
  const fs::path parent = fs::path(path_).parent_path();
  std::error_code ec;
  if (!parent.empty() && !fs::is_directory(parent, ec)) {
    throw InputError(path_, "", "directory '" + parent.string() + "' does not exist",
                     "an output path in an existing directory");
  }
  if (fs::is_directory(path_, ec)) {
    throw InputError(path_, "", "is a directory", "an output file name");
  }
  temp_path_ = MakeTempPath(path_);
}

AtomicFile::~AtomicFile() {
  if (!committed_) {
    std::error_code ec;
    fs::remove(temp_path_, ec);  // Nothing to report from a destructor; absence is the goal.
  }
}

void AtomicFile::Commit() {
  if (committed_) throw std::logic_error("AtomicFile::Commit called twice for " + path_);
  std::error_code ec;
  if (!fs::exists(temp_path_, ec)) {
    throw std::runtime_error("cannot commit " + path_ + ": nothing was written to " + temp_path_);
  }
  fs::rename(temp_path_, path_, ec);
  if (ec) {
    throw std::runtime_error("cannot rename " + temp_path_ + " to " + path_ + ": " + ec.message());
  }
  committed_ = true;
}

}  // namespace mbid
