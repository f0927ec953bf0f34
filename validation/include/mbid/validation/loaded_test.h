#pragma once

#include <string>
#include <vector>

#include "mbid/common/measurement.h"
#include "mbid/identification/modal_result.h"
#include "mbid/identification/options.h"
#include "mbid/model/mechanical_model.h"
#include "mbid/records/records.h"
#include "mbid/simulation/excitation.h"
#include "mbid/validation/record_import.h"
#include "mbid/validation/release_cut.h"
#include "mbid/validation/scenario.h"

namespace mbid::validation {

// One DATA file of `mbid update` or `mbid structure`: its record, the excitation that produced
// it and what identification found.
struct LoadedTest {
  std::string path;
  Measurement record;
  simulation::Excitation excitation;
  std::string excitation_source;  // "scenario" or the file whose /scenario gave it
  identification::ModalResult identified;
  records::ImportReport import;
  AppliedRelease release;
};

// Each test's detected release where `fit` (of these tests, in order) placed it
// (AppliedRelease::Place).
void PlaceReleases(const updating::UpdateResult& fit, std::vector<LoadedTest>* tests);

// Imports `path` (the overrides' channels, units, gaps), checks its channels against `model`,
// takes the excitation stored with a simulated HDF5 record (else the scenario's), cuts the
// record at the release and identifies its modes (for Route 1 and the noise weights).
LoadedTest LoadTest(const std::string& path, const Scenario& scenario,
                    const model::MechanicalModel& model,
                    const identification::IdentificationOptions& identification_options,
                    const ImportOverrides& overrides);

// A record already in memory as one test: checked against `model`, cut at the release (found in
// the record unless `release` says otherwise) and identified; `origin` names it in messages.
LoadedTest PrepareTest(Measurement record, const std::string& origin,
                       const simulation::Excitation& excitation,
                       const model::MechanicalModel& model,
                       const identification::IdentificationOptions& identification_options,
                       const ReleaseChoice& release = {});

// One line per step on standard error: the import, the release, the record and its modes.
void DescribeLoadedTest(const LoadedTest& test);

// Every DATA file in order, each read and checked before any long work starts; with `describe`,
// each is described as it is loaded.
std::vector<LoadedTest> LoadTests(
    const std::vector<std::string>& paths, const Scenario& scenario,
    const model::MechanicalModel& model,
    const identification::IdentificationOptions& identification_options,
    const ImportOverrides& overrides, bool describe);

}  // namespace mbid::validation
