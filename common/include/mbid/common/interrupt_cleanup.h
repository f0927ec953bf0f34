#pragma once

#include <functional>
#include <string>

namespace mbid {

// Temporary outputs (staging folders, files before their rename) are removed when the command is
// stopped by SIGINT, SIGTERM or SIGHUP, so that an interrupted command leaves what a failed one
// leaves: nothing but what it had committed.
//
// InstallInterruptCleanup() must run first in main(), before any other thread exists: it blocks
// those signals in the calling thread, and so in every thread created later, and starts one
// thread that waits for them with sigwait(), removes the registered paths (ordinary code, no
// async-signal-safety limits) and then ends the process by the same signal, so that the parent
// sees the usual status. Signals the parent ignored (nohup, background jobs) stay ignored.
// Without it (library users, tests) registration is bookkeeping only.
//
// It also ignores SIGXFSZ: a file-size limit then fails the write (EFBIG) like a full disk,
// which the normal error path cleans up, instead of killing the process mid-file.
void InstallInterruptCleanup();

// Runs `commits` (several RemoveOnInterrupt::Commit calls) where no clean-up can run between
// them: an interruption sees all the temporaries or all the committed results.
void HoldInterruptCleanup(const std::function<void()>& commits);

// Registers `path` (a file or folder) for removal on interruption during the object's life.
class RemoveOnInterrupt {
 public:
  explicit RemoveOnInterrupt(std::string path);
  ~RemoveOnInterrupt();
  RemoveOnInterrupt(const RemoveOnInterrupt&) = delete;
  RemoveOnInterrupt& operator=(const RemoveOnInterrupt&) = delete;

  // Runs `rename` (the step that gives the path its final name) where no clean-up can run, and
  // then stops watching the path: an interruption sees either the temporary or the committed
  // result, never a removal halfway through a commit. If `rename` throws, the path stays watched.
  void Commit(const std::function<void()>& rename);

 private:
  unsigned long id_;
  bool watched_ = true;
};

}  // namespace mbid
