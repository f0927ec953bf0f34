#include "mbid/common/atomic_file.h"

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <stdexcept>
#include <system_error>

#include "internal.h"
#include "mbid/common/crash_point.h"
#include "mbid/common/error.h"

namespace mbid {
namespace {

namespace fs = std::filesystem;

// Unique per process and object, in the target's directory so that the rename stays atomic.
std::string MakeTempPath(const std::string& path) {
  static std::atomic<unsigned> counter{0};
  return path + ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(counter++);
}

// A complete temporary given its final name (atomic within its folder).
void RenameInto(const std::string& temp_path, const std::string& path) {
  std::error_code error;
  fs::rename(temp_path, path, error);
  if (error) {
    throw std::runtime_error("cannot rename " + temp_path + " to " + path + ": " + error.message());
  }
}

// Temporaries "<path>.tmp-<pid>-<n>" of this very output left by processes that no longer exist
// (kill -9, a crash, a power cut): nobody else names files so, and nobody will commit them.
void RemoveStaleTemporaries(const std::string& path) {
  const fs::path target(path);
  const fs::path folder = target.has_parent_path() ? target.parent_path() : fs::path(".");
  std::error_code error;
  for (const auto& entry : fs::directory_iterator(folder, error)) {
    std::string of;
    int pid = 0;
    if (!ParseAtomicTemporaryName(entry.path().filename().string(), &of, &pid) ||
        of != target.filename().string()) {
      continue;
    }
    std::error_code ignored;
    if (internal::ProcessIsGone(pid) && entry.is_regular_file(ignored)) {
      fs::remove(entry.path(), ignored);
    }
  }
}

}  // namespace

namespace internal {

void WriteWholeFile(const std::string& path, const std::vector<char>& bytes) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  int error = fd < 0 ? errno : 0;
  size_t written = 0;
  while (error == 0 && written < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + written, bytes.size() - written);
    if (n > 0) {
      written += static_cast<size_t>(n);
    } else if (n == 0 || errno != EINTR) {
      error = n == 0 ? EIO : errno;
    }
  }
  if (fd >= 0 && ::close(fd) != 0 && error == 0) error = errno;
  if (error != 0) {
    throw std::runtime_error("cannot write " + path + ": " +
                             std::error_code(error, std::generic_category()).message());
  }
}

bool ProcessIsGone(int pid) { return pid != ::getpid() && ::kill(pid, 0) != 0 && errno == ESRCH; }

void SyncFile(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0 || ::fsync(fd) != 0) {
    const std::error_code error(errno, std::generic_category());
    if (fd >= 0) ::close(fd);
    throw std::runtime_error("cannot write " + path + " to disk: " + error.message());
  }
  ::close(fd);
}

void SyncFolder(const std::string& path) {
  const int fd = ::open(path.empty() ? "." : path.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return;
  ::fsync(fd);
  ::close(fd);
}

}  // namespace internal

AtomicFile::AtomicFile(std::string path, bool sync) : path_(std::move(path)), sync_(sync) {
  if (path_.empty()) {
    throw InputError("(output)", "", "empty output path", "a file name");
  }
  CheckOutputName(path_);
  const fs::path parent = fs::path(path_).parent_path();
  std::error_code ec;
  if (!parent.empty() && !fs::is_directory(parent, ec)) {
    throw InputError(path_, "", "directory '" + parent.string() + "' does not exist",
                     "an output path in an existing directory");
  }
  const fs::file_status status = fs::status(path_, ec);
  if (fs::is_directory(status)) {
    throw InputError(path_, "", "is a directory", "an output file name");
  }
  // Renaming over a device or a pipe would replace it with a plain file.
  if (fs::exists(status) && !fs::is_regular_file(status)) {
    throw InputError(path_, "", "exists and is not a regular file", "an output file name");
  }
  RemoveStaleTemporaries(path_);
  temp_path_ = MakeTempPath(path_);
  interrupt_cleanup_ = std::make_unique<RemoveOnInterrupt>(temp_path_);
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
  if (sync_) internal::SyncFile(temp_path_);
  if (OutputSet::Defer(path_, temp_path_, &interrupt_cleanup_, sync_)) {
    committed_ = true;  // the set renames it, or removes it
    return;
  }
  CrashPoint("file-commit");
  interrupt_cleanup_->Commit([this] { RenameInto(temp_path_, path_); });
  committed_ = true;
  CrashPoint("file-committed");
  if (sync_) internal::SyncFolder(fs::path(path_).parent_path().string());
}

namespace {

std::mutex active_set_mutex;
OutputSet* active_set = nullptr;

bool IsSummary(const std::string& path) {
  return path.size() >= 5 && path.compare(path.size() - 5, 5, ".json") == 0;
}

}  // namespace

OutputSet::OutputSet() {
  std::lock_guard<std::mutex> lock(active_set_mutex);
  if (active_set != nullptr) throw std::logic_error("a second OutputSet while one is active");
  active_set = this;
}

OutputSet::~OutputSet() {
  {
    std::lock_guard<std::mutex> lock(active_set_mutex);
    active_set = nullptr;
  }
  if (committed_) return;
  for (const Pending& pending : pending_) {
    std::error_code ignored;
    fs::remove(pending.temp_path, ignored);
  }
}

bool OutputSet::Defer(const std::string& path, const std::string& temp_path,
                      std::unique_ptr<RemoveOnInterrupt>* interrupt_cleanup, bool sync) {
  std::lock_guard<std::mutex> lock(active_set_mutex);
  if (active_set == nullptr) return false;
  active_set->pending_.push_back({path, temp_path, std::move(*interrupt_cleanup), sync});
  return true;
}

void OutputSet::Commit() {
  {
    std::lock_guard<std::mutex> lock(active_set_mutex);
    active_set = nullptr;  // no file joins the set while it is renamed
  }
  std::stable_partition(pending_.begin(), pending_.end(),
                        [](const Pending& p) { return !IsSummary(p.path); });
  if (!pending_.empty()) CrashPoint("file-commit");
  HoldInterruptCleanup([this] {
    for (Pending& pending : pending_) {
      pending.interrupt_cleanup->Commit(
          [&pending] { RenameInto(pending.temp_path, pending.path); });
      CrashPoint("file-committed");
    }
  });
  committed_ = true;
  for (const Pending& pending : pending_) {
    if (pending.sync) internal::SyncFolder(fs::path(pending.path).parent_path().string());
  }
}

namespace {

bool SameFile(const std::string& a, const std::string& b) {
  std::error_code error;
  if (fs::absolute(a, error).lexically_normal() == fs::absolute(b, error).lexically_normal()) {
    return true;
  }
  return fs::exists(a, error) && fs::exists(b, error) && fs::equivalent(a, b, error);
}

}  // namespace

void CheckOutputsAreNew(const std::vector<NamedFile>& inputs,
                        const std::vector<NamedFile>& outputs) {
  for (size_t o = 0; o < outputs.size(); ++o) {
    const NamedFile& output = outputs[o];
    if (output.path.empty() || output.path == "-") continue;
    for (const NamedFile& input : inputs) {
      if (!input.path.empty() && SameFile(output.path, input.path)) {
        throw InputError(output.path, "",
                         "the " + output.flag + " output is the input " + input.flag + " " +
                             input.path + ", which writing it would destroy",
                         "an output name other than the command's input files");
      }
    }
    for (size_t p = 0; p < o; ++p) {
      if (!outputs[p].path.empty() && outputs[p].path != "-" &&
          SameFile(output.path, outputs[p].path)) {
        throw InputError(output.path, "",
                         "the " + output.flag + " output is also the output of " + outputs[p].flag +
                             ", and one would be lost",
                         "a name of its own for each output");
      }
    }
  }
}

bool ParseAtomicTemporaryName(const std::string& name, std::string* target, int* pid) {
  const size_t at = name.rfind(".tmp-");
  if (at == std::string::npos || at == 0) return false;
  std::string rest = name.substr(at + 5);  // "<pid>-<n>"
  // The scratch files a figure's writer keeps beside its temporary (report/gnuplot.cc).
  for (const char* scratch : {".dat", ".gp", ".log"}) {
    const size_t length = std::char_traits<char>::length(scratch);
    if (rest.size() > length && rest.compare(rest.size() - length, length, scratch) == 0) {
      rest.resize(rest.size() - length);
      break;
    }
  }
  const size_t dash = rest.find('-');
  if (dash == 0 || dash == std::string::npos || dash > 9 ||
      rest.find_first_not_of("0123456789-") != std::string::npos ||
      rest.find('-', dash + 1) != std::string::npos || dash + 1 == rest.size()) {
    return false;
  }
  if (target != nullptr) *target = name.substr(0, at);
  if (pid != nullptr) *pid = std::stoi(rest.substr(0, dash));
  return true;
}

void CheckOutputName(const std::string& path) {
  const auto control = std::find_if(path.begin(), path.end(), [](char c) {
    return static_cast<unsigned char>(c) < 0x20 || c == 0x7f;
  });
  if (control == path.end()) return;
  throw InputError(path, "",
                   "the output's name holds a control character (" +
                       OneLine(std::string(1, *control)) + ", a line break or the like)",
                   "a name of printable characters");
}

void CheckOutputsReplaceable(const std::vector<NamedFile>& outputs, bool overwrite) {
  for (const NamedFile& output : outputs) {
    if (output.path.empty() || output.path == "-") continue;
    CheckOutputName(output.path);
    std::error_code error;
    const fs::path folder = fs::absolute(output.path, error).parent_path();
    if (!fs::is_directory(folder, error)) {
      throw InputError(
          output.path, "",
          "the folder of the " + output.flag + " output, " + folder.string() + ", does not exist",
          "an output in an existing folder");
    }
    if (!overwrite && fs::exists(output.path, error)) {
      throw InputError(output.path, "", "the " + output.flag + " output exists",
                       "a new file name, or --overwrite to replace it");
    }
    // The output is written under a temporary name in its folder: a folder that takes no new
    // file (read-only, /proc) fails here, before the work, not after it.
    const fs::path probe =
        folder / (".mbid-probe-" + std::to_string(static_cast<long>(::getpid())));
    const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
    if (fd < 0 && errno != EEXIST) {  // a file of that name is left alone
      throw InputError(output.path, "",
                       "the " + output.flag + " output cannot be created in " + folder.string() +
                           " (" + std::strerror(errno) + ")",
                       "a writable folder");
    }
    if (fd >= 0) {
      ::close(fd);
      ::unlink(probe.c_str());
    }
  }
}

}  // namespace mbid
