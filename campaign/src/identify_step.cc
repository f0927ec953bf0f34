#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cmath>
#include <memory>

#include "mbid/identification/identify.h"
#include "mbid/identification/modal_result.h"
#include "mbid/validation/identification_settings.h"
#include "steps.h"

namespace mbid::campaign::internal {
using validation::FreeDecayOptions;

std::shared_ptr<const identification::ModalResult> RunIdentifyStep(const StepInput& input,
                                                                   CaseOutcome& outcome) {
  const auto result = std::make_shared<const identification::ModalResult>(identification::Identify(
      input.test->measured,
      FreeDecayOptions(input.scenario->identification, input.scenario->RequireExcitation()),
      input.scenario->path));

  nlohmann::ordered_json& row = outcome.row;
  row["identified.modes"] = result->modes.size();
  // A sweep read column by column must not take an unsupported mode for a measured one.
  row["identified.reliable"] = result->reliable;
  row["identified.reasons"] = fmt::format("{}", fmt::join(result->reasons, " | "));
  for (size_t c = 0; c < result->channels.size(); ++c) {
    row["identified.correlation." + result->channels[c]] =
        Number(result->correlation[static_cast<Eigen::Index>(c)]);
  }
  for (size_t k = 0; k < result->modes.size(); ++k) {
    const identification::IdentifiedMode& mode = result->modes[k];
    const std::string prefix = fmt::format("identified.mode{}.", k + 1);
    row[prefix + "frequency_hz"] = Number(mode.frequency_hz);
    row[prefix + "decay_rate_per_s"] = Number(mode.decay_rate_per_s);
    row[prefix + "damping_ratio"] = Number(mode.damping_ratio);
    row[prefix + "std_frequency_hz"] = Number(mode.std_frequency_hz);
    row[prefix + "std_decay_rate_per_s"] = Number(mode.std_decay_rate_per_s);
    // Empty for a mode; "f1 + f3" for a combination tone, no mode of the structure.
    row[prefix + "combination"] = mode.combination;
    for (size_t c = 0; c < result->channels.size(); ++c) {
      row[prefix + "amplitude." + result->channels[c]] =
          Number(mode.amplitude[static_cast<Eigen::Index>(c)]);
    }
  }
  outcome.groups.push_back(
      [result](H5Writer& file) { identification::WriteModalResult(file, *result); });
  return result;
}

}  // namespace mbid::campaign::internal
