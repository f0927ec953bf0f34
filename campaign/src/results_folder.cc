#include "results_folder.h"

#include <fmt/format.h>
#include <zlib.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "mbid/campaign/campaign_case.h"
#include "mbid/common/atomic_file.h"
#include "mbid/common/crash_point.h"
#include "mbid/common/error.h"
#include "mbid/common/json_io.h"

namespace mbid::campaign::internal {
namespace {

namespace fs = std::filesystem;

constexpr char kManifest[] = "campaign.json";
constexpr char kMerged[] = "campaign.h5";
constexpr char kFormat[] = "mbid-campaign";
constexpr int kFormatVersion = 1;
// A case file written completely but not yet renamed to its checksummed name.
constexpr char kUnsealed[] = ".unsealed.h5";

// CRC-32 (zlib) of a file's bytes: catches the zeroed or lost blocks a power cut leaves in a
// file that was renamed but never synced.
uint32_t FileCrc32(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot be read: " + std::strerror(errno));
  uLong crc = crc32(0L, Z_NULL, 0);
  std::vector<char> buffer(1 << 16);
  while (in) {
    in.read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
    const std::streamsize got = in.gcount();
    if (got > 0)
      crc = crc32(crc, reinterpret_cast<const Bytef*>(buffer.data()), static_cast<uInt>(got));
  }
  if (in.bad()) throw std::runtime_error(path + ": read failed");
  return static_cast<uint32_t>(crc);
}

// "<id>.<8 hex digits>.h5" -> id and checksum; false for any other name.
bool ParseCommittedName(const std::string& name, std::string* id, uint32_t* crc) {
  constexpr size_t kHex = 8;
  if (name.size() < kHex + 5 || name.compare(name.size() - 3, 3, ".h5") != 0) return false;
  const size_t dot = name.size() - 3 - kHex - 1;
  if (name[dot] != '.') return false;
  const std::string hex = name.substr(dot + 1, kHex);
  if (hex.find_first_not_of("0123456789abcdef") != std::string::npos) return false;
  *id = name.substr(0, dot);
  *crc = static_cast<uint32_t>(std::stoul(hex, nullptr, 16));
  return !id->empty();
}

// Only names this program writes are ever removed (AtomicFile's temporaries, the case files'
// own and unsealed ones): a file of the user's in the folder (or in cases/) stays.
bool IsTemporaryName(const std::string& name) {
  return ParseAtomicTemporaryName(name, nullptr, nullptr);
}

bool IsUnsealedName(const std::string& name) {
  const size_t length = sizeof(kUnsealed) - 1;
  return name.size() > length && name.compare(name.size() - length, length, kUnsealed) == 0;
}

// What a kill between creating the folder and committing the manifest leaves: nothing, an
// empty cases/ or a temporary of the manifest. Such a folder starts afresh.
bool IsHalfCreated(const fs::path& dir) {
  std::error_code error;
  for (const auto& entry : fs::directory_iterator(dir, error)) {
    const std::string name = entry.path().filename().string();
    if (name == "cases" && fs::is_directory(entry.path()) && fs::is_empty(entry.path())) continue;
    // WriteJson commits through AtomicFile: "campaign.json.tmp-<pid>-<n>".
    if (name.rfind(kManifest, 0) == 0 && name.find(".tmp-") != std::string::npos) continue;
    return false;
  }
  return !error;
}

}  // namespace

std::string ResultsFolder::Path(const std::string& name) const {
  return (fs::path(dir_) / name).string();
}

ResultsFolder::State ResultsFolder::Prepare(const Campaign& campaign, bool resume) const {
  const fs::path dir(dir_);
  const fs::path manifest_path = dir / kManifest;
  std::error_code error;
  if (fs::exists(manifest_path)) {
    if (!resume) {
      throw InputError(dir_, "", "holds a campaign already (" + std::string(kManifest) + ")",
                       "--resume to finish it, or a new output folder");
    }
    const nlohmann::json manifest = ReadJson(manifest_path.string());
    const std::string fingerprint = manifest.value("fingerprint", "");
    if (manifest.value("format", "") != kFormat || fingerprint != campaign.Fingerprint()) {
      throw InputError(manifest_path.string(), "fingerprint",
                       "the folder was started by a different campaign or base scenario",
                       "the same campaign file and base scenario as the run that started it, or "
                       "a new output folder");
    }
    if (fs::exists(dir / kMerged)) return State::kComplete;
    fs::create_directories(dir / "cases", error);
    return State::kResumed;
  }
  if (fs::exists(dir) && !(fs::is_directory(dir) && IsHalfCreated(dir))) {
    throw InputError(dir_, "", "exists and is not a campaign folder",
                     "a new or empty output folder");
  }
  // The manifest first: from then on the folder is this campaign's, whatever happens next.
  fs::create_directories(dir, error);
  if (error || !fs::is_directory(dir)) {
    throw InputError(dir_, "", "cannot create the folder (" + error.message() + ")",
                     "a writable location for the results");
  }
  WriteJson({{"format", kFormat},
             {"format_version", kFormatVersion},
             {"name", campaign.name},
             {"fingerprint", campaign.Fingerprint()},
             {"cases", campaign.cases.size()}},
            manifest_path.string());
  CrashPoint("campaign-manifest");
  fs::create_directories(dir / "cases", error);
  if (error || !fs::is_directory(dir / "cases")) {
    throw InputError(dir_, "", "cannot create cases/ (" + error.message() + ")",
                     "a writable location for the results");
  }
  return State::kNew;
}

ResultsFolder::Scan ResultsFolder::ScanCommitted(const Campaign& campaign) const {
  std::map<std::string, size_t> index;
  for (size_t i = 0; i < campaign.cases.size(); ++i) index[campaign.cases[i].id] = i;
  Scan scan;
  scan.committed.assign(campaign.cases.size(), false);
  std::error_code error;
  // Temporaries of a process that was killed (AtomicFile names them "<file>.tmp-<pid>-<n>"),
  // unsealed case files that lost their process before the checksummed rename, and case files
  // of cases this campaign does not have go; committed cases are checked against their CRC-32.
  // Any other file is the user's and stays (a note put in cases/ was deleted on --resume).
  for (const auto& entry : fs::directory_iterator(fs::path(dir_) / "cases", error)) {
    const std::string path = entry.path().string();
    const std::string name = entry.path().filename().string();
    std::string id;
    uint32_t expected = 0;
    const bool committed_name = ParseCommittedName(name, &id, &expected);
    const auto it = committed_name ? index.find(id) : index.end();
    if (IsTemporaryName(name) || IsUnsealedName(name) || (committed_name && it == index.end())) {
      std::error_code ignored;
      if (entry.is_regular_file(ignored)) fs::remove(entry.path(), ignored);
      continue;
    }
    if (!committed_name) continue;  // not a file of this program's
    std::string why;
    try {
      const uint32_t actual = FileCrc32(path);
      if (actual == expected) {
        // The bytes this program committed (CRC-32 as in the name): no probe in a child.
        ReadCaseRow(path, H5Reader::Probe::kNone);
        scan.committed[it->second] = true;
        continue;
      }
      why = fmt::format("damaged file (CRC-32 {:08x}, committed as {:08x})", actual, expected);
    } catch (const std::exception& failure) {
      why = failure.what();
    }
    fs::remove(entry.path(), error);
    scan.damaged.push_back(id + ": " + why);
  }
  for (const auto& entry : fs::directory_iterator(dir_, error)) {
    if (IsTemporaryName(entry.path().filename().string())) fs::remove_all(entry.path(), error);
  }
  return scan;
}

void ResultsFolder::CommitCase(const std::string& case_id,
                               const std::function<void(const std::string& path)>& write) const {
  const fs::path cases = fs::path(dir_) / "cases";
  const std::string unsealed = (cases / (case_id + kUnsealed)).string();
  write(unsealed);
  CrashPoint("case-unsealed");
  const std::string sealed =
      (cases / fmt::format("{}.{:08x}.h5", case_id, FileCrc32(unsealed))).string();
  if (std::rename(unsealed.c_str(), sealed.c_str()) != 0) {
    throw std::runtime_error(
        fmt::format("cannot commit case file {}: {}", sealed, std::strerror(errno)));
  }
}

std::map<std::string, std::string> ResultsFolder::FindCommittedCases() const {
  std::map<std::string, std::string> found;
  std::error_code error;
  for (const auto& entry : fs::directory_iterator(fs::path(dir_) / "cases", error)) {
    std::string id;
    uint32_t crc = 0;
    if (ParseCommittedName(entry.path().filename().string(), &id, &crc)) {
      found[id] = entry.path().string();
    }
  }
  return found;
}

void ResultsFolder::RemoveCases() const {
  // The case files and their temporaries; cases/ itself only when nothing else is in it.
  const fs::path cases = fs::path(dir_) / "cases";
  std::error_code error;
  for (const auto& entry : fs::directory_iterator(cases, error)) {
    const std::string name = entry.path().filename().string();
    std::string id;
    uint32_t crc = 0;
    std::error_code ignored;
    if ((ParseCommittedName(name, &id, &crc) || IsUnsealedName(name) || IsTemporaryName(name)) &&
        entry.is_regular_file(ignored)) {
      fs::remove(entry.path(), ignored);
    }
  }
  fs::remove(cases, error);  // fails, and keeps it, where the user's files are
}

}  // namespace mbid::campaign::internal
