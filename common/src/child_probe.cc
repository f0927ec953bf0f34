// SurviveInChild: a library call that may crash on a corrupt file, tried in a child process.
#include <fcntl.h>
#include <fmt/format.h>
#include <pthread.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <thread>

#include "hdf5_internal.h"
#include "internal.h"

namespace mbid::internal {

void PrepareCrashReportingChild() {
  // The parent's lock came along, owned by a thread the child does not have; the child is
  // single-threaded, so a fresh lock is safe (HDF5 calls in the child take it).
  pthread_mutexattr_t recursive;
  pthread_mutexattr_init(&recursive);
  pthread_mutexattr_settype(&recursive, PTHREAD_MUTEX_RECURSIVE);
  pthread_mutex_init(H5Mutex().native_handle(), &recursive);
  // A crash ends the child by its signal, whatever handler the parent installed (a sanitizer's,
  // a host program's around the Python module), so that it is told as a crash.
  for (int signal_number : {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT}) {
    std::signal(signal_number, SIG_DFL);
  }
  // The child leaves without exit handlers; its messages and core dumps are of no use.
  const rlimit no_core{0, 0};
  setrlimit(RLIMIT_CORE, &no_core);
  const int null = open("/dev/null", O_WRONLY);
  if (null >= 0) {
    dup2(null, STDOUT_FILENO);
    dup2(null, STDERR_FILENO);
  }
}

namespace {

// MBID_CHILD_PROBE_LIMIT_S (a positive number of seconds) replaces the 5 s: a slow disk, or the
// test of a looping file, which need not wait 5 s.
std::chrono::milliseconds ChildTimeBase() {
  const char* text = std::getenv("MBID_CHILD_PROBE_LIMIT_S");
  if (text != nullptr && *text != '\0') {
    char* end = nullptr;
    const double seconds = std::strtod(text, &end);
    if (*end == '\0' && seconds > 0 && seconds < 1e6) {
      return std::chrono::milliseconds(static_cast<long long>(std::ceil(seconds * 1000)));
    }
  }
  return std::chrono::milliseconds(5000);
}

}  // namespace

void SurviveInChild(const std::string& path, const std::string& expected,
                    const std::string& library, const std::function<void()>& body) {
  if (ChildProcessesOff()) return;
  std::error_code error;
  const auto bytes = std::filesystem::file_size(path, error);
  // 5 s, plus 1 s per 20 MB: far more than an intact file needs.
  const auto limit = ChildTimeBase() +
                     std::chrono::milliseconds(error ? 0 : static_cast<long long>(bytes / 20000));
  // No other thread is inside libhdf5 (directly or under matio) when the child is made, so the
  // child's copy of the library is in a consistent state.
  const H5Lock lock(H5Mutex());
  const pid_t child = fork();
  if (child < 0) return;  // no process to spare: read as before rather than refuse the file
  if (child == 0) {
    PrepareCrashReportingChild();
    try {
      body();
    } catch (...) {
      // Errors the caller reports itself when it reads the file again.
    }
    _exit(0);
  }
  const auto start = std::chrono::steady_clock::now();
  int status = 0;
  auto pause = std::chrono::microseconds(100);
  while (true) {
    const pid_t done = waitpid(child, &status, WNOHANG);
    if (done == child) break;
    if (done < 0 && errno != EINTR) return;  // reaped elsewhere (a SIGCHLD handler): no verdict
    if (std::chrono::steady_clock::now() - start > limit) {
      kill(child, SIGKILL);
      waitpid(child, &status, 0);
      throw InputError(path, "",
                       fmt::format("{} did not finish reading the file in {:g} s (it loops on "
                                   "some corrupt files)",
                                   library, std::chrono::duration<double>(limit).count()),
                       expected);
    }
    std::this_thread::sleep_for(pause);
    pause = std::min(pause * 2, std::chrono::microseconds(20000));
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return;
  throw InputError(path, "",
                   WIFSIGNALED(status)
                       ? fmt::format("{} crashed reading the file (signal {}, {}): the file is "
                                     "corrupt",
                                     library, WTERMSIG(status), strsignal(WTERMSIG(status)))
                       : fmt::format("{} failed reading the file (status {}): the file is corrupt",
                                     library, WIFEXITED(status) ? WEXITSTATUS(status) : -1),
                   expected);
}

}  // namespace mbid::internal
