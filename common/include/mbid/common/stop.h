#pragma once

#include <stdexcept>

namespace mbid {

// A request to stop the computation under way, from another thread or a signal handler (the
// Python module's Ctrl-C): simulations throw Interrupted at their next output sample and the
// optimizers abort at their next iteration, so a long call ends within a moment instead of at
// its end. The command line needs none: its SIGINT clean-up ends the process
// (interrupt_cleanup.h). Async-signal-safe (a lock-free atomic).
void RequestStop() noexcept;
void ClearStopRequest() noexcept;
bool StopRequested() noexcept;

// What a stopped computation throws. Code that tolerates a failed simulation (a global search's
// start, a fit's trial step) tolerates this one too: every later simulation fails at once and
// the call unwinds; the caller that requested the stop reports it.
class Interrupted : public std::runtime_error {
 public:
  Interrupted() : std::runtime_error("interrupted") {}
};

inline void ThrowIfStopRequested() {
  if (StopRequested()) throw Interrupted();
}

}  // namespace mbid
