#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "mbid/common/measurement.h"
#include "mbid/identification/modal_result.h"
#include "mbid/model/mechanical_model.h"
#include "mbid/records/records.h"
#include "mbid/simulation/excitation.h"
#include "mbid/updating/characteristic.h"
#include "mbid/updating/global_search.h"
#include "mbid/updating/output_error.h"
#include "mbid/updating/settings.h"

namespace mbid::validation {

// The indices (ascending) of the `count` identified modes of largest energy in the record: the
// paper's "main" modes, which it chose among all it found for eq. 7. Combination tones are never
// main modes (fewer than `count` indices when too few modes are left).
std::vector<size_t> SelectMainModes(const identification::ModalResult& identified, size_t count);

// Route 1 (method.md, eqs. 6-8) from the identified poles of `record`, when the settings ask for
// it and there are at least as many modes as coordinates (more: the main ones, named in `note`);
// otherwise null with the reason in `note`. Shared by `mbid run`, `mbid update` and the
// campaigns' update step.
std::shared_ptr<const updating::CharacteristicResult> SolveAlgebraicRoute(
    const model::MechanicalModel& model, const identification::ModalResult& identified,
    const Measurement& record, const simulation::Excitation& excitation,
    const updating::UpdatingSettings& settings, std::string* note);

// Route 2's starts from Route 1 (null: none): Route 1's chosen set becomes the primary start in
// settings->options when admissible (`start` "route1", else "scenario", the reason added to
// `note`); returns the other admissible sets as further starts, and marks them complete
// (settings->global_search.complete_starts) when Route 1 solved.
std::vector<updating::SearchStart> StartFromAlgebraicRoute(
    const updating::CharacteristicResult* algebraic, updating::UpdatingSettings* settings,
    std::string* start, std::string* note);

// Route 2 as every command runs it: from Route 1's chosen set when it applies (else the
// scenario's values), with the other admissible Route-1 sets and the settings' space-filling
// design as further starts of the global search (global_search.h); Route 1's ambiguity marks the
// result too. `start` gets the primary start's label ("route1" or "scenario").
updating::GlobalSearchResult TuneModel(const model::MechanicalModel& model,
                                       const std::vector<updating::TestRecord>& records,
                                       updating::UpdatingSettings settings,
                                       const updating::CharacteristicResult* algebraic,
                                       std::string* start, std::string* note,
                                       const std::function<void(const std::string&)>& say);

// The identification's residual noise weighs the channels whose weights the settings leave open.
void WeighByIdentifiedNoise(const identification::ModalResult& identified,
                            updating::TestRecord& record);

// The samples the import interpolated into gaps, as indices of `record.record` (cut at its
// start since it was read): TestRecord::unmeasured_samples. Their values become the
// `identified` modes' reconstruction where it covers them: a straight line across a gap is off
// by the curvature (23 times the noise on a 10 Hz arm at 200 Hz), the modes by their fit.
void MarkUnmeasuredSamples(const records::ImportReport& import,
                           const identification::ModalResult& identified,
                           updating::TestRecord& record);

}  // namespace mbid::validation
