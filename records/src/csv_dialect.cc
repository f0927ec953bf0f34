#include "csv_dialect.h"

#include <fmt/format.h>

#include <algorithm>
#include <limits>
#include <optional>

#include "header_cells.h"
#include "internal.h"
#include "iso_time.h"
#include "number_marks.h"
#include "units.h"

namespace mbid::records::internal {
namespace {

// A row of values; a logger's status or event column may put text among them, so a row with
// text is data when it holds at least 2 values and more values than text cells (a header's
// names are text, a preamble line "Device;XYZ-200;Serial;12345" has one number).
bool IsDataRow(const std::vector<std::string>& fields, char separator) {
  int values = 0, texts = 0;
  for (const std::string& cell : fields) {
    const CellKind kind = ClassifyCell(cell, separator);
    if (kind == CellKind::kText) {
      ++texts;
    } else if (kind != CellKind::kGap) {
      ++values;
    }
  }
  return values > 0 && (texts == 0 || (values >= 2 && values > texts));
}

bool IsUnitsRow(const std::vector<std::string>& fields) {
  bool any_unit = false;
  for (const std::string& cell : fields) {
    if (cell.empty()) continue;
    if (!IsUnit(StripUnitBrackets(cell))) return false;
    any_unit = true;
  }
  return any_unit;
}

}  // namespace

std::vector<TextLine> SplitLines(const std::string& text, bool* bom, bool* crlf) {
  size_t at = 0;
  *bom = text.compare(0, 3, "\xEF\xBB\xBF") == 0;
  if (*bom) at = 3;
  *crlf = false;
  std::vector<TextLine> lines;
  int number = 0;
  while (at < text.size()) {
    const size_t end = text.find_first_of("\r\n", at);
    const size_t stop = end == std::string::npos ? text.size() : end;
    lines.push_back({++number, text.substr(at, stop - at)});
    if (end == std::string::npos) break;
    at = end + 1;
    if (text[end] == '\r' && at < text.size() && text[at] == '\n') {
      *crlf = true;
      ++at;
    }
  }
  return lines;
}

namespace {

// Fields of a line whose columns are aligned by blanks (a `.txt` from numpy.savetxt, a
// spreadsheet's "formatted text", an oscilloscope's `.dat`): runs of spaces and tabs part them;
// a bracketed unit after a name ("time [s]", "y (mm)") belongs to it.
std::vector<std::string> SplitOnBlanks(const std::string& line) {
  std::vector<std::string> fields;
  std::string field;
  bool quoted = false;
  const auto close = [&] {
    if (field.empty()) return;
    const char open = field.front();
    const bool after_name =
        !fields.empty() && fields.back().front() != '[' && fields.back().front() != '(';
    if ((open == '[' || open == '(') && after_name && !quoted) {
      fields.back() += " " + field;
    } else {
      fields.push_back(field);
    }
    field.clear();
  };
  for (const char c : line) {
    if (c == '"') quoted = !quoted;
    if ((c == ' ' || c == '\t') && !quoted) {
      close();
    } else {
      field += c;
    }
  }
  close();
  for (std::string& f : fields) {
    if (f.size() >= 2 && f.front() == '"' && f.back() == '"') f = f.substr(1, f.size() - 2);
  }
  return fields;
}

}  // namespace

std::vector<std::string> SplitFields(const std::string& line, char separator) {
  if (separator == ' ') return SplitOnBlanks(line);
  std::vector<std::string> fields;
  std::string field;
  bool quoted = false;
  for (const char c : line) {
    if (c == '"') {
      quoted = !quoted;
      field += c;
    } else if (c == separator && !quoted) {
      fields.push_back(field);
      field.clear();
    } else {
      field += c;
    }
  }
  fields.push_back(field);
  for (std::string& f : fields) {
    f = mbid::internal::Trim(f);
    if (f.size() >= 2 && f.front() == '"' && f.back() == '"') f = f.substr(1, f.size() - 2);
  }
  return fields;
}

bool FitRow(std::vector<std::string>* fields, size_t columns) {
  if (fields->size() == columns + 1 && fields->back().empty()) fields->pop_back();
  return fields->size() == columns;
}

CellKind ClassifyCell(const std::string& cell, char separator, double* value) {
  if (value != nullptr) *value = std::numeric_limits<double>::quiet_NaN();
  if (cell.empty() || cell == "NaN" || cell == "nan" || cell == "NAN") return CellKind::kGap;
  // A ','-separated file has a decimal point, unless its quoted cells show a decimal comma
  // ("0,0005"); the file's mark decides the value (csv_reader.cc).
  const NumberReadings readings = ReadNumber(cell);
  const std::optional<double> number = separator == ','
                                           ? (readings.point ? readings.point : readings.comma)
                                       : readings.comma ? readings.comma
                                                        : readings.point;
  if (number) {
    if (value != nullptr) *value = *number;
    return CellKind::kNumber;
  }
  Timestamp timestamp;
  // "01/03/2026" either way round: the record's dates decide which (csv_reader.cc).
  for (const SlashOrder order : {SlashOrder::kDayFirst, SlashOrder::kMonthFirst}) {
    if (ParseTimestamp(cell, &timestamp, order)) return CellKind::kTimestamp;
    if (ParseDate(cell, &timestamp, order)) return CellKind::kDate;
  }
  return CellKind::kText;
}

bool IsCommentOrBlank(const std::string& line) {
  const std::string trimmed = mbid::internal::Trim(line);
  return trimmed.empty() || trimmed.front() == '#';
}

std::string CommentBody(const std::string& line) {
  const std::string trimmed = mbid::internal::Trim(line);
  size_t at = 0;
  while (at < trimmed.size() && trimmed[at] == '#') ++at;
  return mbid::internal::Trim(trimmed.substr(at));
}

std::string HeaderText(const std::vector<TextLine>& lines, const CsvDialect& dialect) {
  const std::string& text = lines[static_cast<size_t>(dialect.header)].text;
  return dialect.header_in_comment ? CommentBody(text) : text;
}

namespace {

// Where the header is and what follows it; the byte order mark and line ends stay as found.
void PlaceHeader(CsvDialect* dialect, char separator, int header, int units_row, size_t fields,
                 size_t preamble_lines, bool in_comment = false) {
  dialect->separator = separator;
  dialect->header = header;
  dialect->header_in_comment = in_comment;
  dialect->units_row = units_row;
  dialect->field_count = static_cast<int>(fields);
  dialect->preamble_lines = static_cast<int>(preamble_lines);
}

// Whether the content lines from `first` on (up to kRowsChecked of them) are all rows of
// `columns` fields that are data: a header candidate's rows must go on as it says. Two data lines
// of a ';' file with decimal commas ("1,49;34,999;-12" then "1,5;35;-11,998") split on ',' as a
// 3-field "header" and a row; the line after had 4 fields, and the file was refused.
bool RowsFollow(const std::vector<TextLine>& lines, const std::vector<int>& content, size_t first,
                size_t columns, char separator) {
  constexpr size_t kRowsChecked = 20;
  for (size_t k = first; k < content.size() && k < first + kRowsChecked; ++k) {
    auto row = SplitFields(lines[static_cast<size_t>(content[k])].text, separator);
    if (!FitRow(&row, columns) || !IsDataRow(row, separator)) return false;
  }
  return true;
}

// numpy.savetxt(header=...) and many scripts name the columns in a comment line right above the
// numbers ("# time_s angle_rad"): taken where no line of names stands elsewhere.
bool FindHeaderInComment(const std::vector<TextLine>& lines, const std::vector<int>& content,
                         CsvDialect* dialect) {
  if (content.empty()) return false;
  int above = content.front() - 1;
  while (above >= 0 && mbid::internal::Trim(lines[static_cast<size_t>(above)].text).empty()) {
    --above;
  }
  if (above < 0) return false;
  const std::string body = CommentBody(lines[static_cast<size_t>(above)].text);
  for (const char separator : {',', ';', '\t', ' '}) {
    const auto header = SplitFields(body, separator);
    const bool names = std::all_of(header.begin(), header.end(), [&](const std::string& cell) {
      return !cell.empty() && ClassifyCell(cell, separator) == CellKind::kText;
    });
    if (header.size() < 2 || !names || !RowsFollow(lines, content, 0, header.size(), separator)) {
      continue;
    }
    PlaceHeader(dialect, separator, above, -1, header.size(), 0, true);
    return true;
  }
  return false;
}

}  // namespace

int FirstLineOfNumbers(const std::vector<TextLine>& lines) {
  for (const TextLine& line : lines) {
    if (IsCommentOrBlank(line.text)) continue;
    for (const char separator : {',', ';', '\t', ' '}) {
      const auto fields = SplitFields(line.text, separator);
      if (std::all_of(fields.begin(), fields.end(), [&](const std::string& cell) {
            return ClassifyCell(cell, separator) == CellKind::kNumber;
          })) {
        return line.number;
      }
    }
    return 0;
  }
  return 0;
}

bool DetectDialect(const std::vector<TextLine>& lines, CsvDialect* dialect) {
  std::vector<int> content;  // indices of lines that are neither comments nor blank
  for (size_t i = 0; i < lines.size(); ++i) {
    if (!IsCommentOrBlank(lines[i].text)) content.push_back(static_cast<int>(i));
  }
  // A header stands among the first lines, after a preamble of at most this many.
  constexpr size_t kMaxPreamble = 1000;
  bool found = false, found_follows = false;
  std::optional<CsvDialect> first_row_broken;
  // Blanks part the columns only where no other separator does: a tab file's names hold spaces.
  for (const char separator : {',', ';', '\t', ' '}) {
    if (separator == ' ' && found) break;
    bool passed_one = false;  // a candidate whose rows did not follow
    for (size_t k = 0; k + 1 < content.size() && k <= kMaxPreamble; ++k) {
      const auto header = SplitFields(lines[content[k]].text, separator);
      if (header.size() < 2 || IsDataRow(header, separator)) continue;
      // Below a candidate whose rows broke off, only names make a header: a data row with a
      // text cell ("0.01,zero") is the bad row the first candidate's error should name.
      const bool names = std::all_of(header.begin(), header.end(), [&](const std::string& cell) {
        return ClassifyCell(cell, separator) == CellKind::kText || cell.empty();
      });
      if (passed_one && !names) continue;
      auto next = SplitFields(lines[content[k + 1]].text, separator);
      if (!FitRow(&next, header.size())) continue;
      int units_row = -1;
      if (!IsDataRow(next, separator)) {
        const auto data = [&] {
          auto row = SplitFields(lines[content[k + 2]].text, separator);
          return FitRow(&row, header.size()) && IsDataRow(row, separator);
        };
        if (k + 2 < content.size() && IsUnitsRow(next) && data()) {
          units_row = content[k + 1];
        } else {
          // Names over a row of numbers with a damaged cell ("0,1" and a NUL, a cell of 10^7
          // digits): the row below had been taken for the header ("no time column"). This one
          // stands where no other does, and the bad cell's error names it.
          const bool numbers = std::any_of(next.begin(), next.end(), [&](const std::string& c) {
            return ClassifyCell(c, separator) == CellKind::kNumber;
          });
          if (names && numbers) {
            if (!first_row_broken) {
              first_row_broken = *dialect;
              PlaceHeader(&*first_row_broken, separator, content[k], -1, header.size(), k);
            }
            passed_one = true;
          }
          continue;
        }
      }
      // A header whose rows go on as it says wins; then the most fields ("a,b;c" is not a ';'
      // file); ties go to the earlier separator. A header whose rows break off soon still
      // stands where it is the only one (the bad row's error then names its cell).
      const bool follows =
          RowsFollow(lines, content, units_row < 0 ? k + 1 : k + 2, header.size(), separator);
      if (!found || (follows && !found_follows) ||
          (follows == found_follows && static_cast<int>(header.size()) > dialect->field_count)) {
        found = true;
        found_follows = follows;
        PlaceHeader(dialect, separator, content[k], units_row, header.size(), k);
      }
      // A logger's preamble line of a name and numbers ("Messbereich;-10;10") reads as a row
      // under the one above it ("Abtastrate;100;Hz"): the header whose rows follow is looked
      // for further down (a trial's such file was refused).
      if (follows) break;
      passed_one = true;
    }
  }
  if (found) return true;
  if (FindHeaderInComment(lines, content, dialect)) return true;
  if (first_row_broken) {
    *dialect = *first_row_broken;
    return true;
  }
  // One column (a single channel logged without a time column: its sample rate comes from
  // --sample-rate-hz): a name, maybe a units row, then numbers, one per line. The separator is
  // one the lines do not hold, so that a decimal comma stays in its number.
  for (const char separator : {'\t', ';', ','}) {
    const bool absent = std::none_of(content.begin(), content.end(), [&](int i) {
      return lines[static_cast<size_t>(i)].text.find(separator) != std::string::npos;
    });
    if (!absent) continue;
    for (size_t k = 0; k + 1 < content.size(); ++k) {
      const auto header = SplitFields(lines[content[k]].text, separator);
      if (header.size() != 1 || header[0].empty() || IsDataRow(header, separator)) continue;
      const auto next = SplitFields(lines[content[k + 1]].text, separator);
      int units_row = -1;
      if (!IsDataRow(next, separator)) {
        if (k + 2 >= content.size() || !IsUnitsRow(next)) continue;
        if (!IsDataRow(SplitFields(lines[content[k + 2]].text, separator), separator)) continue;
        units_row = content[k + 1];
      }
      PlaceHeader(dialect, separator, content[k], units_row, 1, k);
      return true;
    }
    break;
  }
  return false;
}

std::string CsvDialect::Describe(bool decimal_comma, bool thousands) const {
  std::string text = field_count == 1    ? "one column"
                     : separator == '\t' ? "tab-separated"
                     : separator == ' '  ? "blank-separated"
                                         : fmt::format("'{}'-separated", separator);
  if (header_in_comment) text += ", header in a comment";
  if (decimal_comma) text += ", decimal comma";
  if (thousands) text += ", thousands separators";
  if (crlf) text += ", CRLF";
  if (bom) text += ", BOM";
  if (preamble_lines > 0) {
    text += fmt::format(", {} preamble line{}", preamble_lines, preamble_lines == 1 ? "" : "s");
  }
  if (units_row >= 0) text += ", units row";
  return text;
}

}  // namespace mbid::records::internal
