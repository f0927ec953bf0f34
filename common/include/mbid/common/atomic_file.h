#pragma once

#include <memory>
#include <string>

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

}  // namespace mbid
