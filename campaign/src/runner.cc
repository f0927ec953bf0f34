#include <fmt/format.h>
#include <malloc.h>

#include <algorithm>
#include <condition_variable>
#include <exception>
#include <filesystem>
#include <mutex>
#include <optional>
#include <system_error>
#include <thread>

#include "cluster.h"
#include "commit_queue.h"
#include "h5_merge.h"
#include "mbid/campaign/campaign_case.h"
#include "mbid/campaign/campaign_runner.h"
#include "mbid/common/atomic_file.h"
#include "mbid/common/crash_point.h"
#include "mbid/common/hdf5_io.h"
#include "mbid/common/write_in_child.h"
#include "progress.h"
#include "report.h"
#include "results_folder.h"
#include "summary_table.h"

namespace mbid::campaign {
namespace {

namespace fs = std::filesystem;

// Rank 0's verdict on the folder, broadcast before any case runs.
enum Decision : int { kRun = 0, kAlreadyComplete = 1, kStop = 2 };

// Every case builds a model, integrates and writes a file: the same allocations case after case.
// glibc returns freed memory above 128 KiB to the kernel and maps large blocks one by one, so
// each case faults its pages in again (about 2000 page faults per case of the reference crane),
// and worker threads queue for the address-space lock those faults and mappings take. Keeping
// freed memory in the process (at most the campaign's peak) removes 96% of the faults.
void KeepFreedMemory() {
  static std::once_flag once;
  std::call_once(once, [] {
    mallopt(M_TRIM_THRESHOLD, 256 << 20);
    mallopt(M_MMAP_THRESHOLD, 32 << 20);
  });
}

// The campaign's own metadata (/campaign): what ran and with which settings, without paths (a
// local run and an MPI run from another folder give the same file).
void WriteCampaignInfo(const Campaign& campaign, const std::vector<nlohmann::ordered_json>& rows,
                       const std::string& path) {
  H5Writer file(path);
  file.WriteStringAttribute("/campaign", "name", campaign.name);
  file.WriteStringAttribute("/campaign", "yaml", campaign.text);
  file.WriteStringAttribute("/campaign", "base_yaml", campaign.base_text);
  file.WriteStringAttribute("/campaign", "fingerprint", campaign.Fingerprint());
  file.WriteDoubleAttribute("/campaign", "seed", static_cast<double>(campaign.seed));
  std::vector<std::string> steps{"modes"};
  if (campaign.steps.simulate) steps.push_back("simulate");
  if (campaign.steps.identify) steps.push_back("identify");
  if (campaign.steps.update) steps.push_back("update");
  file.WriteStrings("/campaign", "steps", steps);
  file.WriteStrings("/campaign", "swept_keys", campaign.swept_keys);
  std::vector<std::string> ids, status;
  for (const auto& row : rows) {
    ids.push_back(row["case_id"].get<std::string>());
    status.push_back(row["status"].get<std::string>());
  }
  file.WriteStrings("/campaign", "case_ids", ids);
  file.WriteStrings("/campaign", "status", status);
  file.Commit();
}

// Everything after the last case: summary.csv, the study, report.md with figures, and last
// campaign.h5, whose rename completes the campaign. `known_rows[i]`: case i's row as its file
// holds it, where this process committed it (the others, resumed or from other ranks, are read).
int FinishCampaign(const Campaign& campaign, const internal::ResultsFolder& folder,
                   const internal::CampaignProgress& progress,
                   std::vector<std::optional<nlohmann::ordered_json>> known_rows) {
  std::vector<nlohmann::ordered_json> rows;
  rows.reserve(campaign.cases.size());
  int failed = 0;
  const std::map<std::string, std::string> case_files = folder.FindCommittedCases();
  const auto case_file = [&](const std::string& id) {
    const auto it = case_files.find(id);
    if (it == case_files.end()) {
      throw std::runtime_error("campaign " + campaign.name + ": the file of case " + id +
                               " disappeared from " + folder.Path("cases"));
    }
    return it->second;
  };
  // Every case file was written by this run or passed the resume scan's CRC-32 check: no
  // child process per file (a fork of this process and its wait were most of the merge).
  for (size_t i = 0; i < campaign.cases.size(); ++i) {
    std::optional<nlohmann::ordered_json>& known = known_rows[i];
    rows.push_back(known ? std::move(*known)
                         : ReadCaseRow(case_file(campaign.cases[i].id), H5Reader::Probe::kNone));
    if (rows.back()["status"] != "ok") ++failed;
  }
  internal::WriteSummaryCsv(rows, folder.Path("summary.csv"));

  const std::string info_path = folder.Path(".campaign-info.h5");
  const std::string study_path = folder.Path(".study.h5");
  WriteCampaignInfo(campaign, rows, info_path);
  StudyReport study;
  if (campaign.study) {
    study = campaign.study->Run({campaign, rows, folder.Path(""), study_path,
                                 [&progress](const std::string& line) { progress.Say(line); }});
  }
  const std::vector<std::string> figures =
      internal::WriteCampaignReport(campaign, rows, folder.Path(""), study);

  AtomicFile merged(folder.Path("campaign.h5"));
  // In a child process: HDF5 crashes when the file system refuses its writes (write_in_child.h).
  WriteInChild(merged.path(), [&] {
    internal::DeterministicH5File file(merged.temp_path());
    file.CopyTree(info_path, "/", {});
    file.CreateGroup("/cases");
    for (const CampaignCase& one_case : campaign.cases) {
      file.CopyTree(case_file(one_case.id), "/cases/" + one_case.id,
                    {"format", "format_version", "row"});
    }
    if (fs::exists(study_path)) file.CopyTree(study_path, "/", {"format", "format_version"});
    file.Close();
  });
  CrashPoint("campaign-merge");
  merged.Commit();
  CrashPoint("campaign-merged");
  std::error_code ignored;
  fs::remove(info_path, ignored);
  fs::remove(study_path, ignored);
  folder.RemoveCases();
  progress.Say(fmt::format("wrote campaign.h5, summary.csv and report.md ({} figures) in {}",
                           figures.size(), folder.Path("")));
  return failed;
}

}  // namespace

CampaignRunSummary RunCampaign(const Campaign& campaign, const std::string& output_dir,
                               const CampaignRunOptions& options, internal::Cluster* cluster_in) {
  std::unique_ptr<internal::Cluster> own_cluster;
  if (cluster_in == nullptr) own_cluster = internal::MakeSingleProcess();
  internal::Cluster& cluster = cluster_in != nullptr ? *cluster_in : *own_cluster;
  const auto start = std::chrono::steady_clock::now();
  KeepFreedMemory();

  CampaignRunSummary summary;
  summary.cases = static_cast<int>(campaign.cases.size());
  summary.ranks = cluster.size();
  summary.workers =
      options.workers > 0
          ? options.workers
          : (cluster.distributed()
                 ? 1  // mpirun placed one rank per core
                 : std::max(1, static_cast<int>(std::thread::hardware_concurrency())));

  const internal::ResultsFolder folder(output_dir);
  std::vector<int> pending;
  std::vector<std::string> damaged;
  std::exception_ptr folder_error;
  int decision = kRun;
  if (cluster.is_root()) {
    try {
      if (folder.Prepare(campaign, options.resume) == internal::ResultsFolder::State::kComplete) {
        decision = kAlreadyComplete;
        // A kill between the final rename and the clean-up leaves the case files behind.
        folder.RemoveCases();
        std::error_code ignored;
        fs::remove(folder.Path(".campaign-info.h5"), ignored);
        fs::remove(folder.Path(".study.h5"), ignored);
      } else {
        const internal::ResultsFolder::Scan scan = folder.ScanCommitted(campaign);
        for (size_t i = 0; i < scan.committed.size(); ++i) {
          if (!scan.committed[i]) pending.push_back(static_cast<int>(i));
        }
        damaged = scan.damaged;
      }
    } catch (...) {
      folder_error = std::current_exception();
      decision = kStop;
    }
  }
  decision = cluster.Broadcast(decision);
  if (decision == kStop) {
    if (folder_error) std::rethrow_exception(folder_error);
    summary.stopped_before_running = true;
    return summary;
  }
  summary.already_committed = summary.cases - static_cast<int>(pending.size());
  summary.damaged_cases = damaged;
  internal::CampaignProgress progress(campaign.name, summary.cases, summary.already_committed,
                                      options.quiet || !cluster.is_root());
  if (decision == kAlreadyComplete) {
    summary.was_complete = true;
    summary.already_committed = summary.cases;
    progress.Say("already complete (" + folder.Path("campaign.h5") + "); nothing to do");
    return summary;
  }
  progress.Say(
      fmt::format("{} cases{}; running {} on {} rank{} x {} worker{}", summary.cases,
                  summary.already_committed > 0
                      ? fmt::format(", resuming: {} already committed", summary.already_committed)
                      : "",
                  pending.size(), cluster.size(), cluster.size() > 1 ? "s" : "", summary.workers,
                  summary.workers > 1 ? "s" : ""));

  std::condition_variable wakeup;
  std::mutex wakeup_mutex;
  internal::WorkQueue queue(wakeup, summary.workers);
  internal::Tally tally;
  std::atomic<int> running{summary.workers + 1};
  std::mutex error_mutex;
  std::exception_ptr worker_error;
  // Taking the mutex before notifying makes the main thread's predicate wait race-free.
  const auto notify_main = [&] {
    std::lock_guard<std::mutex> lock(wakeup_mutex);
    wakeup.notify_all();
  };
  // Workers compute cases and hand them to one committer thread, which writes their files.
  // `running` counts both: the campaign's threads are done when it is 0.
  internal::CommitQueue commits(summary.workers);
  // Each committed case's row, parsed from the text its file holds, so that the summary need
  // not open the files again (1.6 M instructions a case, a tenth of the serial finish).
  std::vector<std::optional<nlohmann::ordered_json>> committed_rows(campaign.cases.size());
  std::atomic<int> computing{summary.workers};
  std::vector<std::thread> threads;
  const auto fail = [&] {
    // Not a case's failure (those are results) but the campaign's: its files cannot be
    // written. Stop taking and committing cases.
    std::lock_guard<std::mutex> lock(error_mutex);
    if (!worker_error) worker_error = std::current_exception();
    queue.Close();
    commits.Close();
  };
  const auto work = [&] {
    try {
      CaseCache cache;
      while (const std::optional<int> index = queue.Pop()) {
        if (!commits.Push(
                ComputeCase(campaign, campaign.cases[static_cast<size_t>(*index)], &cache))) {
          break;
        }
      }
    } catch (...) {
      fail();
    }
    if (--computing == 0) commits.Close();
    --running;
    notify_main();
  };
  const auto commit = [&] {
    try {
      while (const std::optional<CaseOutcome> outcome = commits.Pop()) {
        folder.CommitCase(outcome->id,
                          [&outcome](const std::string& path) { WriteCaseFile(*outcome, path); });
        const size_t index = static_cast<size_t>(outcome->index);
        if (outcome->index >= 0 && index < committed_rows.size() &&
            campaign.cases[index].id == outcome->id) {
          committed_rows[index] = nlohmann::ordered_json::parse(outcome->row.dump());
        }
        if (!outcome->ok()) ++tally.failed;
        ++tally.done;
        notify_main();
      }
    } catch (...) {
      fail();
    }
    --running;
    notify_main();
  };
  try {
    threads.emplace_back(commit);
    for (int w = 0; w < summary.workers; ++w) threads.emplace_back(work);
  } catch (const std::system_error& error) {
    // Out of threads or memory for their stacks: stop the ones that started, then fail like any
    // other campaign error (a joinable std::thread left behind would call std::terminate).
    const int started = static_cast<int>(threads.size());
    const int workers_started = std::max(0, started - 1);
    running -= summary.workers + 1 - started;
    computing -= summary.workers - workers_started;
    queue.Close();
    commits.Close();
    for (std::thread& thread : threads) thread.join();
    const std::string message =
        started == 0 ? fmt::format("cannot start the thread that commits cases: {}", error.what())
                     : fmt::format("cannot start worker thread {} of {}: {}", workers_started + 1,
                                   summary.workers, error.what());
    if (cluster.size() > 1) {
      std::fprintf(stderr, "mbid: failure: rank %d: %s\n", cluster.rank(), message.c_str());
      cluster.Abort(1);
    }
    throw std::runtime_error(message);
  }
  const auto cases_start = std::chrono::steady_clock::now();
  size_t cursor = 0;
  const auto next = [&]() { return cursor < pending.size() ? pending[cursor++] : -1; };
  while (true) {
    const bool over = cluster.Pump(next, queue, tally, running.load() > 0);
    {
      std::lock_guard<std::mutex> lock(error_mutex);
      if (worker_error && cluster.size() > 1) {
        try {
          std::rethrow_exception(worker_error);
        } catch (const std::exception& error) {
          std::fprintf(stderr, "mbid: failure: rank %d: %s\n", cluster.rank(), error.what());
        }
        cluster.Abort(1);
      }
    }
    if (over) break;
    const int seen_done = tally.done;
    progress.Update(seen_done + cluster.remote_done(), tally.failed + cluster.remote_failed());
    std::unique_lock<std::mutex> lock(wakeup_mutex);
    wakeup.wait_for(lock, cluster.poll_interval(),
                    [&] { return running.load() == 0 || tally.done.load() != seen_done; });
  }
  for (std::thread& thread : threads) thread.join();
  if (worker_error) std::rethrow_exception(worker_error);
  summary.ran = tally.done + cluster.remote_done();
  summary.cases_wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - cases_start).count();
  if (!cluster.is_root()) return summary;
  progress.Finish(summary.ran, tally.failed + cluster.remote_failed());

  summary.failed = FinishCampaign(campaign, folder, progress, std::move(committed_rows));
  summary.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

std::shared_ptr<internal::Cluster> JoinCampaignCluster() { return internal::JoinCluster(); }

bool IsClusterRoot(const internal::Cluster& cluster) { return cluster.is_root(); }

}  // namespace mbid::campaign
