// Extension -> reader. A new format is one line in kFormats (and its reader in readers.h).
#include "formats.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cctype>

#include "mbid/common/error.h"
#include "mbid/records/records.h"
#include "readers.h"

namespace mbid::records {
namespace {

struct Format {
  std::vector<std::string> extensions;  // lower case, with the dot
  // The user's time unit goes to readers that must apply it before checking the time base.
  internal::RawTable (*read)(const std::string& path, const std::string& time_unit);
};

const std::vector<Format>& Formats() {
  static const std::vector<Format> formats = {
      {{".csv", ".txt", ".tsv", ".dat", ".asc"},
       [](const std::string& p, const std::string&) { return internal::ReadCsv(p); }},
      {{".h5", ".hdf5"}, &internal::ReadHdf5},
      {{".uff", ".unv", ".uff58", ".uffb"},
       [](const std::string& p, const std::string&) { return internal::ReadUff58(p); }},
      {{".lvm"}, [](const std::string& p, const std::string&) { return internal::ReadLvm(p); }},
      {{".mat"}, [](const std::string& p, const std::string&) { return internal::ReadMat(p); }},
  };
  return formats;
}

}  // namespace

std::string LowerExtension(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  const size_t dot = path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  std::string extension = path.substr(dot);
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension;
}

std::vector<std::string> SupportedExtensions() {
  std::vector<std::string> extensions;
  for (const Format& format : Formats()) {
    extensions.insert(extensions.end(), format.extensions.begin(), format.extensions.end());
  }
  return extensions;
}

bool IsSupportedFile(const std::string& path) {
  const std::vector<std::string> extensions = SupportedExtensions();
  return std::find(extensions.begin(), extensions.end(), LowerExtension(path)) != extensions.end();
}

namespace internal {

RawTable ReadRawTable(const std::string& path, const std::string& time_unit) {
  const std::string extension = LowerExtension(path);
  for (const Format& format : Formats()) {
    const auto& extensions = format.extensions;
    if (std::find(extensions.begin(), extensions.end(), extension) != extensions.end()) {
      return format.read(path, time_unit);
    }
  }
  throw InputError(
      path, "", fmt::format("unsupported file type '{}'", extension.empty() ? "(none)" : extension),
      fmt::format("a measurement file ({})", fmt::join(SupportedExtensions(), ", ")));
}

}  // namespace internal
void CheckHdf5OutputName(const std::string& path) {
  if (path.empty() || path == "-") return;
  const std::string extension = LowerExtension(path);
  if (extension == ".h5" || extension == ".hdf5" || !IsSupportedFile(path)) return;
  throw InputError(path, "", "'" + extension + "' names another record format, and -o writes HDF5",
                   "a .h5 file name (mbid simulate --export writes .csv, .uff, .uffb and .mat)");
}

}  // namespace mbid::records
