#include <fmt/format.h>

#include <algorithm>
#include <iostream>
#include <memory>
#include <thread>

#include "mbid/app/commands.h"
#include "mbid/app/exit_code.h"
#include "mbid/campaign/campaign.h"
#include "mbid/campaign/campaign_runner.h"
#include "mbid/common/error.h"

namespace mbid::app {
using campaign::Campaign;
using campaign::CampaignRunOptions;
using campaign::LoadCampaign;
using campaign::RunCampaign;

namespace {

// Threads beyond a few per core only add memory and contention; 100000 would fail to start.
void CheckWorkerCount(int workers) {
  const int cores = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  const int most = 4 * cores;
  if (workers > most) {
    throw InputError("--workers", "",
                     fmt::format("{} threads on {} core{}", workers, cores, cores > 1 ? "s" : ""),
                     fmt::format("at most {} (4 per core)", most));
  }
}

}  // namespace

int RunCampaignCommand(const std::string& campaign_path, const std::string& output_dir, int workers,
                       bool resume, const CommonOptions& common) {
  // Under mpirun this starts MPI (and ends it on return); alone it is this process.
  const std::shared_ptr<campaign::internal::Cluster> cluster = campaign::JoinCampaignCluster();
  Campaign campaign;
  try {
    CheckWorkerCount(workers);
    if (common.overwrite) {  // accepted by every command; a campaign is resumed, never replaced
      throw InputError("--overwrite", "", "a campaign folder is never replaced",
                       "--resume to finish the campaign a folder holds, or a new output folder");
    }
    campaign = LoadCampaign(campaign_path);
  } catch (const std::exception& error) {
    // Every rank finds the same mistake; rank 0 alone reports it.
    if (!campaign::IsClusterRoot(*cluster)) return static_cast<int>(ExitCodeFor(error));
    throw;
  }
  CampaignRunOptions options;
  options.workers = workers;
  options.resume = resume;
  options.quiet = common.quiet;
  const campaign::CampaignRunSummary summary =
      RunCampaign(campaign, output_dir, options, cluster.get());
  // Said even with --quiet: results the user had were lost and recomputed.
  for (const std::string& damaged : summary.damaged_cases) {
    std::cerr << "mbid: warning: " << output_dir << ": case " << damaged << "; computed again\n";
  }
  // The outcome on standard output (rank 0), as the other commands print their results: the
  // progress on standard error is for a terminal only.
  if (campaign::IsClusterRoot(*cluster) && !summary.stopped_before_running) {
    std::cout << (summary.was_complete
                      ? fmt::format("{}: already complete, nothing to do\n", output_dir)
                      : fmt::format("{}: {} cases, {} run now in {:.2f} s, {} failed{}\n",
                                    output_dir, summary.cases, summary.ran, summary.wall_s,
                                    summary.failed,
                                    summary.failed > 0 ? " (see summary.csv)" : ""));
  }
  // Rank 0 throws the folder's error itself; the other ranks learn only that it stopped.
  return static_cast<int>(summary.stopped_before_running ? ExitCode::kInvalidInput
                                                         : ExitCode::kSuccess);
}

}  // namespace mbid::app
