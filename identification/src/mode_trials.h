#pragma once

#include <functional>
#include <string>

#include "estimate.h"
#include "mbid/identification/options.h"
#include "record.h"

namespace mbid::identification {

// A trial estimate that starts from `estimate`'s poles and keeps its warnings, doubts and orders.
Estimate TrialFrom(const Estimate& estimate);

// The warning of a search that added modes: "<added> more significant mode(s) <how>".
void NoteAddedModes(int added, const std::string& how, Estimate* estimate);

// Refines `trial` (the estimate's modes and more) and tests it for significance; when it keeps
// more significant modes, all carrying amplitude (and passes `accept`, if given), it replaces the
// estimate. Returns how many modes it added (0: the estimate stands).
int KeepIfMoreModes(const AnalysisRecord& record, const IdentificationOptions& options,
                    const std::function<void(Estimate*)>& refine, Estimate trial,
                    Estimate* estimate,
                    const std::function<bool(const Estimate&)>& accept = nullptr);

}  // namespace mbid::identification
