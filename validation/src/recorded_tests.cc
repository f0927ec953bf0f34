#include "mbid/validation/recorded_tests.h"

#include <fmt/format.h>

#include <optional>

#include "mbid/identification/identify.h"
#include "mbid/validation/identification_settings.h"
#include "mbid/validation/record_source.h"
#include "mbid/validation/two_route_update.h"

namespace mbid::validation {

std::vector<updating::TestRecord> MakeWeightedRecords(const std::vector<LoadedTest>& tests,
                                                      const updating::UpdatingSettings& settings) {
  std::vector<updating::TestRecord> records;
  for (const LoadedTest& test : tests) {
    updating::TestRecord record =
        updating::MakeTestRecord(test.path, test.record, test.excitation, settings);
    WeighByIdentifiedNoise(test.identified, record);
    MarkUnmeasuredSamples(test.import, test.identified, record);
    record.release_detected = test.release.how == "detected";
    records.push_back(std::move(record));
  }
  return records;
}

RecordedUpdate UpdateFromTests(const model::MechanicalModel& model,
                               const std::vector<LoadedTest>& tests,
                               const updating::UpdatingSettings& settings,
                               const std::function<void(const std::string&)>& say) {
  RecordedUpdate update;
  update.algebraic = SolveAlgebraicRoute(model, tests.front().identified, tests.front().record,
                                         tests.front().excitation, settings, &update.note);
  say(fmt::format("route 1: {}{}", update.algebraic ? update.algebraic->status_name() : "not run",
                  update.note.empty() ? "" : " (" + update.note + ")"));
  update.records = MakeWeightedRecords(tests, settings);
  update.search = TuneModel(model, update.records, settings, update.algebraic.get(), &update.start,
                            &update.note, say);
  return update;
}

}  // namespace mbid::validation
