#pragma once

#include <optional>
#include <string>
#include <vector>

#include "mbid/common/measurement.h"
#include "mbid/common/yaml_reader.h"
#include "mbid/model/mechanical_model.h"
#include "mbid/simulation/excitation.h"
#include "mbid/simulation/modal_record.h"
#include "mbid/validation/record_import.h"
#include "mbid/validation/release_cut.h"

namespace mbid::validation {

// Where a test's record comes from when the scenario does not simulate it: the `record:`
// section (docs/scenarios.md), one map or a list of maps, each naming a measurement file or the
// modes of a synthetic record.
struct RecordSource {
  std::string name;               // the test's name in reports and result groups
  std::string file;               // a measurement file, resolved against the scenario's folder
  records::ImportOptions import;  // the entry's channels, units, time_unit, fill_gaps, ...
  std::optional<simulation::ModalRecordSpec> synthetic;
  // The test's own excitation: the entry's `excitation:` (it wins), else, for an HDF5 file mbid
  // wrote, the excitation of the scenario stored in it; unset: the scenario's excitation.
  std::optional<simulation::Excitation> excitation;
  std::string excitation_origin;  // "record entry", "<file>:/scenario"
  ReleaseChoice release;          // the entry's release / release_time_s
};

// Reads the section strictly; `scenario_dir` resolves relative file names. Channels of synthetic
// records must be outputs of `model`; files are checked when read.
std::vector<RecordSource> ReadRecordSources(const YamlReader& record,
                                            const std::string& scenario_dir,
                                            const model::MechanicalModel& model);

// A test record ready for identification.
struct LoadedRecord {
  Measurement measured;
  std::optional<Measurement> exact;                  // the noise-free record of a synthetic one
  std::string origin;                                // the file, or "synthetic modes"
  std::optional<records::ImportReport> import;       // what reading the file did
  std::optional<simulation::Excitation> excitation;  // as RecordSource::excitation
  std::string excitation_origin;
};

// The excitation of the scenario an HDF5 record mbid simulated stores under /scenario; none when
// the file has no stored scenario or the scenario no excitation. An invalid stored scenario is an
// InputError naming "<path>:/scenario".
std::optional<simulation::Excitation> ReadStoredExcitation(const std::string& path);

// Throws InputError naming `origin` (key "time") when `record` is sampled below every oscillating
// mode of `model` (its Nyquist frequency under the lowest): it cannot show one, and a time base
// read 1000 times too long (a logger's ms read as s) is the likelier cause. A fit would simulate
// the whole stretched record: 9500 s of a 2-5 Hz mast ran for more than 20 minutes.
void RequireSamplingOfAMode(const Measurement& record, const std::string& origin,
                            const model::MechanicalModel& model);

// Throws InputError naming `origin` unless every channel of `record` is an output of `model`.
void RequireModelOutputs(const Measurement& record, const std::string& origin,
                         const model::MechanicalModel& model);

// Reads the file (every channel must be an output or coordinate of `model`; the command line's
// `overrides` on top of the entry's import keys) or synthesizes the record.
LoadedRecord LoadRecord(const RecordSource& source, const model::MechanicalModel& model,
                        const ImportOverrides& overrides = {});

}  // namespace mbid::validation
