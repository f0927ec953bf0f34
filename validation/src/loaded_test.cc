#include "mbid/validation/loaded_test.h"

#include <fmt/format.h>

#include <iostream>
#include <optional>

#include "mbid/identification/identify.h"
#include "mbid/validation/identification_settings.h"
#include "mbid/validation/record_source.h"

namespace mbid::validation {
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
  // Checked before anything else is read from the file.
  RequireModelOutputs(test.record, path, model);
  RequireSamplingOfAMode(test.record, path, model);
  // A simulated test carries its own scenario: its excitation is the one of this record (a load
  // drop and an initial deflection can then be fitted together).
  std::optional<simulation::Excitation> own =
      IsHdf5(path) ? ReadStoredExcitation(path) : std::nullopt;
  LoadedTest prepared =
      PrepareTest(std::move(test.record), path, own ? *own : scenario.RequireExcitation(), model,
                  identification_options, OverrideRelease({}, overrides));
  prepared.import = std::move(test.import);
  prepared.excitation_source = own ? path : "scenario";
  return prepared;
}

LoadedTest PrepareTest(Measurement record, const std::string& origin,
                       const simulation::Excitation& excitation,
                       const model::MechanicalModel& model,
                       const identification::IdentificationOptions& identification_options,
                       const ReleaseChoice& release) {
  LoadedTest test;
  test.path = origin;
  test.record = std::move(record);
  // Checked here rather than left to the fit: identification would run first on any channels.
  RequireModelOutputs(test.record, origin, model);
  test.excitation = excitation;
  test.excitation_source = "scenario";
  // The simulation of the test starts at the release: the record is cut there.
  test.release = CutRecordAtRelease(&test.record, origin, release, test.excitation);
  test.identified = IdentifyForTheFit(
      test.record, FreeDecayOptions(identification_options, test.excitation), origin);
  return test;
}

void PlaceReleases(const updating::UpdateResult& fit, std::vector<LoadedTest>* tests) {
  for (size_t i = 0; i < tests->size() && i < fit.tests.size(); ++i) {
    (*tests)[i].release.Place(fit.tests[i]);
  }
}

void DescribeLoadedTest(const LoadedTest& test) {
  std::cerr << fmt::format("mbid: {}: {}\n", test.path, DescribeImport(test.import));
  std::cerr << fmt::format("mbid: {}: free decay from {:.6g} s of the record ({}); t = 0 there\n",
                           test.path, test.release.release_time_s, test.release.how);
  if (test.release.clipped_until_s) {
    std::cerr << fmt::format("mbid: {}: {}\n", test.path, test.release.DescribeClipped());
  }
  std::cerr << fmt::format("mbid: {}: {} samples x {} channels, {} ({}), {} modes identified\n",
                           test.path, test.record.samples(), test.record.channel_count(),
                           test.excitation.type_name(), test.excitation_source,
                           test.identified.modes.size());
}

std::vector<LoadedTest> LoadTests(
    const std::vector<std::string>& paths, const Scenario& scenario,
    const model::MechanicalModel& model,
    const identification::IdentificationOptions& identification_options,
    const ImportOverrides& overrides, bool describe) {
  std::vector<LoadedTest> tests;
  for (const std::string& path : paths) {
    tests.push_back(LoadTest(path, scenario, model, identification_options, overrides));
    if (describe) {
      DescribeLoadedTest(tests.back());
    } else {
      // Under --quiet the import's doubts are still said (the progress line carries them), and
      // samples left out.
      for (const std::string& warning : tests.back().import.warnings) {
        std::cerr << fmt::format("mbid: warning: {}: {}\n", tests.back().path, warning);
      }
      if (tests.back().release.clipped_until_s) {
        std::cerr << fmt::format("mbid: warning: {}: {}\n", tests.back().path,
                                 tests.back().release.DescribeClipped());
      }
    }
    if (tests.back().release.next_excitation_s) {  // samples left out at the end
      std::cerr << fmt::format("mbid: warning: {}: {}\n", tests.back().path,
                               tests.back().release.next_excitation);
    }
  }
  return tests;
}

}  // namespace mbid::validation
