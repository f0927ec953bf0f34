#include <memory>

#include "campaign/cluster.h"
#include "mbid/app/campaign.h"
#include "mbid/app/campaign_runner.h"
#include "mbid/app/commands.h"
#include "mbid/common/error.h"

namespace mbid::app {

int RunCampaignCommand(const std::string& campaign_path, const std::string& output_dir, int workers,
                       bool resume, const CommonOptions& common) {
  // Under mpirun this starts MPI (and ends it on return); alone it is this process.
  const std::unique_ptr<internal::Cluster> cluster = internal::JoinCluster();
  Campaign campaign;
  try {
    campaign = LoadCampaign(campaign_path);
  } catch (const std::exception& error) {
    // Every rank finds the same mistake; rank 0 alone reports it.
    if (!cluster->is_root()) return static_cast<int>(ExitCodeFor(error));
    throw;
  }
  CampaignRunOptions options;
  options.workers = workers;
  options.resume = resume;
  options.quiet = common.quiet;
  return RunCampaign(campaign, output_dir, options, cluster.get()).exit_code;
}

}  // namespace mbid::app
