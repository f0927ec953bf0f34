#include "mbid/validation/record_source.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <set>

#include "mbid/common/error.h"
#include "mbid/common/hdf5_io.h"
#include "mbid/model/linear_model.h"
#include "mbid/records/records.h"
#include "mbid/simulation/scenario_sections.h"
#include "mbid/validation/scenario.h"

namespace mbid::validation {
namespace {

namespace fs = std::filesystem;

bool IsOutput(const model::MechanicalModel& model, const std::string& channel) {
  const auto& outputs = model.output_names();
  return std::find(outputs.begin(), outputs.end(), channel) != outputs.end();
}

std::string OutputList(const model::MechanicalModel& model) {
  return fmt::format("channels among the model's outputs ({})",
                     fmt::join(model.output_names(), ", "));
}

RecordSource ReadOne(const YamlReader& entry, const std::string& default_name,
                     const std::string& scenario_dir, const model::MechanicalModel& model) {
  if (!entry.IsMap()) entry.Fail("not a mapping", "{file: PATH} or {synthetic_modes: {...}}");
  std::vector<std::string> keys = {"name",    "file",           "synthetic_modes", "excitation",
                                   "release", "release_time_s", "end_time_s"};
  keys.insert(keys.end(), ImportKeys().begin(), ImportKeys().end());
  entry.ExpectMap(keys);
  RecordSource source;
  source.name = entry.String("name", default_name);
  // The name is an HDF5 group and, with several tests, the folder of the test's figures.
  if (source.name.empty() || source.name.find('/') != std::string::npos || source.name == "." ||
      source.name == "..") {
    entry.FailAt("name", "'" + source.name + "'", "a non-empty test name without '/', not . or ..");
  }
  const bool has_file = entry.Has("file");
  if (has_file == entry.Has("synthetic_modes")) {
    entry.Fail(has_file ? "both file and synthetic_modes" : "neither file nor synthetic_modes",
               "exactly one of file: PATH and synthetic_modes: {...}");
  }
  if (has_file) {
    const fs::path file = entry.String("file");
    source.file = (file.is_relative() ? fs::path(scenario_dir) / file : file).string();
    if (!records::IsSupportedFile(file.string())) {
      entry.FailAt(
          "file", "'" + file.string() + "'",
          fmt::format("a measurement file ({})", fmt::join(records::SupportedExtensions(), ", ")));
    }
    if (!fs::is_regular_file(source.file)) {
      entry.FailAt("file", "'" + source.file + "' does not exist", "a readable measurement file");
    }
    source.import = ReadImportOptions(entry);
    source.release = ReadReleaseChoice(entry);
    if (entry.Has("excitation")) {
      source.excitation = simulation::ReadExcitation(entry.Child("excitation"), model);
      source.excitation_origin = "record entry";
    }
  } else {
    if (entry.Has("excitation")) {
      entry.FailAt("excitation", "given for synthetic_modes",
                   "an excitation only with file: PATH (synthetic modes have none)");
    }
    std::vector<std::string> file_keys = ImportKeys();
    file_keys.insert(file_keys.end(), {"release", "release_time_s", "end_time_s"});
    for (const std::string& key : file_keys) {
      if (entry.Has(key))
        entry.FailAt(key, "given for synthetic_modes", "import keys only with file: PATH");
    }
    const YamlReader modes = entry.Child("synthetic_modes");
    source.synthetic = simulation::ReadModalRecordSpec(modes);
    for (const std::string& channel : source.synthetic->channels) {
      if (!IsOutput(model, channel)) {
        modes.FailAt("channels", "'" + channel + "' is not an output of the model",
                     OutputList(model));
      }
    }
  }
  return source;
}

}  // namespace

std::vector<RecordSource> ReadRecordSources(const YamlReader& record,
                                            const std::string& scenario_dir,
                                            const model::MechanicalModel& model) {
  std::vector<RecordSource> sources;
  if (record.node().IsSequence()) {
    if (record.node().size() == 0) record.Fail("an empty list", "one or more records");
    for (size_t k = 0; k < record.node().size(); ++k) {
      const YamlReader entry(record.node()[k], record.source(),
                             record.field() + "[" + std::to_string(k) + "]");
      sources.push_back(ReadOne(entry, fmt::format("test-{}", k + 1), scenario_dir, model));
    }
  } else {
    sources.push_back(ReadOne(record, "test-1", scenario_dir, model));
  }
  std::set<std::string> names;
  for (const RecordSource& source : sources) {
    if (!names.insert(source.name).second) {
      record.Fail("two records named '" + source.name + "'", "a unique name per record");
    }
  }
  return sources;
}

LoadedRecord LoadRecord(const RecordSource& source, const model::MechanicalModel& model,
                        const ImportOverrides& overrides) {
  LoadedRecord loaded;
  if (source.synthetic) {
    Measurement exact;
    loaded.measured = simulation::SynthesizeModalRecord(*source.synthetic, &exact);
    loaded.exact = std::move(exact);
    loaded.origin = "synthetic modes";
    return loaded;
  }
  records::ImportReport report;
  loaded.measured = records::ImportMeasurement(
      source.file, MergeImportOptions(source.import, overrides, &model), &report);
  loaded.import = report;
  loaded.origin = source.file;
  RequireModelOutputs(loaded.measured, source.file, model);
  RequireSamplingOfAMode(loaded.measured, source.file, model);
  loaded.excitation = source.excitation;
  loaded.excitation_origin = source.excitation_origin;
  if (!loaded.excitation && report.format == "hdf5") {
    // A test mbid simulated carries its scenario: its own load, not the run scenario's.
    loaded.excitation = ReadStoredExcitation(source.file);
    if (loaded.excitation) loaded.excitation_origin = source.file + ":/scenario";
  }
  return loaded;
}

std::optional<simulation::Excitation> ReadStoredExcitation(const std::string& path) {
  const std::string yaml = ReadScenarioYaml(path);
  if (yaml.empty()) return std::nullopt;
  const Scenario stored = LoadScenarioFromText(yaml, path + ":/scenario");
  if (!stored.has_excitation) return std::nullopt;
  return stored.excitation;
}

void RequireModelOutputs(const Measurement& record, const std::string& origin,
                         const model::MechanicalModel& model) {
  const std::vector<std::string>& coordinates = model.coordinate_names();
  for (const std::string& channel : record.channels) {
    // Coordinate channels (as `mbid simulate` writes them for `sensors.channels: [theta]`) are
    // measured joint angles or slides: updating compares them like outputs.
    if (!IsOutput(model, channel) &&
        std::find(coordinates.begin(), coordinates.end(), channel) == coordinates.end()) {
      // `tip_z_mm` beside `tip_z_m`: each would be `tip_z` without its unit suffix, and the
      // import keeps both whole rather than choose (records.md).
      const std::string shortened = records::NameWithoutUnitSuffix(channel);
      const std::string shared =
          shortened != channel && IsOutput(model, shortened) ? shortened : "";
      throw InputError(
          origin, "channels",
          fmt::format("channel '{}' is neither an output nor a coordinate of the model{}", channel,
                      shared.empty()
                          ? ""
                          : fmt::format(" (nor is it named '{}' without its unit suffix: another "
                                        "column would share that name; read the one you mean "
                                        "under it, --channel {}={})",
                                        shared, shared, channel)),
          fmt::format("{}, or coordinates ({})", OutputList(model), fmt::join(coordinates, ", ")));
    }
  }
}

void RequireSamplingOfAMode(const Measurement& record, const std::string& origin,
                            const model::MechanicalModel& model) {
  double lowest_hz = std::numeric_limits<double>::infinity();
  for (const model::Mode& mode : model::CalcModes(model.Linearize())) {
    if (mode.frequency_hz() > 0) lowest_hz = std::min(lowest_hz, mode.frequency_hz());
  }
  const double nyquist_hz = 0.5 / record.sample_interval_s;
  if (!std::isfinite(lowest_hz) || lowest_hz <= nyquist_hz) return;
  throw InputError(
      origin, "time",
      fmt::format("a sample rate of {:.4g} Hz (Nyquist {:.4g} Hz), below every mode "
                  "of the model (the lowest at {:.4g} Hz): the record cannot show "
                  "one; is its time in ms (`time_unit: ms` in the record entry, "
                  "--time-unit ms)?",
                  1 / record.sample_interval_s, nyquist_hz, lowest_hz),
      fmt::format("a record sampled at {:.4g} Hz or more", std::ceil(2.1 * lowest_hz)));
}

}  // namespace mbid::validation
