#include "mbid/common/interrupt_cleanup.h"

#include <pthread.h>
#include <signal.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <map>
#include <mutex>
#include <system_error>

namespace mbid {
namespace {

namespace fs = std::filesystem;

struct Registry {
  std::recursive_mutex mutex;  // HoldInterruptCleanup's commits lock it again
  unsigned long next_id = 0;
  std::map<unsigned long, std::string> paths;
};

// Never destroyed: the clean-up thread may still use it while static objects are destroyed at
// exit.
Registry& TheRegistry() {
  static Registry* registry = new Registry;
  return *registry;
}

sigset_t watched_signals;

// Another thread may still be writing into a folder being removed; a few passes catch what it
// created meanwhile (it fails once the folder itself is gone).
void RemoveEverything(const std::string& path) {
  for (int pass = 0; pass < 5; ++pass) {
    std::error_code error;
    fs::remove_all(path, error);
    if (!fs::exists(fs::symlink_status(path, error))) return;
  }
}

void* WaitForSignals(void*) {
  int signal = 0;
  while (sigwait(&watched_signals, &signal) != 0) {
  }
  // Held until the process ends: no commit can start after the clean-up.
  TheRegistry().mutex.lock();
  for (const auto& [id, path] : TheRegistry().paths) RemoveEverything(path);
  std::signal(signal, SIG_DFL);
  sigset_t only;
  sigemptyset(&only);
  sigaddset(&only, signal);
  pthread_sigmask(SIG_UNBLOCK, &only, nullptr);
  raise(signal);
  _exit(128 + signal);  // not reached: the default action of these signals ends the process
}

}  // namespace

void InstallInterruptCleanup() {
  std::signal(SIGXFSZ, SIG_IGN);
  // A reader of the progress or the JSON that went away (`mbid run ... 2>&1 | head`) must not
  // end the run by SIGPIPE's default action, which would leave its staging folder and lose the
  // results: the writes fail (EPIPE) and the run completes.
  std::signal(SIGPIPE, SIG_IGN);
  sigemptyset(&watched_signals);
  int count = 0;
  for (const int signal : {SIGINT, SIGTERM, SIGHUP}) {
    struct sigaction current {};
    if (sigaction(signal, nullptr, &current) == 0 && current.sa_handler == SIG_IGN) continue;
    sigaddset(&watched_signals, signal);
    ++count;
  }
  if (count == 0) return;
  pthread_sigmask(SIG_BLOCK, &watched_signals, nullptr);
  // A small stack of its own: the thread only removes files, and a huge `ulimit -s` (the default
  // stack size of new threads) must not stop it from starting.
  pthread_attr_t attributes;
  pthread_attr_init(&attributes);
  pthread_attr_setstacksize(&attributes, 256 * 1024);
  pthread_attr_setdetachstate(&attributes, PTHREAD_CREATE_DETACHED);
  pthread_t thread;
  const int status = pthread_create(&thread, &attributes, WaitForSignals, nullptr);
  pthread_attr_destroy(&attributes);
  // Without the thread the signals keep their default action (no clean-up, but no hang).
  if (status != 0) pthread_sigmask(SIG_UNBLOCK, &watched_signals, nullptr);
}

void HoldInterruptCleanup(const std::function<void()>& commits) {
  std::lock_guard<std::recursive_mutex> lock(TheRegistry().mutex);
  commits();
}

RemoveOnInterrupt::RemoveOnInterrupt(std::string path) {
  Registry& registry = TheRegistry();
  std::lock_guard<std::recursive_mutex> lock(registry.mutex);
  id_ = registry.next_id++;
  registry.paths.emplace(id_, std::move(path));
}

RemoveOnInterrupt::~RemoveOnInterrupt() {
  if (!watched_) return;
  Registry& registry = TheRegistry();
  std::lock_guard<std::recursive_mutex> lock(registry.mutex);
  registry.paths.erase(id_);
}

void RemoveOnInterrupt::Commit(const std::function<void()>& rename) {
  Registry& registry = TheRegistry();
  std::lock_guard<std::recursive_mutex> lock(registry.mutex);
  rename();
  registry.paths.erase(id_);
  watched_ = false;
}

}  // namespace mbid
