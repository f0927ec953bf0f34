#include "mbid/app/recorded_tests.h"

#include <fmt/format.h>

#include <optional>

#include "mbid/app/identification_settings.h"
#include "mbid/app/record_source.h"
#include "mbid/app/updating_glue.h"
#include "mbid/identification/identify.h"

namespace mbid::app {
namespace {

bool IsHdf5(const std::string& path) {
  const auto ends_with = [&](const std::string& tail) {
    return path.size() >= tail.size() &&
           path.compare(path.size() - tail.size(), tail.size(), tail) == 0;
  };
  return ends_with(".h5") || ends_with(".hdf5");
}

}  // namespace

LoadedTest LoadTest(const std::string& path, const Scenario& scenario,
                    const model::MechanicalModel& model,
                    const identification::IdentificationOptions& identification_options,
                    const ImportOverrides& overrides) {
  LoadedTest test;
  test.path = path;
  test.record =
      records::ImportMeasurement(path, MergeImportOptions({}, overrides, &model), &test.import);
  // Checked here rather than left to the fit: identification would run first on any channels.
  RequireModelOutputs(test.record, path, model);
  // A simulated test carries its own scenario: its excitation is the one of this record (a load
  // drop and an initial deflection can then be fitted together).
  std::optional<simulation::Excitation> own =
      IsHdf5(path) ? ReadStoredExcitation(path) : std::nullopt;
  test.excitation = own ? *own : scenario.RequireExcitation();
  test.excitation_source = own ? path : "scenario";
  // The simulation of the test starts at the release: the record is cut there.
  test.release =
      CutRecordAtRelease(&test.record, path, OverrideRelease({}, overrides), test.excitation);

  test.identified = identification::Identify(
      test.record, FreeDecayOptions(identification_options, test.excitation), path);
  return test;
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
  for (const LoadedTest& test : tests) {
    updating::TestRecord record =
        updating::MakeTestRecord(test.path, test.record, test.excitation, settings);
    WeighByIdentifiedNoise(test.identified, record);
    update.records.push_back(std::move(record));
  }
  update.search = TuneModel(model, update.records, settings, update.algebraic.get(), &update.start,
                            &update.note, say);
  return update;
}

}  // namespace mbid::app
