#include "mbid/validation/record_import.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "mbid/common/error.h"

namespace mbid::validation {

std::vector<std::pair<std::string, std::string>> ParseAssignments(
    const std::vector<std::string>& items, const std::string& flag) {
  std::vector<std::pair<std::string, std::string>> pairs;
  for (const std::string& item : items) {
    const size_t at = item.find('=');
    if (at == std::string::npos || at == 0 || at + 1 == item.size()) {
      throw InputError("command line", flag, fmt::format("'{}' is not NAME=VALUE", item),
                       fmt::format("{} NAME=VALUE (e.g. {} psi=\"Boom angle\")", flag, flag));
    }
    pairs.emplace_back(item.substr(0, at), item.substr(at + 1));
  }
  return pairs;
}

records::GapFill ParseGapFill(const std::string& text, const std::string& source,
                              const std::string& field) {
  if (text == "linear") return records::GapFill::kLinear;
  if (text == "none") return records::GapFill::kRefuse;
  throw InputError(source, field, fmt::format("unknown choice '{}'", text), "linear or none");
}

const std::vector<std::string>& ImportKeys() {
  static const std::vector<std::string> keys = {"channels", "units", "time_unit", "fill_gaps",
                                                "sample_rate_hz"};
  return keys;
}

records::ImportOptions ReadImportOptions(const YamlReader& entry) {
  records::ImportOptions options;
  if (entry.Has("channels")) {
    const YamlReader channels = entry.Child("channels");
    if (!channels.IsMap())
      channels.Fail("not a map", "{record channel: file column name or number}");
    for (const std::string& channel : channels.Keys()) {
      options.channel_columns.emplace_back(channel, channels.String(channel));
    }
  }
  if (entry.Has("units")) {
    const YamlReader units = entry.Child("units");
    if (!units.IsMap()) units.Fail("not a map", "{file column or record channel: unit}");
    for (const std::string& column : units.Keys()) options.units[column] = units.String(column);
  }
  options.time_unit = entry.String("time_unit", "");
  if (entry.Has("fill_gaps")) {
    options.fill_gaps = entry.Choice("fill_gaps", {"none", "linear"}, "none") == "linear"
                            ? records::GapFill::kLinear
                            : records::GapFill::kRefuse;
  }
  if (entry.Has("sample_rate_hz")) options.sample_rate_hz = entry.PositiveDouble("sample_rate_hz");
  return options;
}

records::ImportOptions MergeImportOptions(const records::ImportOptions& base,
                                          const ImportOverrides& overrides,
                                          const model::MechanicalModel* model) {
  records::ImportOptions options = base;
  if (!overrides.channel_columns.empty()) options.channel_columns = overrides.channel_columns;
  for (const auto& [column, unit] : overrides.units) options.units[column] = unit;
  if (overrides.fill_gaps) options.fill_gaps = *overrides.fill_gaps;
  if (!overrides.time_unit.empty()) options.time_unit = overrides.time_unit;
  if (overrides.sample_rate_hz) options.sample_rate_hz = *overrides.sample_rate_hz;
  if (model != nullptr) {
    const std::vector<std::string> coordinate_units = model->coordinate_units();
    for (size_t k = 0; k < model->coordinate_names().size(); ++k) {
      options.target_units[model->coordinate_names()[k]] = coordinate_units[k];
    }
    for (size_t k = 0; k < model->output_names().size(); ++k) {
      options.target_units[model->output_names()[k]] = model->output_units()[k];
    }
  }
  return options;
}

std::string DescribeImport(const records::ImportReport& report) {
  std::vector<std::string> parts;
  parts.push_back(report.dialect.empty() ? report.format
                                         : fmt::format("{} ({})", report.format, report.dialect));
  parts.insert(parts.end(), report.mapping.begin(), report.mapping.end());
  parts.insert(parts.end(), report.conversions.begin(), report.conversions.end());
  if (report.filled_samples > 0) {
    parts.push_back(fmt::format("{} gap sample{} filled linearly", report.filled_samples,
                                report.filled_samples == 1 ? "" : "s"));
  }
  for (const std::string& warning : report.warnings) parts.push_back("WARNING: " + warning);
  return fmt::format("{}", fmt::join(parts, ", "));
}

nlohmann::json ImportReportToJson(const records::ImportReport& report) {
  nlohmann::json json;
  json["format"] = report.format;
  if (!report.dialect.empty()) json["dialect"] = report.dialect;
  json["mapping"] = report.mapping;
  json["conversions"] = report.conversions;
  json["filled_samples"] = report.filled_samples;
  if (!report.warnings.empty()) json["warnings"] = report.warnings;
  return json;
}

void AddImportDoubts(const records::ImportReport& report, identification::ModalResult* identified) {
  for (const std::string& warning : report.warnings) {
    identified->reasons.push_back("reading the record: " + warning);
    identified->reliable = false;
  }
}

}  // namespace mbid::validation
