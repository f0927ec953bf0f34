#include "mbid/common/output_folder.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <system_error>

#include "internal.h"
#include "mbid/common/atomic_file.h"
#include "mbid/common/crash_point.h"
#include "mbid/common/error.h"

namespace mbid {
namespace {

namespace fs = std::filesystem;

constexpr char kMarkerFormat[] = "mbid-output";
constexpr size_t kMaxNameBytes = 200;  // NAME_MAX 255 less ".", ".tmp-" and a pid

// The pid of a staging (".<name>.tmp-<pid>") or aside (".<name>.old-<pid>") folder, and its
// final name; 0 if `entry` is neither.
pid_t ParseTemporary(const std::string& entry, const char* tag, std::string* final_name) {
  if (entry.size() < 2 || entry[0] != '.') return 0;
  const size_t at = entry.rfind(tag);
  if (at == std::string::npos || at < 2) return 0;
  const std::string digits = entry.substr(at + std::char_traits<char>::length(tag));
  if (digits.empty() || digits.size() > 9 ||
      digits.find_first_not_of("0123456789") != std::string::npos) {
    return 0;
  }
  *final_name = entry.substr(1, at - 1);
  return static_cast<pid_t>(std::stol(digits));
}

// Files first, then the folders that hold them, so that the rename commits synced entries.
void SyncTree(const fs::path& folder) {
  for (const auto& entry : fs::recursive_directory_iterator(folder)) {
    if (entry.is_regular_file()) internal::SyncFile(entry.path().string());
  }
  for (const auto& entry : fs::recursive_directory_iterator(folder)) {
    if (entry.is_directory()) internal::SyncFolder(entry.path().string());
  }
  internal::SyncFolder(folder.string());
}

}  // namespace

bool OutputFolder::HasMarker(const fs::path& folder, const std::string& kind) {
  std::ifstream in(folder / kMarkerFile);
  if (!in) return false;
  const nlohmann::json marker = nlohmann::json::parse(in, nullptr, false);
  return marker.is_object() && marker.value("format", "") == kMarkerFormat &&
         (kind.empty() || marker.value("kind", "") == kind);
}

OutputFolder::OutputFolder(const fs::path& final_path, std::string kind, bool overwrite,
                           Recogniser is_previous)
    : shown_(final_path.string()),
      kind_(std::move(kind)),
      overwrite_(overwrite),
      is_previous_(std::move(is_previous)) {
  if (final_path.empty()) throw InputError("(output)", "", "empty output folder", "a folder name");
  CheckOutputName(final_path.string());
  // "DIR/", "." and "a/.." name the folder before the separator.
  fs::path absolute = fs::absolute(final_path).lexically_normal();
  if (!absolute.has_filename()) absolute = absolute.parent_path();
  if (absolute == absolute.root_path()) {
    throw InputError(shown_, "", "is the root folder", "another output folder");
  }
  final_ = absolute;
  const fs::path parent = final_.parent_path();
  std::error_code error;
  fs::create_directories(parent, error);
  if (error || !fs::is_directory(parent)) {
    throw InputError(shown_, "", "cannot create the parent folder " + parent.string(),
                     "a writable location for the results");
  }
  CheckFinal();

  // Leftovers of processes that ended without cleaning up (kill -9, a crash, power loss).
  for (const auto& entry : fs::directory_iterator(parent, error)) {
    const std::string name = entry.path().filename().string();
    std::string final_name;
    std::error_code ignored;
    if (!entry.is_directory(ignored)) continue;
    if (const pid_t pid = ParseTemporary(name, ".tmp-", &final_name)) {
      if (internal::ProcessIsGone(pid) &&
          (HasMarker(entry.path(), "") || is_previous_(entry.path()))) {
        fs::remove_all(entry.path(), ignored);
      }
    } else if (const pid_t old_pid = ParseTemporary(name, ".old-", &final_name)) {
      if (!internal::ProcessIsGone(old_pid) ||
          !(HasMarker(entry.path(), "") || is_previous_(entry.path())))
        continue;
      // Renamed aside for a replacement that never arrived: the results are still wanted.
      const fs::path original = parent / final_name;
      if (!fs::exists(fs::symlink_status(original, ignored))) {
        fs::rename(entry.path(), original, ignored);
      } else if (fs::is_directory(fs::symlink_status(original, ignored)) &&
                 is_previous_(original)) {
        fs::remove_all(entry.path(), ignored);  // the replacement did arrive
      }
    }
  }

  staging_ = parent / fmt::format(".{}.tmp-{}", final_.filename().string(), ::getpid());
  interrupt_cleanup_ = std::make_unique<RemoveOnInterrupt>(staging_.string());
  fs::remove_all(staging_, error);  // an earlier process with the same pid
  if (!fs::create_directory(staging_, error) || error) {
    throw InputError(shown_, "",
                     "cannot create a folder in " + parent.string() + " (" + error.message() + ")",
                     "a writable location for the results");
  }
  std::ofstream(staging_ / kMarkerFile)
      << nlohmann::json{{"format", kMarkerFormat}, {"kind", kind_}} << "\n";
}

OutputFolder::~OutputFolder() {
  std::error_code ignored;
  if (!committed_ && !staging_.empty()) fs::remove_all(staging_, ignored);
}

void OutputFolder::CheckFinal() const {
  std::error_code error;
  const fs::file_status status = fs::symlink_status(final_, error);
  if (!fs::exists(status)) return;
  if (fs::is_symlink(status)) {
    throw InputError(shown_, "", "is a symbolic link", "another output folder");
  }
  if (!fs::is_directory(status)) {
    throw InputError(shown_, "", "exists and is not a folder", "another output folder");
  }
  if (fs::is_empty(final_, error) && !error) return;
  if (!is_previous_(final_)) {
    throw InputError(shown_, "",
                     "exists and is not an mbid " + kind_ + " folder (it holds other files)",
                     "another output folder (--overwrite replaces only an earlier mbid " + kind_ +
                         "'s results)");
  }
  if (!overwrite_) {
    throw InputError(shown_, "", "holds the results of an earlier mbid " + kind_,
                     "--overwrite to replace them, or another output folder");
  }
}

void OutputFolder::Commit() {
  if (committed_) throw std::logic_error("OutputFolder::Commit called twice for " + shown_);
  SyncTree(staging_);
  CheckFinal();  // the folder may have appeared or changed while the results were computed
  fs::path old;
  CrashPoint("folder-commit");
  interrupt_cleanup_->Commit([&] {
    std::error_code error;
    if (!fs::exists(fs::symlink_status(final_, error))) {
      fs::rename(staging_, final_, error);
      if (error) {
        throw std::runtime_error("cannot rename " + staging_.string() + " to " + shown_ + ": " +
                                 error.message());
      }
      return;
    }
    if (::renameat2(AT_FDCWD, staging_.c_str(), AT_FDCWD, final_.c_str(), RENAME_EXCHANGE) == 0) {
      old = staging_;  // now holds the earlier results
      return;
    }
    if (errno != EINVAL && errno != ENOSYS && errno != EOPNOTSUPP) {
      throw std::runtime_error("cannot exchange " + staging_.string() + " and " + shown_ + ": " +
                               std::strerror(errno));
    }
    // No atomic exchange here: the earlier results go aside first, and come back on failure.
    const fs::path aside =
        final_.parent_path() / fmt::format(".{}.old-{}", final_.filename().string(), ::getpid());
    fs::rename(final_, aside, error);
    if (error) {
      throw std::runtime_error("cannot rename " + shown_ + " aside: " + error.message());
    }
    fs::rename(staging_, final_, error);
    if (error) {
      std::error_code ignored;
      fs::rename(aside, final_, ignored);
      throw std::runtime_error("cannot rename " + staging_.string() + " to " + shown_ + ": " +
                               error.message());
    }
    old = aside;
  });
  committed_ = true;
  CrashPoint("folder-committed");
  internal::SyncFolder(final_.parent_path().string());
  std::error_code ignored;
  if (!old.empty()) fs::remove_all(old, ignored);
}

std::string SafeFileName(const std::string& name, const std::string& source,
                         const std::string& field) {
  if (name.empty()) throw InputError(source, field, "is empty", "a non-empty name");
  std::string safe;
  for (const char c : name) {
    const auto byte = static_cast<unsigned char>(c);
    safe += (c == '/' || c == '\\' || byte < 0x20 || byte == 0x7f) ? '_' : c;
  }
  if (safe[0] == '.') safe[0] = '_';
  if (safe.size() > kMaxNameBytes) {
    size_t size = kMaxNameBytes;
    while (size > 0 && (static_cast<unsigned char>(safe[size]) & 0xC0) == 0x80) --size;
    safe.resize(size);
  }
  return safe;
}

}  // namespace mbid
