#pragma once

#include <memory>
#include <string>
#include <vector>

#include "mbid/common/interrupt_cleanup.h"

namespace mbid {

// An output file that appears under its final name only when complete. Write to temp_path();
// Commit() renames it into place; destruction without Commit() removes the temporary, so a
// failed command leaves nothing behind (docs/interfaces: exit codes).
//
// The temporary is "<path>.tmp-<pid>-<n>" beside the target; SIGINT/SIGTERM remove it
// (interrupt_cleanup.h). Commit() syncs it to disk before the rename and the folder after it, so
// that a crash leaves the old file or the new one, complete. An existing regular file is
// replaced (the user named it). The constructor throws InputError when the target's directory
// does not exist or the target exists and is not a regular file (a folder, a device: a bad output
// flag); Commit() throws std::runtime_error when nothing was written, the sync or the rename
// fails.
class AtomicFile {
 public:
  // `sync` false skips the fsyncs, for files whose reader checks them anyway (a campaign's case
  // files: --resume reads each back and runs a damaged case again).
  explicit AtomicFile(std::string path, bool sync = true);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  const std::string& path() const { return path_; }
  const std::string& temp_path() const { return temp_path_; }
  void Commit();

 private:
  std::string path_;
  std::string temp_path_;
  std::unique_ptr<RemoveOnInterrupt> interrupt_cleanup_;
  bool sync_;
  bool committed_ = false;
};

// A command's outputs committed together. While an OutputSet lives (at most one per process),
// AtomicFile::Commit() syncs its temporary and hands the rename to the set; Commit() then renames
// them all where no SIGINT, SIGTERM or SIGHUP clean-up can run in between, `.json` summaries
// last (they name the others). An interruption between two commits had left a --json summary
// naming an -o file that was never written, and the rerun refused as the summary existed.
// Destroyed without Commit() (a failure, a non-zero exit), it removes the temporaries. kill -9
// between two renames (microseconds: every file is synced before) can still leave the first.
class OutputSet {
 public:
  OutputSet();
  ~OutputSet();
  OutputSet(const OutputSet&) = delete;
  OutputSet& operator=(const OutputSet&) = delete;

  void Commit();

 private:
  friend class AtomicFile;
  struct Pending {
    std::string path, temp_path;
    std::unique_ptr<RemoveOnInterrupt> interrupt_cleanup;
    bool sync = true;
  };
  // Takes a synced temporary and its clean-up; false (nothing taken) when no set is active.
  static bool Defer(const std::string& path, const std::string& temp_path,
                    std::unique_ptr<RemoveOnInterrupt>* interrupt_cleanup, bool sync);
  std::vector<Pending> pending_;
  bool committed_ = false;
};

// A command's file named on its command line: the flag or argument that names it ("--json",
// "-o", "DATA") and the path.
struct NamedFile {
  std::string flag;
  std::string path;
};

// Throws InputError (naming the output's flag and path) when an output names the same file as
// an input (replacing it would destroy the user's record) or as another output (one of the two
// would be lost). Outputs "" and "-" (standard output) are skipped. Same file: the same path
// once made absolute and normal, or, where both exist, one file under two names (a link).
void CheckOutputsAreNew(const std::vector<NamedFile>& inputs,
                        const std::vector<NamedFile>& outputs);

// Whether the file name `name` is an AtomicFile temporary, "<target>.tmp-<pid>-<n>" (or a
// figure's scratch file beside one: the same with ".dat", ".gp" or ".log"); if so,
// `target` and `pid` (either may be null) receive its target's file name and its writer's pid.
bool ParseAtomicTemporaryName(const std::string& name, std::string* target, int* pid);

// Throws InputError when an output's name holds a line break or another control character
// (a script's variable with its newline): the figures' gnuplot scripts cannot name such a file,
// and a run failed after all its work. Checked by AtomicFile, OutputFolder and
// CheckOutputsReplaceable, before any work.
void CheckOutputName(const std::string& path);

// Throws InputError (naming the output's flag and path) before any work when an output's folder
// does not exist, or the output exists and `overwrite` is false: nothing of the user's is
// replaced unasked (--overwrite). Outputs "" and "-" are skipped.
void CheckOutputsReplaceable(const std::vector<NamedFile>& outputs, bool overwrite);

}  // namespace mbid
