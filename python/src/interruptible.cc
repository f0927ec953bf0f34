#include "interruptible.h"

#include <signal.h>

#include <atomic>
#include <mutex>
#include <stdexcept>

#include "mbid/common/stop.h"

namespace mbid::python {
namespace {

std::atomic<bool> sigint_seen{false};

void OnSigint(int) {
  sigint_seen.store(true);
  RequestStop();
}

std::mutex handler_mutex;
int depth = 0;  // StopOnSigint objects alive
bool installed = false;
struct sigaction previous {};

}  // namespace

StopOnSigint::StopOnSigint() {
  std::lock_guard<std::mutex> lock(handler_mutex);
  if (depth++ > 0) return;
  sigint_seen.store(false);
  ClearStopRequest();
  struct sigaction ours {};
  ours.sa_handler = OnSigint;
  sigemptyset(&ours.sa_mask);
  if (sigaction(SIGINT, nullptr, &previous) == 0 && previous.sa_handler != SIG_IGN) {
    sigaction(SIGINT, &ours, nullptr);
    installed = true;
  }
}

StopOnSigint::~StopOnSigint() { Restore(); }

void StopOnSigint::Finish() {
  Restore();
  if (!sigint_seen.load()) return;
  PyErr_SetInterrupt();
  if (PyErr_CheckSignals() != 0) throw pybind11::error_already_set();
  // A handler of the user's that raised nothing: the computation was still cut short.
  throw std::runtime_error("mbid: interrupted by SIGINT");
}

void StopOnSigint::Restore() {
  if (restored_) return;
  restored_ = true;
  std::lock_guard<std::mutex> lock(handler_mutex);
  if (--depth > 0) return;
  if (installed) sigaction(SIGINT, &previous, nullptr);
  installed = false;
  ClearStopRequest();
}

}  // namespace mbid::python
