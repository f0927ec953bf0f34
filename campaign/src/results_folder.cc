#include "results_folder.h"

#include <filesystem>
#include <nlohmann/json.hpp>

#include "mbid/campaign/campaign_case.h"
#include "mbid/common/error.h"
#include "mbid/common/json_io.h"

namespace mbid::campaign::internal {
namespace {

namespace fs = std::filesystem;

constexpr char kManifest[] = "campaign.json";
constexpr char kMerged[] = "campaign.h5";
constexpr char kFormat[] = "mbid-campaign";
constexpr int kFormatVersion = 1;

}  // namespace

std::string ResultsFolder::CasePath(const std::string& case_id) const {
  return (fs::path(dir_) / "cases" / (case_id + ".h5")).string();
}

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
  if (fs::exists(dir) && !(fs::is_directory(dir) && fs::is_empty(dir))) {
    throw InputError(dir_, "", "exists and is not a campaign folder",
                     "a new or empty output folder");
  }
  fs::create_directories(dir / "cases", error);
  if (error || !fs::is_directory(dir / "cases")) {
    throw InputError(dir_, "", "cannot create the folder (" + error.message() + ")",
                     "a writable location for the results");
  }
  WriteJson({{"format", kFormat},
             {"format_version", kFormatVersion},
             {"name", campaign.name},
             {"fingerprint", campaign.Fingerprint()},
             {"cases", campaign.cases.size()}},
            manifest_path.string());
  return State::kNew;
}

std::vector<bool> ResultsFolder::ScanCommitted(const Campaign& campaign) const {
  const fs::path cases = fs::path(dir_) / "cases";
  std::error_code error;
  // Temporaries of a process that was killed: AtomicFile names them "<file>.tmp-<pid>-<n>".
  for (const auto& entry : fs::directory_iterator(cases, error)) {
    if (entry.path().filename().string().find(".tmp-") != std::string::npos) {
      fs::remove(entry.path(), error);
    }
  }
  for (const auto& entry : fs::directory_iterator(dir_, error)) {
    if (entry.path().filename().string().find(".tmp-") != std::string::npos) {
      fs::remove_all(entry.path(), error);
    }
  }
  std::vector<bool> committed(campaign.cases.size(), false);
  for (size_t i = 0; i < campaign.cases.size(); ++i) {
    const std::string path = CasePath(campaign.cases[i].id);
    if (!fs::exists(path)) continue;
    try {
      ReadCaseRow(path);
      committed[i] = true;
    } catch (const std::exception&) {
      fs::remove(path, error);  // not a complete case file: run the case again
    }
  }
  return committed;
}

void ResultsFolder::RemoveCases() const {
  std::error_code error;
  fs::remove_all(fs::path(dir_) / "cases", error);
}

}  // namespace mbid::campaign::internal
