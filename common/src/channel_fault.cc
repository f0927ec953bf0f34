#include "mbid/common/channel_fault.h"

#include <algorithm>
#include <vector>

#include "mbid/common/clipping.h"
#include "mbid/common/outliers.h"

namespace mbid {

std::optional<ChannelFault> FindChannelFault(const Eigen::Ref<const Eigen::VectorXd>& values,
                                             const std::string& channel, const std::string& unit,
                                             double sample_interval_s, double start_time_s,
                                             double jumps_from_s) {
  if (const std::optional<Clipping> clipping = FindClipping(values)) {
    return ChannelFault{ChannelFault::Kind::kClipped, ClippingReason(channel, unit, *clipping)};
  }
  std::vector<Outlier> outliers = FindOutliers(values);
  outliers.erase(std::remove_if(outliers.begin(), outliers.end(),
                                [&](const Outlier& o) {
                                  return start_time_s +
                                             static_cast<double>(o.sample) * sample_interval_s <=
                                         jumps_from_s;
                                }),
                 outliers.end());
  if (outliers.empty()) return std::nullopt;
  return ChannelFault{ChannelFault::Kind::kGlitch,
                      OutlierReason(channel, outliers, sample_interval_s, start_time_s)};
}

}  // namespace mbid
