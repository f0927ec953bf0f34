#pragma once

// The identify and update steps of a campaign case: what each takes from the case and adds to
// its results.

#include <cmath>
#include <memory>
#include <nlohmann/json.hpp>

#include "mbid/campaign/campaign_case.h"
#include "mbid/identification/modal_result.h"
#include "mbid/model/mechanical_model.h"
#include "mbid/simulation/simulate.h"
#include "mbid/validation/scenario.h"

namespace mbid::campaign::internal {

// A row value: JSON has no NaN or infinity; NaN (missing) becomes null, an empty cell in
// summary.csv, and an infinity (a settling time never reached) the text "inf" or "-inf".
inline nlohmann::ordered_json Number(double value) {
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  if (!std::isfinite(value)) return nullptr;
  return value;
}

// What a step sees of its case: the scenario, the case's model and its simulated test.
struct StepInput {
  const validation::Scenario* scenario = nullptr;
  std::shared_ptr<const model::MechanicalModel> model;
  std::shared_ptr<const simulation::SimulationResult> test;
  // The identify step's result, if it ran (the update step starts from its poles).
  std::shared_ptr<const identification::ModalResult> identified;
};

// Identifies the modes of the case's record with the scenario's identification settings; adds
// identified.* columns to the row and the /identification group. Throws on failure.
std::shared_ptr<const identification::ModalResult> RunIdentifyStep(const StepInput& input,
                                                                   CaseOutcome& outcome);

// Tunes the scenario's updating parameters to the case's record (mbid/identification/updating):
// the scenario's updating: settings; Route 1 (eq. 7) from the identified poles as the start
// when it gives an admissible set and the settings ask for it; the identification's residual
// noise as weights where the settings give none. Adds updated.* columns and the /updating
// group; a fit that does not converge throws NumericalError after recording what it found.
void RunUpdateStep(const StepInput& input, CaseOutcome& outcome);

}  // namespace mbid::campaign::internal
