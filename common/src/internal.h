#pragma once

// Helpers shared by the common sources; not part of the public API.

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "mbid/common/error.h"

namespace mbid::internal {

enum class ParseStatus { kOk, kNotANumber, kOutOfRange };

// Parses all of `text` as a decimal double, independent of the C locale. "nan"/"inf" parse
// (callers reject non-finite values with their own message); a leading '+' is accepted.
inline ParseStatus ParseDouble(std::string_view text, double* value) {
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);
  if (text.empty() || text.front() == '+' || text.front() == ' ') return ParseStatus::kNotANumber;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, *value);
  if (ptr != end) return ParseStatus::kNotANumber;
  if (ec == std::errc::result_out_of_range) {
    // from_chars also reports underflow to a subnormal; strtod gives the nearest value then.
    const std::string copy(text);
    const double v = std::strtod(copy.c_str(), nullptr);
    if (!std::isfinite(v)) return ParseStatus::kOutOfRange;
    *value = v;
    return ParseStatus::kOk;
  }
  if (ec != std::errc()) return ParseStatus::kNotANumber;
  return ParseStatus::kOk;
}

inline std::string Trim(std::string_view text) {
  const auto first = text.find_first_not_of(" \t\r\n");
  if (first == std::string_view::npos) return {};
  const auto last = text.find_last_not_of(" \t\r\n");
  return std::string(text.substr(first, last - first + 1));
}

inline std::string Join(const std::vector<std::string>& items, const std::string& separator) {
  std::string out;
  for (size_t i = 0; i < items.size(); ++i) {
    if (i > 0) out += separator;
    out += items[i];
  }
  return out;
}

// Whole file as text; a file that cannot be opened or read is an InputError naming it.
inline std::string ReadTextFile(const std::string& path, const std::string& expected) {
  // A folder opens and reads as nothing on Linux: said as what it is.
  std::error_code error_code;
  if (std::filesystem::is_directory(path, error_code)) {
    throw InputError(path, "", "is a folder", expected);
  }
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (file == nullptr) {
    throw InputError(path, "", std::string("cannot open: ") + std::strerror(errno), expected);
  }
  std::string text;
  char buffer[65536];
  size_t n = 0;
  while ((n = std::fread(buffer, 1, sizeof(buffer), file)) > 0) text.append(buffer, n);
  const bool failed = std::ferror(file) != 0;
  const int error = errno;
  std::fclose(file);
  if (failed)
    throw InputError(path, "", std::string("cannot read: ") + std::strerror(error), expected);
  return text;
}

// Throws the same "cannot open" InputError as ReadTextFile when `path` is not readable.
inline void CheckReadable(const std::string& path, const std::string& expected) {
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (file == nullptr) {
    throw InputError(path, "", std::string("cannot open: ") + std::strerror(errno), expected);
  }
  char byte = 0;
  const size_t n = std::fread(&byte, 1, 1, file);
  const bool failed = n == 0 && std::ferror(file) != 0;
  const int error = errno;
  std::fclose(file);
  if (failed)
    throw InputError(path, "", std::string("cannot read: ") + std::strerror(error), expected);
}

// MBID_NO_CHILD_PROBE is set (non-empty): HDF5 reads and writes run in this process, to debug a
// crash in-process (docs/reliability.md).
inline bool ChildProcessesOff() {
  const char* off = std::getenv("MBID_NO_CHILD_PROBE");
  return off != nullptr && *off != '\0';
}

// In a child forked while this thread held the HDF5 lock: a fresh HDF5 lock, crash signals back
// to their default action (so that the parent sees the crash), no core dump, standard output and
// error to /dev/null.
void PrepareCrashReportingChild();

// libhdf5 1.10 (and matio over it) can crash or loop for ever on a corrupt file, e.g. in its
// global-heap reads of variable-length strings, and no check before a call can rule that out.
// SurviveInChild runs `body` (the read) in a child process first and throws an InputError
// ("<library> crashed reading the file", with `expected`) if the child crashes or does not
// finish in time; a file it survives is then read in this process. Errors `body` throws are
// left to that second read. MBID_NO_CHILD_PROBE=1 turns it off (to debug a crash in-process).
void SurviveInChild(const std::string& path, const std::string& expected,
                    const std::string& library, const std::function<void()>& body);
// SurviveInChild with every attribute and dataset of an HDF5 file read as H5Reader reads them.
void ProbeHdf5InChild(const std::string& path, const std::string& expected);

// Writes `bytes` as the whole content of `path` (created or truncated); throws
// std::runtime_error naming the file and the system's reason (ENOSPC, EFBIG, EIO).
void WriteWholeFile(const std::string& path, const std::vector<char>& bytes);
// fsync of a written file, so that the rename that commits it cannot reach the disk before its
// data; throws std::runtime_error naming the file (EIO, ENOSPC: the data is not safe).
void SyncFile(const std::string& path);
// fsync of a folder, so that renames and new entries in it survive a crash. Best effort: file
// systems that cannot sync folders (EINVAL) are not an error.
void SyncFolder(const std::string& path);

// True when no process `pid` exists (kill(pid, 0) fails with ESRCH; EPERM means it exists and is
// not ours) and it is not this one: its temporaries will never be committed.
bool ProcessIsGone(int pid);

}  // namespace mbid::internal
