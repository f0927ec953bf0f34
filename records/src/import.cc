// RawTable -> Measurement in SI: the channel mapping, the time base, gaps, units
// (docs/records.md).
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <optional>
#include <set>

#include "formats.h"
#include "gaps.h"
#include "mbid/common/error.h"
#include "mbid/records/records.h"
#include "raw_table.h"
#include "time_base.h"
#include "units.h"

namespace mbid::records {

std::string internal::DescribeColumn(const RawColumn& column) {
  return column.name.empty() ? column.where : fmt::format("{} ({})", column.where, column.name);
}

std::string internal::SampleField(const RawTable& table, const std::string& where, Eigen::Index j) {
  if (static_cast<size_t>(j) < table.sample_lines.size()) {
    const std::string line = fmt::format("line {}", table.sample_lines[static_cast<size_t>(j)]);
    return where.empty() ? line : line + ", " + where;
  }
  return where.empty() ? fmt::format("sample {}", j) : fmt::format("{}, sample {}", where, j);
}

namespace {

using internal::RawColumn;
using internal::RawTable;

// A record channel and the file column it comes from.
struct Selected {
  std::string channel;
  const RawColumn* column = nullptr;
  std::string unit;  // the unit the values are in ("" if nobody states one)
};

bool IsNumber(const std::string& text) {
  return !text.empty() && std::all_of(text.begin(), text.end(),
                                      [](unsigned char c) { return std::isdigit(c) != 0; });
}

std::string ColumnList(const RawTable& table) {
  std::vector<std::string> names;
  for (size_t c = 0; c < table.columns.size(); ++c) {
    names.push_back(fmt::format("{} '{}'", c + 1, table.columns[c].name));
  }
  return fmt::format("a column of the file by name or number among its data columns: {}",
                     fmt::join(names, ", "));
}

// A name whose suffix states its unit (`boom_incl_rad`, with no unit beside it) names the channel
// without it, as `boom_incl [rad]` does: the values are converted to SI, and the model's output
// is `boom_incl` (a trial's file was refused: "channel 'boom_incl_rad' is neither an output nor a
// coordinate"). A name the model has itself, or one that two columns would share, stays whole.
void NameChannelsWithoutTheirUnitSuffix(const ImportOptions& options,
                                        std::vector<Selected>* selected) {
  std::vector<std::string> names;
  for (const Selected& s : *selected) {
    const internal::NameAndUnit split = internal::SplitUnitSuffix(s.column->name);
    const bool rename = s.unit.empty() && !split.unit.empty() &&
                        options.target_units.count(s.channel) == 0 &&
                        ProblemWithChannelName(split.name).empty();
    names.push_back(rename ? split.name : s.channel);
  }
  for (size_t c = 0; c < selected->size(); ++c) {
    if (std::count(names.begin(), names.end(), names[c]) > 1) continue;
    bool taken = false;
    for (const Selected& other : *selected) taken = taken || other.channel == names[c];
    if (!taken) (*selected)[c].channel = names[c];
  }
}

std::vector<Selected> SelectColumns(const RawTable& table, const std::string& path,
                                    const ImportOptions& options, ImportReport* report) {
  std::vector<Selected> selected;
  if (options.channel_columns.empty()) {
    for (const RawColumn& column : table.columns) {
      if (!column.text.empty()) continue;  // status or event marks, no channel
      if (column.name.empty()) {
        throw InputError(path, column.where, "the column has no name",
                         "a name in the header, or a mapping `channels: {NAME: COLUMN}`");
      }
      if (!column.name_repeated_at.empty()) {
        throw InputError(path, column.name_repeated_at,
                         "column name '" + column.name + "' appears twice",
                         "unique column names, or channels mapped to column numbers "
                         "(`channels: {NAME: 2}`, --channel NAME=2)");
      }
      if (!ProblemWithChannelName(column.name).empty()) {
        // A logger's "Weg, links [mm]": its name cannot be a channel's (mbid's CSV header), but
        // the column can be read under one the user gives.
        std::string suggestion;
        for (const char c : column.name) {
          if (std::isalnum(static_cast<unsigned char>(c)) != 0) {
            suggestion += c;
          } else if (!suggestion.empty() && suggestion.back() != '_') {
            suggestion += '_';
          }
        }
        while (!suggestion.empty() && suggestion.back() == '_') suggestion.pop_back();
        if (suggestion.empty() || ProblemWithChannelName(suggestion) != "") suggestion = "x";
        const size_t number = static_cast<size_t>(&column - table.columns.data()) + 1;
        throw InputError(path, DescribeColumn(column),
                         fmt::format("the column name '{}' cannot name a channel (no ',', '/', "
                                     "line break or blank at its ends, not 'time')",
                                     column.name),
                         fmt::format("the column read under a name of yours: --channel {0}={1} "
                                     "(`channels: {{{0}: {1}}}` in the record entry), one per "
                                     "channel to read",
                                     suggestion, number));
      }
      selected.push_back({column.name, &column, column.unit});
    }
    NameChannelsWithoutTheirUnitSuffix(options, &selected);
    return selected;
  }
  for (const auto& [channel, spec] : options.channel_columns) {
    const RawColumn* found = nullptr;
    for (const RawColumn& column : table.columns) {
      if (column.name != spec) continue;
      if (found != nullptr) {
        throw InputError(path, "channels." + channel,
                         fmt::format("column name '{}' appears twice in the file", spec),
                         ColumnList(table));
      }
      found = &column;
    }
    if (found == nullptr && IsNumber(spec)) {
      const size_t number = std::stoul(spec);
      if (number >= 1 && number <= table.columns.size()) found = &table.columns[number - 1];
    }
    if (found == nullptr) {
      const bool is_time = !table.time_name.empty() && spec == table.time_name;
      throw InputError(path, "channels." + channel,
                       is_time ? fmt::format("'{}' is the time column", spec)
                               : fmt::format("no column '{}' in the file", spec),
                       ColumnList(table));
    }
    if (!found->text.empty()) {
      throw InputError(
          path, "channels." + channel,
          fmt::format("{} holds text ({}), no number", DescribeColumn(*found), found->text),
          ColumnList(table));
    }
    selected.push_back({channel, found, found->unit});
    report->mapping.push_back(fmt::format("{} <- {}", channel, DescribeColumn(*found)));
  }
  return selected;
}

// Units given by the user complete or override the file's; every key must name something.
std::string ApplyUserUnits(const RawTable& table, const std::string& path,
                           const ImportOptions& options, std::vector<Selected>* selected) {
  std::set<std::string> used;
  for (Selected& s : *selected) {
    // By name, by channel, or by number among the data columns (as --channel takes it).
    const std::string number = std::to_string(s.column - table.columns.data() + 1);
    std::string given_by;
    for (const std::string& key : {number, s.column->name, s.channel}) {
      const auto unit = options.units.find(key);
      if (unit == options.units.end() || key == given_by) continue;
      // Two units for one column (its name's and its channel's: a reversed sensor's "-1 deg"
      // beside its calibration "0.02 deg" read the latter's millivolts as degrees) is no choice
      // of ours to make.
      if (!given_by.empty() && unit->second != s.unit) {
        throw InputError(path, "units." + key,
                         fmt::format("'{}' for {}, which units.{} gives '{}'", unit->second,
                                     DescribeColumn(*s.column), given_by, s.unit),
                         "one unit per column, under its name, number or channel");
      }
      s.unit = unit->second;
      given_by = key;
      used.insert(key);
    }
  }
  std::string time_unit = options.time_unit;
  if (!table.time_name.empty()) {
    const auto unit = options.units.find(table.time_name);
    if (unit != options.units.end()) {
      if (time_unit.empty()) time_unit = unit->second;
      used.insert(table.time_name);
    }
  }
  for (const auto& [key, unit] : options.units) {
    if (used.count(key) == 0) {
      throw InputError(
          path, "units." + key,
          fmt::format("'{}' is neither a column of the file nor a record channel", key),
          ColumnList(table));
    }
  }
  return time_unit;
}

// Gaps in the kept columns: refused naming the first, or filled (counted in the report).
std::vector<std::vector<double>> TakeValues(const RawTable& table, const std::string& path,
                                            const ImportOptions& options,
                                            const std::vector<Selected>& selected,
                                            ImportReport* report) {
  std::vector<std::vector<double>> values;
  int first_sample = -1;
  const Selected* first_column = nullptr;
  for (const Selected& s : selected) {
    values.push_back(s.column->values);
    const int gap = internal::FirstGap(s.column->values);
    if (gap >= 0 && (first_sample < 0 || gap < first_sample)) {
      first_sample = gap;
      first_column = &s;
    }
  }
  if (first_sample < 0) return values;
  const std::string field =
      internal::SampleField(table, DescribeColumn(*first_column->column), first_sample);
  if (options.fill_gaps == GapFill::kRefuse) {
    throw InputError(path, field, "empty or NaN cell (a gap in the record)",
                     "a value in every cell, or gaps filled by `--fill-gaps linear` (record key "
                     "`fill_gaps: linear`)");
  }
  std::vector<bool> filled(values.front().size(), false);
  for (size_t c = 0; c < values.size(); ++c) {
    for (size_t j = 0; j < values[c].size(); ++j) filled[j] = filled[j] || std::isnan(values[c][j]);
  }
  for (size_t j = 0; j < filled.size(); ++j) {
    if (filled[j]) report->filled_rows.push_back(static_cast<int>(j));
  }
  for (size_t c = 0; c < values.size(); ++c) {
    int unfillable = -1;
    report->filled_samples += internal::FillGapsLinear(&values[c], &unfillable);
    if (unfillable >= 0) {
      throw InputError(
          path, internal::SampleField(table, DescribeColumn(*selected[c].column), unfillable),
          fmt::format("a gap at the {} sample cannot be interpolated",
                      unfillable == 0 ? "first" : "last"),
          "values in the first and last row (linear filling needs a value on both sides)");
    }
  }
  return values;
}

}  // namespace

std::string NameWithoutUnitSuffix(const std::string& name) {
  return internal::SplitUnitSuffix(name).name;
}

Measurement ImportMeasurement(const std::string& path, const ImportOptions& options,
                              ImportReport* report) {
  ImportReport local;
  ImportReport& r = report != nullptr ? *report : local;
  r = ImportReport();
  const RawTable table = internal::ReadRawTable(path, options.time_unit);
  r.format = table.format;
  r.dialect = table.dialect;

  std::vector<Selected> selected = SelectColumns(table, path, options, &r);
  const std::string time_unit = ApplyUserUnits(table, path, options, &selected);
  Measurement m;
  internal::ReadTimeBase(table, path, options, time_unit, &m, &r);
  std::vector<std::vector<double>> values = TakeValues(table, path, options, selected, &r);
  r.samples = values.empty() ? 0 : static_cast<int>(values.front().size());

  const Eigen::Index samples =
      selected.empty() ? 0 : static_cast<Eigen::Index>(values.front().size());
  m.values.resize(samples, static_cast<Eigen::Index>(selected.size()));
  for (size_t c = 0; c < selected.size(); ++c) {
    const Selected& s = selected[c];
    const auto target_it = options.target_units.find(s.channel);
    std::string target = target_it == options.target_units.end() ? "" : target_it->second;
    const std::string field = DescribeColumn(*s.column);
    std::string unit = s.unit;
    // A name's suffix states a unit even in a file that looks like mbid's CSV (',' and a first
    // column `time`, as pandas writes one): `jib_incl_deg` was read as radians, 57 times too
    // large, without a word. mbid's own CSV states its units in a comment and never gets here.
    if (unit.empty()) {
      unit = internal::SplitUnitSuffix(s.column->name).unit;
      if (!unit.empty()) {
        r.conversions.push_back(
            fmt::format("{}: unit {} from the name's suffix{}", s.column->name, unit,
                        s.channel != s.column->name ? ", channel " + s.channel : std::string()));
      }
    }
    if (unit.empty()) {
      if (!table.si_by_contract) {
        // The example in the unit the model reads the channel in, where there is a model.
        const std::string example = internal::EverydayUnit(target);
        throw InputError(path, field, fmt::format("no unit for column '{}'", s.column->name),
                         fmt::format("a unit: a header '{0} [{1}]', a units row, `units: {{{0}: "
                                     "{1}}}` in the scenario's record entry or `--unit {0}={1}`",
                                     s.column->name, example));
      }
      // SI by contract: the unit the model expects, else radians (mbid's CSV of angles).
      unit = target.empty() ? "rad" : target;
    }
    if (target.empty()) target = internal::SiUnitFor(unit, path, field);
    const internal::UnitConversion conversion =
        internal::FindConversion(unit, target, path, field, s.column->name);
    internal::Convert(conversion, &values[c]);
    if (!conversion.identity()) {
      r.conversions.push_back(internal::DescribeConversion(s.channel, unit, target, conversion));
    }
    m.channels.push_back(s.channel);
    m.units.push_back(target);
    for (Eigen::Index j = 0; j < samples; ++j)
      m.values(j, static_cast<Eigen::Index>(c)) = values[c][static_cast<size_t>(j)];
  }
  if (!table.source.empty()) m.source = table.source;
  m.Validate(path);
  internal::SayIfOversampled(m, &r);
  return m;
}

}  // namespace mbid::records
