// Text exports of loggers -> RawTable: the dialect (csv_dialect.h), the header's names and
// units, mbid's `# units:` comments, the time column (numbers or ISO timestamps) and its
// printed resolution.
#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <optional>
#include <set>

#include "csv_dialect.h"
#include "header_cells.h"
#include "internal.h"
#include "iso_time.h"
#include "mbid/common/error.h"
#include "mbid/common/utf8.h"
#include "number_marks.h"
#include "readers.h"
#include "text_util.h"

namespace mbid::records::internal {
namespace {

// How the record's "NN/NN/YYYY" dates read (in its time or date column): day first where a
// first field is over 12, month first where a second one is; else the order in which the dates
// run on by 0 or 1 day from row to row (a record that passes midnight). Dates all of one day
// give the same times either way. A record that fits both or neither order is refused.
SlashOrder DecideSlashOrder(const std::string& path, const std::vector<TextLine>& lines,
                            int first_row, char separator, const std::vector<int>& date_columns) {
  struct SlashDate {
    int first, second, year, line;
  };
  std::vector<SlashDate> dates;
  for (size_t i = static_cast<size_t>(first_row); i < lines.size(); ++i) {
    if (IsCommentOrBlank(lines[i].text)) continue;
    const std::vector<std::string> fields = SplitFields(lines[i].text, separator);
    for (const int c : date_columns) {
      SlashDate date{0, 0, 0, lines[i].number};
      if (c >= 0 && static_cast<size_t>(c) < fields.size() &&
          ReadSlashDate(fields[static_cast<size_t>(c)], &date.first, &date.second, &date.year)) {
        dates.push_back(date);
      }
    }
  }
  const auto day_over_12 =
      std::find_if(dates.begin(), dates.end(), [](const SlashDate& d) { return d.first > 12; });
  const auto month_over_12 =
      std::find_if(dates.begin(), dates.end(), [](const SlashDate& d) { return d.second > 12; });
  if (day_over_12 != dates.end() && month_over_12 != dates.end()) {
    throw InputError(path, LineField(month_over_12->line),
                     fmt::format("a date month first ({:02}/{:02}) after one day first (line {})",
                                 month_over_12->first, month_over_12->second, day_over_12->line),
                     "the dates with '/' in one order, day first or month first");
  }
  if (day_over_12 != dates.end()) return SlashOrder::kDayFirst;
  if (month_over_12 != dates.end()) return SlashOrder::kMonthFirst;
  const auto runs_on = [&dates](SlashOrder order) {
    for (size_t k = 1; k < dates.size(); ++k) {
      const bool month_first = order == SlashOrder::kMonthFirst;
      const auto day = [month_first](const SlashDate& d) {
        return DaysFromCivil(d.year, month_first ? d.first : d.second,
                             month_first ? d.second : d.first);
      };
      const std::int64_t step = day(dates[k]) - day(dates[k - 1]);
      if (step != 0 && step != 1) return false;
    }
    return true;
  };
  const bool day_first = runs_on(SlashOrder::kDayFirst);
  const bool month_first = runs_on(SlashOrder::kMonthFirst);
  if (day_first != month_first) return day_first ? SlashOrder::kDayFirst : SlashOrder::kMonthFirst;
  if (day_first && std::all_of(dates.begin(), dates.end(), [&dates](const SlashDate& d) {
        return d.first == dates.front().first && d.second == dates.front().second &&
               d.year == dates.front().year;
      })) {
    return SlashOrder::kDayFirst;  // one day: the times are the same either way
  }
  throw InputError(path, LineField(dates.empty() ? 0 : dates.back().line),
                   "dates with '/' that read as well day first as month first",
                   "dates in ISO form (2026-03-01), or a record whose dates tell the order");
}

constexpr char kExpected[] =
    "a table of numbers with a header line, separated by ',', ';', tabs or blanks "
    "(docs/records.md)";

// The decimal place of a number's last printed digit, as a power of ten: "0.0123" -> -4,
// "1.5e-3" -> -4, "12" -> 0 (as mbid's CSV reader counts it).
int PrintedPlace(const std::string& text, char decimal) {
  const size_t exponent_at = std::min(text.find_first_of("eE"), text.size());
  const int exponent = exponent_at < text.size() ? std::atoi(text.c_str() + exponent_at + 1) : 0;
  const size_t point = text.find(decimal);
  const int decimals = point < exponent_at ? static_cast<int>(exponent_at - point - 1) : 0;
  return exponent - decimals;
}

// mbid's metadata comments: "# units: s,rad,rad", "# sample_interval_s: 0.01", "# source: x".
struct Metadata {
  std::vector<std::string> units;
  int units_line = 0;
  std::string interval_text;
  int interval_line = 0;
  std::string source;
};

void ReadComment(const std::string& line, int number, char separator, Metadata* metadata) {
  const std::string trimmed = mbid::internal::Trim(line);
  if (trimmed.empty() || trimmed.front() != '#') return;
  const std::string body = mbid::internal::Trim(trimmed.substr(1));
  const auto value_of = [&body](const std::string& key) -> std::optional<std::string> {
    if (body.compare(0, key.size() + 1, key + ":") != 0) return std::nullopt;
    return mbid::internal::Trim(body.substr(key.size() + 1));
  };
  if (auto source = value_of("source")) {
    metadata->source = *source;
  } else if (auto interval = value_of("sample_interval_s")) {
    metadata->interval_text = *interval;
    metadata->interval_line = number;
  } else if (auto units = value_of("units")) {
    const char split = units->find(separator) != std::string::npos ? separator : ',';
    metadata->units = SplitFields(*units, split);
    metadata->units_line = number;
  }
}

// Where a cell showed the file's decimal mark (a reading only that mark gives).
struct MarkEvidence {
  DecimalMark mark = DecimalMark::kUnknown;
  std::string cell, where;
};

// The decimal mark of a file's data rows: the mark of the first number that reads with only one
// of them ("0,5", "1,234.5", "1.234.567"); kUnknown when no number shows it (then "1,234" is
// ambiguous and refused where it occurs). A ','-separated file has a decimal point unless
// quoted cells hold commas ("107,389": a decimal comma or a thousands separator, as they show).
MarkEvidence FindDecimalMark(const std::vector<TextLine>& lines, int first_row, char separator) {
  MarkEvidence evidence;
  if (separator == ',') {
    const bool quoted_commas =
        std::any_of(lines.begin() + first_row, lines.end(), [&](const TextLine& line) {
          if (IsCommentOrBlank(line.text)) return false;
          const std::vector<std::string> fields = SplitFields(line.text, separator);
          return std::any_of(fields.begin(), fields.end(), [](const std::string& field) {
            return field.find(',') != std::string::npos;
          });
        });
    if (!quoted_commas) {
      evidence.mark = DecimalMark::kPoint;
      return evidence;
    }
  }
  for (size_t i = static_cast<size_t>(first_row); i < lines.size(); ++i) {
    if (IsCommentOrBlank(lines[i].text)) continue;
    const std::vector<std::string> fields = SplitFields(lines[i].text, separator);
    for (size_t c = 0; c < fields.size(); ++c) {
      if (fields[c].find_first_of(".,") == std::string::npos) continue;
      const DecimalMark mark = ReadNumber(fields[c]).Evidence();
      if (mark == DecimalMark::kUnknown) continue;
      evidence.mark = mark;
      evidence.cell = fields[c];
      evidence.where = fmt::format("line {}, column {}", lines[i].number, c + 1);
      return evidence;
    }
  }
  return evidence;
}

// A number cell's value with the file's decimal mark: refused (exit 2, naming the cell) when it
// reads only with the other mark than a cell before showed, or both ways and no cell shows which.
double ReadWithFileMark(const std::string& path, const std::string& where, const std::string& cell,
                        const MarkEvidence& decimal, bool* thousands) {
  const NumberReadings readings = ReadNumber(cell);
  bool grouped = false;
  const std::optional<double> value = readings.With(decimal.mark, &grouped);
  if (value) {
    *thousands = *thousands || grouped;
    return *value;
  }
  if (decimal.mark == DecimalMark::kUnknown) {
    throw InputError(
        path, where,
        fmt::format("'{}' reads as {} with a decimal comma and as {} with a thousands separator, "
                    "and no number in the file shows which decimal mark it uses",
                    cell, *readings.comma, *readings.point),
        "numbers whose decimal mark is evident (a decimal part of other than 3 digits, as in "
        "0,5 or 1.25, or both marks, as in 1.234,5), or no thousands separators");
  }
  const bool comma = decimal.mark == DecimalMark::kComma;
  throw InputError(path, where,
                   fmt::format("'{}' does not read with a decimal {}, which {} ('{}') shows", cell,
                               comma ? "comma" : "point", decimal.where, decimal.cell),
                   fmt::format("one decimal mark in the file: a decimal {} with '{}' or spaces "
                               "as thousands separators",
                               comma ? "comma" : "point", comma ? '.' : ','));
}

}  // namespace

RawTable ReadCsv(const std::string& path) {
  const std::string text = mbid::internal::ReadTextFile(path, kExpected);
  ValidateUtf8Text(text, path);
  CsvDialect dialect;
  const std::vector<TextLine> lines = SplitLines(text, &dialect.bom, &dialect.crlf);
  if (!DetectDialect(lines, &dialect)) {
    const int first = FirstLineOfNumbers(lines);
    if (first > 0) {
      throw InputError(path, LineField(first), "rows of numbers without a line of names above them",
                       "a header line naming each column with its unit, the time first "
                       "(time [s], theta [deg]; numpy.savetxt's header= writes one)");
    }
    throw InputError(path, "", "no header line followed by rows of numbers with as many fields",
                     kExpected);
  }
  const char separator = dialect.separator;
  const int header_line = lines[static_cast<size_t>(dialect.header)].number;
  const std::vector<std::string> header_cells = SplitFields(HeaderText(lines, dialect), separator);
  std::vector<std::string> unit_cells(header_cells.size());
  if (dialect.units_row >= 0) {
    unit_cells = SplitFields(lines[static_cast<size_t>(dialect.units_row)].text, separator);
    FitRow(&unit_cells, header_cells.size());
  }
  const auto cell_field = [&](int line, size_t c) {
    return fmt::format("line {}, column {}", line, c + 1);
  };

  // Names and units from the header and the units row.
  std::vector<NameAndUnit> columns;
  std::set<std::string> seen;
  std::vector<std::string> repeated_at(header_cells.size());
  for (size_t c = 0; c < header_cells.size(); ++c) {
    NameAndUnit column = SplitNameUnit(header_cells[c]);
    const std::string row_unit = StripUnitBrackets(unit_cells[c]);
    if (!row_unit.empty()) {
      if (!column.unit.empty() && column.unit != row_unit) {
        throw InputError(path, cell_field(header_line, c),
                         fmt::format("column '{}' has unit '{}' in the header and '{}' in the "
                                     "units row",
                                     column.name, column.unit, row_unit),
                         "one unit per column");
      }
      column.unit = row_unit;
    }
    if (!column.name.empty() && !seen.insert(column.name).second) {
      repeated_at[c] = cell_field(header_line, c);
    }
    columns.push_back(column);
  }

  // The time column: the first with a time name.
  int time_column = -1;
  for (size_t c = 0; c < columns.size() && time_column < 0; ++c) {
    std::string suffix_unit;
    if (IsTimeColumnName(columns[c].name, &suffix_unit)) {
      time_column = static_cast<int>(c);
      if (columns[c].unit.empty()) columns[c].unit = suffix_unit;
    }
  }

  const int first_row = (dialect.units_row >= 0 ? dialect.units_row : dialect.header) + 1;
  // Else the first column of timestamps ("Date/Time", "Datum Uhrzeit"): no channel holds them.
  // A column of dates alone completes a time of day ("Date;Time" loggers).
  int date_column = -1;
  for (size_t i = static_cast<size_t>(first_row); i < lines.size(); ++i) {
    if (IsCommentOrBlank(lines[i].text)) continue;
    const std::vector<std::string> fields = SplitFields(lines[i].text, separator);
    for (size_t c = 0; c < fields.size() && c < columns.size(); ++c) {
      const CellKind kind = ClassifyCell(fields[c], separator);
      if (time_column < 0 && kind == CellKind::kTimestamp) time_column = static_cast<int>(c);
      if (date_column < 0 && kind == CellKind::kDate) date_column = static_cast<int>(c);
    }
    break;
  }

  const SlashOrder slash_order =
      DecideSlashOrder(path, lines, first_row, separator, {time_column, date_column});

  // Rows. A column of text, no number in any row (a logger's status or event marks), is no
  // channel: its first text is kept until a number in the column makes it an error.
  struct FirstText {
    std::string cell, where;
    int line = 0;
  };
  std::vector<FirstText> text_in(columns.size());
  std::vector<bool> has_value(columns.size(), false);
  const auto not_a_number = [&path](const std::string& cell, const std::string& where) {
    // A number a double cannot hold ('1e400', a 5 MB row of digits) is one, out of range.
    errno = 0;
    char* end = nullptr;
    std::strtod(cell.c_str(), &end);
    const bool out_of_range = !cell.empty() && end == cell.c_str() + cell.size() && errno == ERANGE;
    return InputError(path, where,
                      "'" + cell + "' is " +
                          (out_of_range ? "a number beyond a double's range (1e-308 to 1.8e308)"
                                        : "not a number"),
                      "a decimal number, or an empty cell or NaN for a gap");
  };
  Metadata metadata;
  RawTable table;
  table.columns.resize(columns.size());
  bool timestamps = false;
  Timestamp first_timestamp;
  std::string first_text;
  std::int64_t day_offset = 0, last_seconds = 0;
  int time_place = std::numeric_limits<int>::max();
  int timestamp_decimals = 0;
  const MarkEvidence decimal = FindDecimalMark(lines, first_row, separator);
  bool thousands = false;
  std::vector<bool> written(columns.size(), false);  // a cell of the column holds text
  for (size_t i = 0; i < lines.size(); ++i) {
    const TextLine& line = lines[i];
    if (IsCommentOrBlank(line.text)) {
      ReadComment(line.text, line.number, separator, &metadata);
      continue;
    }
    if (static_cast<int>(i) < first_row) continue;  // preamble, header, units row
    std::vector<std::string> fields = SplitFields(line.text, separator);
    if (!FitRow(&fields, columns.size())) {
      throw InputError(
          path, LineField(line.number), fmt::format("{} fields", fields.size()),
          fmt::format("{} fields as in the header (line {})", columns.size(), header_line));
    }
    const bool first = table.sample_lines.empty();
    Timestamp date;
    if (date_column >= 0 &&
        !ParseDate(fields[static_cast<size_t>(date_column)], &date, slash_order)) {
      throw InputError(
          path, cell_field(line.number, static_cast<size_t>(date_column)),
          "'" + fields[static_cast<size_t>(date_column)] + "' is not a date",
          "a date as in the first row (2026-03-01, 2026/03/01, 01.03.2026 or 01/03/2026)");
    }
    for (size_t c = 0; c < fields.size(); ++c) {
      double value = 0;
      if (static_cast<int>(c) == date_column) {
        table.columns[c].values.push_back(std::numeric_limits<double>::quiet_NaN());
        continue;
      }
      const CellKind kind = ClassifyCell(fields[c], separator, &value);
      if (!mbid::internal::Trim(fields[c]).empty()) written[c] = true;
      const std::string where = fmt::format("{} ({})", cell_field(line.number, c),
                                            columns[c].name.empty() ? "unnamed" : columns[c].name);
      if (static_cast<int>(c) == time_column && first) timestamps = kind == CellKind::kTimestamp;
      if (static_cast<int>(c) == time_column && timestamps) {
        Timestamp timestamp;
        const bool parsed = ParseTimestamp(fields[c], &timestamp, slash_order);
        if (parsed && !timestamp.has_date && date_column >= 0) {
          timestamp.seconds += date.seconds;
          timestamp.has_date = true;
        }
        if (!parsed || (!first && timestamp.has_date != first_timestamp.has_date)) {
          throw InputError(
              path, where, "'" + fields[c] + "' is not a timestamp as in the first row",
              fmt::format("a {} as in the first row ('{}')",
                          !first && !first_timestamp.has_date ? "time of day" : "date and time",
                          first_text));
        }
        if (first) {
          first_timestamp = timestamp;
          first_text = fields[c];
        }
        // A time of day alone runs past midnight into the next day.
        timestamp.seconds += day_offset;
        if (!timestamp.has_date && !first && timestamp.seconds < last_seconds - 43200) {
          day_offset += 86400;
          timestamp.seconds += 86400;
        }
        last_seconds = timestamp.seconds;
        timestamp_decimals = std::max(timestamp_decimals, timestamp.decimals);
        value = SecondsBetween(first_timestamp, timestamp);
      } else if (kind == CellKind::kNumber) {
        value = ReadWithFileMark(path, where, fields[c], decimal, &thousands);
        if (!std::isfinite(value)) {
          throw InputError(path, where, "'" + fields[c] + "' is not finite",
                           "a finite number, or an empty cell or NaN for a gap");
        }
        if (static_cast<int>(c) == time_column) {
          time_place = std::min(
              time_place, PrintedPlace(fields[c], decimal.mark == DecimalMark::kComma ? ',' : '.'));
        }
      } else if (kind == CellKind::kText && static_cast<int>(c) != time_column && !has_value[c]) {
        if (text_in[c].cell.empty()) text_in[c] = {fields[c], where, line.number};
      } else if (kind != CellKind::kGap) {
        throw not_a_number(fields[c], where);
      }
      if (kind != CellKind::kText && kind != CellKind::kGap) {
        if (!text_in[c].cell.empty()) throw not_a_number(text_in[c].cell, text_in[c].where);
        has_value[c] = true;
      }
      table.columns[c].values.push_back(value);
    }
    table.sample_lines.push_back(line.number);
  }
  // A separator at every line's end (spreadsheets, many loggers) makes a column without name,
  // unit or any value: not a channel, so it is dropped rather than refused as unnamed.
  int empty_columns = 0;
  std::vector<size_t> file_column(columns.size());  // for messages after dropping
  for (size_t c = 0; c < columns.size(); ++c) file_column[c] = c;
  for (size_t c = columns.size(); c-- > 0;) {
    const bool unused = columns[c].name.empty() && columns[c].unit.empty() && !written[c];
    if (static_cast<int>(c) != date_column && !unused) continue;
    if (static_cast<int>(c) != date_column) ++empty_columns;
    if (static_cast<int>(c) < time_column) --time_column;
    columns.erase(columns.begin() + static_cast<std::ptrdiff_t>(c));
    table.columns.erase(table.columns.begin() + static_cast<std::ptrdiff_t>(c));
    file_column.erase(file_column.begin() + static_cast<std::ptrdiff_t>(c));
  }

  // mbid's own CSV: ',' and a first column named exactly `time`; channels without a unit are
  // SI by contract (docs/file-formats.md).
  table.si_by_contract = separator == ',' && dialect.units_row < 0 && !dialect.header_in_comment &&
                         !header_cells.empty() && header_cells.front() == "time";
  table.format = table.si_by_contract ? "mbid-csv" : "csv";
  table.dialect = dialect.Describe(decimal.mark == DecimalMark::kComma, thousands);
  if (date_column >= 0) table.dialect += fmt::format(", dates in column {}", date_column + 1);
  if (timestamps) {
    table.dialect += fmt::format(", timestamps read as s from the first ({}){}", first_text,
                                 day_offset > 0 ? ", past midnight into the next day" : "");
  }
  for (size_t c = 0; c < text_in.size(); ++c) {
    if (!text_in[c].cell.empty()) {
      table.dialect += fmt::format(", text in column {}{}, no channel", c + 1,
                                   header_cells[c].empty() ? "" : " (" + header_cells[c] + ")");
    }
  }
  if (empty_columns > 0) {
    table.dialect +=
        fmt::format(", {} empty column{} ignored", empty_columns, empty_columns == 1 ? "" : "s");
  }
  table.source = metadata.source;
  if (metadata.units_line > 0) {
    // "# units: s,rad,rad" may include the time column; "rad,rad" lists the channels.
    std::vector<std::string> units = metadata.units;
    const size_t data_columns = columns.size() - (time_column >= 0 ? 1 : 0);
    if (units.size() == columns.size() && time_column >= 0) {
      units.erase(units.begin() + time_column);
      if (columns[static_cast<size_t>(time_column)].unit.empty()) {
        columns[static_cast<size_t>(time_column)].unit = metadata.units[time_column];
      }
    }
    if (units.size() != data_columns) {
      throw InputError(
          path, LineField(metadata.units_line),
          fmt::format("'# units:' lists {} units for {} channels", units.size(), data_columns),
          "one unit per channel, in header order");
    }
    size_t k = 0;
    for (size_t c = 0; c < columns.size(); ++c) {
      if (static_cast<int>(c) == time_column) continue;
      if (columns[c].unit.empty()) columns[c].unit = units[k];
      ++k;
    }
  }
  if (metadata.interval_line > 0) {
    double stated = 0;
    if (mbid::internal::ParseDouble(metadata.interval_text, &stated) !=
            mbid::internal::ParseStatus::kOk ||
        !(stated > 0) || !std::isfinite(stated)) {
      throw InputError(path, LineField(metadata.interval_line),
                       "'" + metadata.interval_text + "' is not a sample interval",
                       "a positive number of seconds");
    }
    table.stated_interval_s = stated;
    table.stated_interval_where = LineField(metadata.interval_line);
  }

  for (size_t c = 0; c < columns.size(); ++c) {
    table.columns[c].name = columns[c].name;
    table.columns[c].unit = columns[c].unit;
    table.columns[c].where = fmt::format("column {}", file_column[c] + 1);
    table.columns[c].name_repeated_at = repeated_at[file_column[c]];
    const FirstText& marks = text_in[file_column[c]];
    if (!marks.cell.empty()) {
      table.columns[c].text = fmt::format("'{}' at line {}", marks.cell, marks.line);
    }
  }
  if (time_column >= 0) {
    RawColumn time = std::move(table.columns[static_cast<size_t>(time_column)]);
    table.columns.erase(table.columns.begin() + time_column);
    table.time = std::move(time.values);
    table.time_unit = timestamps ? "s" : time.unit;
    table.time_name = time.name;
    table.time_where = time.where;
    table.printed_resolution = timestamps ? std::pow(10.0, -timestamp_decimals)
                               : time_place == std::numeric_limits<int>::max()
                                   ? 0.0
                                   : std::pow(10.0, time_place);
  }
  return table;
}

}  // namespace mbid::records::internal
