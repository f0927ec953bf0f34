#include "gnuplot_standby.h"

#include <fcntl.h>
#include <pthread.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <ctime>
#include <mutex>
#include <vector>

extern char** environ;

namespace mbid::report::internal {
namespace {

void CloseQuietly(int fd) {
  if (fd >= 0) ::close(fd);
}

// Writes all of `text` to `fd`; false if the reader is gone. SIGPIPE is blocked on this thread
// while writing, and a pending one taken back, so that a dead gnuplot cannot end mbid.
bool WriteAll(int fd, const std::string& text) {
  sigset_t pipe_signal, old;
  sigemptyset(&pipe_signal);
  sigaddset(&pipe_signal, SIGPIPE);
  pthread_sigmask(SIG_BLOCK, &pipe_signal, &old);
  size_t done = 0;
  bool ok = true;
  while (done < text.size()) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      ok = false;
      break;
    }
    done += static_cast<size_t>(n);
  }
  if (!ok && errno == EPIPE) {
    const timespec now{0, 0};
    while (sigtimedwait(&pipe_signal, nullptr, &now) == SIGPIPE) {
    }
  }
  pthread_sigmask(SIG_SETMASK, &old, nullptr);
  return ok;
}

std::optional<StandbyGnuplot> Spawn(const std::string& warm_up) {
  // Close-on-exec: no other child of mbid may hold these pipes open.
  int input[2], output[2];
  if (::pipe2(input, O_CLOEXEC) != 0) return std::nullopt;
  if (::pipe2(output, O_CLOEXEC) != 0) {
    CloseQuietly(input[0]);
    CloseQuietly(input[1]);
    return std::nullopt;
  }
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, input[0], STDIN_FILENO);
  posix_spawn_file_actions_adddup2(&actions, output[1], STDOUT_FILENO);
  posix_spawn_file_actions_adddup2(&actions, output[1], STDERR_FILENO);
  char name[] = "gnuplot";
  char* argv[] = {name, nullptr};
  pid_t pid = -1;
  const int error = SpawnUnblocked(&pid, actions, argv);
  posix_spawn_file_actions_destroy(&actions);
  CloseQuietly(input[0]);
  CloseQuietly(output[1]);
  if (error != 0) {
    CloseQuietly(input[1]);
    CloseQuietly(output[0]);
    return std::nullopt;
  }
  StandbyGnuplot process{pid, input[1], output[0]};
  if (!WriteAll(process.input, warm_up)) {
    CloseQuietly(process.input);
    CloseQuietly(process.output);
    while (::waitpid(pid, nullptr, 0) < 0 && errno == EINTR) {
    }
    return std::nullopt;
  }
  return process;
}

// Ends a process that was not used: at end of input gnuplot exits.
void Dismiss(const StandbyGnuplot& process) {
  CloseQuietly(process.input);
  CloseQuietly(process.output);
  while (::waitpid(process.pid, nullptr, 0) < 0 && errno == EINTR) {
  }
}

class Pool {
 public:
  ~Pool() {
    for (const StandbyGnuplot& process : waiting_) Dismiss(process);
  }

  void Fill(int count, const std::string& warm_up) {
    std::lock_guard<std::mutex> lock(mutex_);
    while (static_cast<int>(waiting_.size()) < count) {
      const std::optional<StandbyGnuplot> process = Spawn(warm_up);
      if (!process) return;
      waiting_.push_back(*process);
    }
  }

  std::optional<StandbyGnuplot> Take() {
    std::lock_guard<std::mutex> lock(mutex_);
    while (!waiting_.empty()) {
      const StandbyGnuplot process = waiting_.back();
      waiting_.pop_back();
      if (::waitpid(process.pid, nullptr, WNOHANG) == 0) return process;
      // Ended on its own (killed, or its warm-up failed): reaped above.
      CloseQuietly(process.input);
      CloseQuietly(process.output);
    }
    return std::nullopt;
  }

 private:
  std::mutex mutex_;
  std::vector<StandbyGnuplot> waiting_;
};

Pool& ThePool() {
  static Pool pool;
  return pool;
}

}  // namespace

int SpawnUnblocked(pid_t* pid, const posix_spawn_file_actions_t& actions, char* const argv[]) {
  posix_spawnattr_t attributes;
  posix_spawnattr_init(&attributes);
  sigset_t none;
  sigemptyset(&none);
  posix_spawnattr_setsigmask(&attributes, &none);
  posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETSIGMASK);
  const int error = posix_spawnp(pid, argv[0], &actions, &attributes, argv, environ);
  posix_spawnattr_destroy(&attributes);
  return error;
}

void StartStandbyGnuplot(int count, const std::string& warm_up) { ThePool().Fill(count, warm_up); }

std::optional<StandbyGnuplot> TakeStandbyGnuplot() { return ThePool().Take(); }

int RunStandby(const StandbyGnuplot& process, const std::string& commands, std::string* log) {
  // `exit` rather than the end of input: a child forked meanwhile elsewhere in mbid may still
  // hold a copy of the pipe's writing end.
  const bool taken = WriteAll(process.input, commands + "\nexit\n");
  CloseQuietly(process.input);
  char buffer[4096];
  for (;;) {
    const ssize_t n = ::read(process.output, buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    log->append(buffer, static_cast<size_t>(n));
  }
  CloseQuietly(process.output);
  int status = 0;
  while (::waitpid(process.pid, &status, 0) < 0) {
    if (errno != EINTR) return -1;
  }
  return taken ? status : -1;
}

}  // namespace mbid::report::internal
