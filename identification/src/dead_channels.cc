#include "dead_channels.h"

#include <fmt/format.h>

#include <string>
#include <vector>

#include "record.h"

namespace mbid::identification {

void LeaveOutDeadChannels(const Measurement& measurement, IdentificationOptions* applied,
                          ModalResult* result) {
  if (!applied->channels.empty() || measurement.channel_count() < 2) return;
  const WindowRows window = FindWindowRows(measurement, *applied);
  if (window.count() < 2) return;
  std::vector<std::string> live;
  std::vector<std::string> warnings;
  for (int c = 0; c < measurement.channel_count(); ++c) {
    const auto values = measurement.values.col(c).segment(window.first, window.count());
    const std::string& name = measurement.channels[static_cast<size_t>(c)];
    if (values.allFinite() && values.maxCoeff() == values.minCoeff()) {
      warnings.push_back(fmt::format(
          "channel {} is constant ({:g} in every sample analysed): left out, as a dead sensor "
          "records nothing of the decay (--channels names the channels to analyse)",
          name, values[0]));
    } else {
      live.push_back(name);
    }
  }
  if (live.empty() || warnings.empty()) return;
  applied->channels = live;
  result->warnings.insert(result->warnings.end(), warnings.begin(), warnings.end());
}

}  // namespace mbid::identification
