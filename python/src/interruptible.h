#pragma once

// Ctrl-C during a long call. Python runs its SIGINT handler between bytecodes, which a call in
// C++ never reaches: a run went on for 25 s, its gnuplot children (same process group) died, and
// a "gnuplot failed" RuntimeError came before the KeyboardInterrupt, raised later inside the
// user's own except block. For the call's length SIGINT asks mbid to stop (stop.h) instead; the
// call then unwinds within a moment, and Python's handler (KeyboardInterrupt by default) runs as
// the call returns, whatever the stopped computation threw.

#include <pybind11/pybind11.h>

namespace mbid::python {

// Installs the stopping SIGINT handler for its life (calls from several threads share one;
// where SIGINT is ignored, it stays ignored).
class StopOnSigint {
 public:
  StopOnSigint();
  ~StopOnSigint();
  StopOnSigint(const StopOnSigint&) = delete;
  StopOnSigint& operator=(const StopOnSigint&) = delete;

  // Python's handler back; with the GIL held, raises what it raises for a SIGINT seen meanwhile.
  void Finish();

 private:
  void Restore();
  bool restored_ = false;
};

// Runs `call` without the GIL, stoppable by Ctrl-C.
template <typename Call>
auto Interruptible(Call&& call) -> decltype(call()) {
  StopOnSigint stop;
  try {
    auto result = [&] {
      pybind11::gil_scoped_release release;
      return call();
    }();
    stop.Finish();
    return result;
  } catch (const pybind11::error_already_set&) {
    throw;
  } catch (...) {
    stop.Finish();  // a SIGINT's KeyboardInterrupt over what the stopped computation threw
    throw;
  }
}

}  // namespace mbid::python
