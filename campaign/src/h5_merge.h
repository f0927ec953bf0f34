#pragma once

#include <memory>
#include <string>
#include <vector>

namespace mbid::campaign::internal {

// Builds one HDF5 file out of others so that the same inputs give the same bytes, whatever the
// order or the time the inputs were written in: objects are created in name order and without
// modification times, and each input's objects are copied by HDF5's object copy (H5Ocopy), whose
// bytes follow from the input's (H5Writer writes no modification times either). This is what
// makes a campaign file bit-for-bit identical for 1 or 2 workers, or 2 MPI ranks.
//
// It calls the HDF5 C library directly, outside H5Writer's process-wide lock: use it only while
// no other thread uses HDF5 (the campaign merges after its workers have finished).
class DeterministicH5File {
 public:
  // Creates (truncates) `path`. Throws std::runtime_error naming the file on failure.
  explicit DeterministicH5File(const std::string& path);
  ~DeterministicH5File();
  DeterministicH5File(const DeterministicH5File&) = delete;
  DeterministicH5File& operator=(const DeterministicH5File&) = delete;

  // Creates `group` (absolute, its parent must exist).
  void CreateGroup(const std::string& group);
  // Copies every object under `source`'s root (recursively, with attributes) into `group` (which
  // is created unless it is "/" or exists), and the root's attributes onto `group`, except
  // those named in `skip_root_attributes`.
  void CopyTree(const std::string& source, const std::string& group,
                const std::vector<std::string>& skip_root_attributes);
  // Flushes and closes; the file is complete after this.
  void Close();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mbid::campaign::internal
