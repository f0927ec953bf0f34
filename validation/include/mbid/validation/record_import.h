#pragma once

// Measured files into mbid's commands: the scenario's `record:` keys and the command line's
// --channel/--unit/--fill-gaps become records::ImportOptions, with the model's units as targets
// (docs/records.md).

#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "mbid/common/yaml_reader.h"
#include "mbid/identification/modal_result.h"
#include "mbid/model/mechanical_model.h"
#include "mbid/records/records.h"

namespace mbid::validation {

// What the command line says about every measured file of the command.
struct ImportOverrides {
  std::vector<std::pair<std::string, std::string>> channel_columns;  // --channel NAME=COLUMN
  std::map<std::string, std::string> units;                          // --unit COLUMN=UNIT
  std::optional<records::GapFill> fill_gaps;                         // --fill-gaps
  std::string time_unit;  // --time-unit: the time column's unit, over the file's (empty: keep)
  std::optional<double> sample_rate_hz;  // --sample-rate-hz: for files without a time column
  // --release none (the record is the free decay) / --release-time-s T (in the file's time);
  // unset: the release is found in the record (identification/release.h).
  bool release_none = false;
  std::optional<double> release_time_s;
  std::optional<double> end_time_s;  // --end-time-s T: the test ends there (the file's time)
};

// Parses "NAME=VALUE" items of `flag`; an item without '=' or with an empty side is an
// InputError naming the flag.
std::vector<std::pair<std::string, std::string>> ParseAssignments(
    const std::vector<std::string>& items, const std::string& flag);
// "linear" or "none".
records::GapFill ParseGapFill(const std::string& text, const std::string& source,
                              const std::string& field);

// The import keys of a `record:` entry: channels, units, time_unit, fill_gaps, sample_rate_hz.
records::ImportOptions ReadImportOptions(const YamlReader& entry);
// The record entry's keys the import reads (for the entry's ExpectMap).
const std::vector<std::string>& ImportKeys();

// `base` with the command line on top (a --channel list replaces the entry's mapping; --unit
// adds to or overrides its units) and, with a model, its outputs' and coordinates' units as the
// channels' targets.
records::ImportOptions MergeImportOptions(const records::ImportOptions& base,
                                          const ImportOverrides& overrides,
                                          const model::MechanicalModel* model);

// One line for the user: "csv (';'-separated, decimal comma), psi <- column 3 (Boom angle),
// psi: deg -> rad (x 0.0174533), 2 gap samples filled".
std::string DescribeImport(const records::ImportReport& report);
nlohmann::json ImportReportToJson(const records::ImportReport& report);

// The reading's doubts (ImportReport::warnings: a time column without a unit whose step looks
// like ms) are doubts about the modes too: each becomes a reason of `identified`, which is then
// unreliable. A record whose every frequency may be 1000 times off is no result to size on.
void AddImportDoubts(const records::ImportReport& report, identification::ModalResult* identified);

}  // namespace mbid::validation
