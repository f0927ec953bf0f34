#pragma once

#include <string>

namespace mbid {

// An output file that appears under its final name only when complete. Write to temp_path();
// Commit() renames it into place; destruction without Commit() removes the temporary, so a
// failed command leaves nothing behind (docs/interfaces: exit codes).
class AtomicFile {
 public:
  explicit AtomicFile(std::string path);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  const std::string& path() const { return path_; }
  const std::string& temp_path() const { return temp_path_; }
  void Commit();

 private:
  std::string path_;
  std::string temp_path_;
  bool committed_ = false;
};

}  // namespace mbid
