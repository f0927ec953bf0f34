#pragma once

#include <filesystem>
#include <functional>
#include <memory>
#include <string>

#include "mbid/common/interrupt_cleanup.h"

namespace mbid {

// A results folder that appears under its final name only when complete, and never at the cost of
// what was there before:
//
// - it is built in ".<name>.tmp-<pid>" beside the final folder, with a marker file
//   (kMarkerFile, naming the kind of results) that tells mbid's folders from anyone else's;
// - an existing final folder is refused (InputError naming it: exit code 2) unless it is empty,
//   or `overwrite` is set and `is_previous` recognises it as results of the same kind;
// - Commit() syncs every file and the folder, then swaps the two folders in one step
//   (renameat2 RENAME_EXCHANGE; where the file system lacks it, the old folder is renamed aside
//   to ".<name>.old-<pid>" first) and removes the old results last;
// - staging folders of processes that no longer exist (kill -9, power loss) are removed from
//   the parent folder on the next use; an old folder renamed aside whose replacement never
//   arrived is renamed back;
// - SIGINT/SIGTERM remove the staging folder (interrupt_cleanup.h); so does destruction without
//   Commit().
class OutputFolder {
 public:
  static constexpr const char* kMarkerFile = ".mbid-output";

  // Whether an existing folder holds results of this kind and nothing else.
  using Recogniser = std::function<bool(const std::filesystem::path& folder)>;

  OutputFolder(const std::filesystem::path& final_path, std::string kind, bool overwrite,
               Recogniser is_previous);
  ~OutputFolder();
  OutputFolder(const OutputFolder&) = delete;
  OutputFolder& operator=(const OutputFolder&) = delete;

  std::filesystem::path operator/(const std::string& name) const { return staging_ / name; }
  const std::filesystem::path& staging_path() const { return staging_; }
  // Throws InputError if the final folder changed into something that may not be replaced while
  // the results were built, std::runtime_error if the disk refuses; the staging folder is then
  // removed and whatever was there before is untouched.
  void Commit();

  // Whether `folder` carries the marker of `kind`.
  static bool HasMarker(const std::filesystem::path& folder, const std::string& kind);

 private:
  void CheckFinal() const;

  std::filesystem::path final_;  // absolute and normalized
  std::string shown_;            // as the user wrote it, for messages
  std::string kind_;
  bool overwrite_;
  Recogniser is_previous_;
  std::filesystem::path staging_;
  std::unique_ptr<RemoveOnInterrupt> interrupt_cleanup_;
  bool committed_ = false;
};

// `name` as one safe folder or file name: path separators, control characters and a leading dot
// (".", "..", hidden names) become '_'; at most 200 bytes (room for the staging suffix within
// NAME_MAX), cut at a UTF-8 character boundary. Throws InputError (`source`, `field`) if empty.
std::string SafeFileName(const std::string& name, const std::string& source,
                         const std::string& field);

}  // namespace mbid
