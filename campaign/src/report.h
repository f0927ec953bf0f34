#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "mbid/campaign/campaign.h"
#include "mbid/campaign/study.h"

namespace mbid::campaign::internal {

// report.md in `folder` (atomically): the campaign, its cases by status, the failed cases with
// their reasons, the modes across the campaign against the first numeric swept key (exact and,
// if identified, identified), then the study's section. Figures need gnuplot; without it the
// report says so. Returns the names of all figures.
std::vector<std::string> WriteCampaignReport(const Campaign& campaign,
                                             const std::vector<nlohmann::ordered_json>& rows,
                                             const std::string& folder, const StudyReport& study);

}  // namespace mbid::campaign::internal
