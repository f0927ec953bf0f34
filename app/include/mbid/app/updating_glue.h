#pragma once

#include <memory>
#include <string>

#include "mbid/common/measurement.h"
#include "mbid/identification/modal_result.h"
#include "mbid/identification/updating/characteristic.h"
#include "mbid/identification/updating/output_error.h"
#include "mbid/identification/updating/settings.h"
#include "mbid/model/mechanical_model.h"
#include "mbid/simulation/excitation.h"

namespace mbid::app {

// Route 1 (method.md, eqs. 6-8) from the identified poles of `record`, when the settings ask for
// it and there is one mode per coordinate; otherwise null with the reason in `note`. Shared by
// `mbid run`, `mbid update` and the campaigns' update step.
std::shared_ptr<const updating::CharacteristicResult> SolveAlgebraicRoute(
    const model::MechanicalModel& model, const identification::ModalResult& identified,
    const Measurement& record, const simulation::Excitation& excitation,
    const updating::UpdatingSettings& settings, std::string* note);

// The identification's residual noise weighs the channels whose weights the settings leave open.
void WeighByIdentifiedNoise(const identification::ModalResult& identified,
                            updating::TestRecord& record);

}  // namespace mbid::app
