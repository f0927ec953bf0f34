#pragma once

#include <memory>
#include <string>
#include <vector>

#include "mbid/campaign/campaign.h"

namespace mbid::campaign {

namespace internal {
class Cluster;
}  // namespace internal

struct CampaignRunOptions {
  // Worker threads of this process, each computing one case at a time with its own model.
  // 0: one per hardware thread, or one per rank under MPI.
  int workers = 0;
  bool resume = false;  // continue a folder this campaign started (skip committed cases)
  bool quiet = false;   // no progress on standard error
};

struct CampaignRunSummary {
  int cases = 0;              // in the campaign
  int already_committed = 0;  // found committed by --resume
  // Case files --resume found damaged (checksum or contents) and computed again: "<id>: <why>".
  std::vector<std::string> damaged_cases;
  int ran = 0;                // cases this run computed (all ranks)
  int failed = 0;             // cases of the campaign with a status other than ok
  bool was_complete = false;  // --resume of a finished campaign: nothing to do
  int ranks = 1;
  int workers = 1;          // per rank
  double wall_s = 0;        // the whole run on rank 0, merge and report included
  double cases_wall_s = 0;  // from the first case handed out to the last one committed
  // On ranks other than 0: rank 0 refused the results folder and stopped the campaign before
  // it ran (rank 0 throws the error itself).
  bool stopped_before_running = false;
};

// Runs `campaign` into `output_dir` (layout and resume rules: docs/campaigns.md): the pending
// cases go to `options.workers` threads, and, when `cluster` is an MPI job, to the threads of
// every rank; each case is committed to its own file as it finishes; rank 0 then merges them
// in case order into campaign.h5, writes summary.csv, the study and report.md. The merged
// file is the same, bit for bit, for any number of workers and ranks. `cluster` = nullptr runs
// in this process alone. Errors of the folder (see ResultsFolder) are InputErrors; a case's
// own failure is recorded in its results and does not stop the campaign. It tunes the process's
// allocator once (glibc mallopt: freed memory is kept for reuse rather than returned to the
// kernel), which the cases' repeated allocations need to scale over threads.
CampaignRunSummary RunCampaign(const Campaign& campaign, const std::string& output_dir,
                               const CampaignRunOptions& options,
                               internal::Cluster* cluster = nullptr);

// The processes that run a campaign together: under `mpirun` the ranks of the MPI job (MPI
// starts here and ends with the last copy of the handle), otherwise this process alone.
std::shared_ptr<internal::Cluster> JoinCampaignCluster();

// Whether this process is rank 0, the one that reports errors and writes the merged results.
bool IsClusterRoot(const internal::Cluster& cluster);

}  // namespace mbid::campaign
