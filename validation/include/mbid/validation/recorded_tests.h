#pragma once

// The DATA files of `mbid update` and `mbid plan` (loaded_test.h) tuned together: Route 1 start
// from the first, Route 2 on all.

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "mbid/common/measurement.h"
#include "mbid/identification/modal_result.h"
#include "mbid/identification/options.h"
#include "mbid/model/mechanical_model.h"
#include "mbid/records/records.h"
#include "mbid/simulation/excitation.h"
#include "mbid/updating/characteristic.h"
#include "mbid/updating/global_search.h"
#include "mbid/updating/output_error.h"
#include "mbid/updating/settings.h"
#include "mbid/validation/loaded_test.h"

namespace mbid::validation {

// The tests as Route 2 takes them: the settings' noise and nuisance switches, and the
// identification's residual noise where the settings give none.
std::vector<updating::TestRecord> MakeWeightedRecords(const std::vector<LoadedTest>& tests,
                                                      const updating::UpdatingSettings& settings);

// Route 2 on the loaded tests as `mbid update` runs it.
struct RecordedUpdate {
  std::shared_ptr<const updating::CharacteristicResult> algebraic;  // Route 1, or null
  std::string start;  // "route1" or "scenario": Route 2's primary start
  std::string note;   // why Route 1 did not run or was not used, if so
  std::vector<updating::TestRecord> records;
  updating::GlobalSearchResult search;  // search.best: the estimate
};

// Route 1 on the first test's identified poles, then Route 2 on every test with the
// identification's residual noise as weights, from Route 1's set (else the scenario's values)
// and the global search's further starts (TuneModel). `settings` as read from the scenario;
// `say` gets the progress lines (Route 1's status first).
RecordedUpdate UpdateFromTests(const model::MechanicalModel& model,
                               const std::vector<LoadedTest>& tests,
                               const updating::UpdatingSettings& settings,
                               const std::function<void(const std::string&)>& say);

}  // namespace mbid::validation
