#include "mbid/common/write_in_child.h"

#include <fmt/format.h>
#include <sys/resource.h>
#include <sys/statvfs.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <filesystem>
#include <stdexcept>

#include "hdf5_internal.h"
#include "internal.h"

namespace mbid {
namespace {

// What the file system has left where `path` goes, and the file-size limit, for the message
// after a crash.
std::string SpaceLeft(const std::string& path) {
  std::string folder = std::filesystem::path(path).parent_path().string();
  if (folder.empty()) folder = ".";
  struct statvfs stats {};
  std::string text = statvfs(folder.c_str(), &stats) == 0
                         ? fmt::format("{:.1f} MB free there",
                                       static_cast<double>(stats.f_bavail) * stats.f_frsize / 1e6)
                         : "free space unknown";
  rlimit size_limit{};
  if (getrlimit(RLIMIT_FSIZE, &size_limit) == 0 && size_limit.rlim_cur != RLIM_INFINITY) {
    text +=
        fmt::format(", file-size limit {:.1f} MB", static_cast<double>(size_limit.rlim_cur) / 1e6);
  }
  return text;
}

}  // namespace

void WriteInChild(const std::string& path, const std::function<void()>& write) {
  if (internal::ChildProcessesOff()) {
    write();
    return;
  }
  // Held across the fork, so that no thread of this process is inside HDF5 when the child's copy
  // of the library is made (the child gets a fresh lock).
  const internal::H5Lock lock(internal::H5Mutex());
  int message_pipe[2];
  if (pipe(message_pipe) != 0) {
    write();
    return;
  }
  const pid_t child = fork();
  if (child < 0) {
    close(message_pipe[0]);
    close(message_pipe[1]);
    write();
    return;
  }
  if (child == 0) {
    close(message_pipe[0]);
    internal::PrepareCrashReportingChild();
    int status = 0;
    try {
      write();
    } catch (const std::exception& error) {
      const std::string message = error.what();
      [[maybe_unused]] const ssize_t ignored =
          ::write(message_pipe[1], message.data(), message.size());
      status = 1;
    } catch (...) {
      status = 1;
    }
    // Without exit handlers: HDF5's at-exit clean-up may meet the file it failed to write.
    _exit(status);
  }
  close(message_pipe[1]);
  std::string message;
  char buffer[512];
  while (true) {
    const ssize_t got = read(message_pipe[0], buffer, sizeof buffer);
    if (got > 0) {
      message.append(buffer, static_cast<size_t>(got));
    } else if (got == 0 || errno != EINTR) {
      break;
    }
  }
  close(message_pipe[0]);
  int status = 0;
  while (waitpid(child, &status, 0) < 0) {
    if (errno != EINTR) throw std::runtime_error("cannot write " + path + ": lost its writer");
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return;
  if (WIFSIGNALED(status)) {
    throw std::runtime_error(fmt::format(
        "cannot write {}: HDF5 crashed writing it (signal {}, {}); the file system may be full "
        "or the file over its size limit ({})",
        path, WTERMSIG(status), strsignal(WTERMSIG(status)), SpaceLeft(path)));
  }
  throw std::runtime_error(
      fmt::format("cannot write {}: {}", path, message.empty() ? "its writer failed" : message));
}

}  // namespace mbid
