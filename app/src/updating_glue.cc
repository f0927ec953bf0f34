#include "mbid/app/updating_glue.h"

#include <fmt/format.h>

#include <complex>
#include <vector>

namespace mbid::app {

std::shared_ptr<const updating::CharacteristicResult> SolveAlgebraicRoute(
    const model::MechanicalModel& model, const identification::ModalResult& identified,
    const Measurement& record, const simulation::Excitation& excitation,
    const updating::UpdatingSettings& settings, std::string* note) {
  if (!settings.algebraic_start) {
    *note = "algebraic_start is off";
    return nullptr;
  }
  if (static_cast<int>(identified.modes.size()) != model.coordinate_count()) {
    *note = fmt::format("{} identified modes for {} coordinates", identified.modes.size(),
                        model.coordinate_count());
    return nullptr;
  }
  std::vector<std::complex<double>> lambda;
  for (const auto& mode : identified.modes) lambda.push_back(mode.lambda);
  return std::make_shared<const updating::CharacteristicResult>(
      updating::SolveCharacteristicEquation(
          updating::MakeCharacteristicProblem(model, lambda, record, excitation),
          settings.algebraic));
}

void WeighByIdentifiedNoise(const identification::ModalResult& identified,
                            updating::TestRecord& record) {
  for (size_t c = 0; c < identified.channels.size(); ++c) {
    const double noise = identified.noise_std[static_cast<Eigen::Index>(c)];
    if (noise > 0) record.noise_std.emplace(identified.channels[c], noise);
  }
}

}  // namespace mbid::app
