#pragma once

// The identify and update steps of a campaign case. They live apart from the case runner so
// that a build without the identification or updating library still runs the other steps and
// says which step it lacks.

#include <memory>

#include "mbid/app/campaign_case.h"
#include "mbid/app/scenario.h"
#include "mbid/model/mechanical_model.h"
#include "mbid/simulation/simulate.h"

namespace mbid::app::internal {

// What a step sees of its case: the scenario, the case's model and its simulated test.
struct StepInput {
  const Scenario* scenario = nullptr;
  std::shared_ptr<const model::MechanicalModel> model;
  std::shared_ptr<const simulation::SimulationResult> test;
};

// Thrown by a step this build does not have; the case records status "not_available".
class StepNotAvailable : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Identifies the modes of the case's record with the scenario's identification settings; adds
// identified.* columns to the row and the /identification group. Throws on failure.
void RunIdentifyStep(const StepInput& input, CaseOutcome& outcome);

// Tunes the scenario's updating parameters to the case's record; adds updated.* columns and
// the /updating group. Throws on failure.
void RunUpdateStep(const StepInput& input, CaseOutcome& outcome);

}  // namespace mbid::app::internal
