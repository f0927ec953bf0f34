#pragma once

// What plan.cc and plan_alternatives.cc share. Not part of the public API.

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "mbid/model/mechanical_model.h"
#include "mbid/updating/plan.h"

namespace mbid::updating::internal {

// The candidate's model (its own, or a copy of the plan's `model`) with the tuned parameters at
// `values` (set in their order); a candidate model without one of them is an InputError naming the
// candidate.
std::unique_ptr<model::MechanicalModel> MakeCandidateModel(
    const model::MechanicalModel& model, const PlanCandidate& candidate,
    const std::vector<std::pair<std::string, double>>& values);

}  // namespace mbid::updating::internal
