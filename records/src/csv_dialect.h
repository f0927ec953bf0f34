#pragma once

// How a logger's text export is laid out (docs/records.md, "Dialects"): separator, decimal
// comma, byte order mark, line ends, preamble lines, header and units row. Found from the text
// itself, never from the file name.

#include <string>
#include <vector>

namespace mbid::records::internal {

struct TextLine {
  int number = 0;  // 1-based, as an editor shows it
  std::string text;
};

// The file's lines without a UTF-8 byte order mark and without CR/CRLF line ends.
std::vector<TextLine> SplitLines(const std::string& text, bool* bom, bool* crlf);

// Fields of one line, trimmed and without surrounding double quotes ("a;b" stays one field);
// separator ' ' splits on runs of blanks.
std::vector<std::string> SplitFields(const std::string& line, char separator);

// Whether a row of `fields` fits a header of `columns` fields: as many, or one more that is
// empty (a separator at the line's end, which spreadsheets and many loggers write); that one
// is dropped.
bool FitRow(std::vector<std::string>* fields, size_t columns);

enum class CellKind { kNumber, kGap, kTimestamp, kDate, kText };

// A data cell: a decimal number (with a decimal comma where the separator is not ',', and
// thousands separators: number_marks.h), a gap (empty, NaN, nan), a timestamp or a date alone
// (iso_time.h), or text. `value` is set for numbers (NaN for gaps): with a decimal comma when the
// cell reads so (the reader decides a cell that reads both ways by the file's decimal mark).
CellKind ClassifyCell(const std::string& cell, char separator, double* value = nullptr);

struct CsvDialect {
  char separator = ',';
  bool bom = false;
  bool crlf = false;
  int header = -1;     // index into the lines
  int units_row = -1;  // index into the lines, or -1
  int field_count = 0;
  int preamble_lines = 0;          // lines before the header other than comments and blank lines
  bool header_in_comment = false;  // "# time_s angle_rad" right above the numbers
  // "';'-separated, decimal comma, thousands separators, CRLF, BOM, 3 preamble lines, units row"
  std::string Describe(bool decimal_comma, bool thousands = false) const;
};

// The header is the first line followed (after an optional units row: every cell empty or a
// unit) by a data row with as many fields; the separator is the one of ',' ';' tab that finds
// a header with the most fields, else blanks (' ': runs of spaces and tabs); else a comment line
// of names right above the numbers. Returns false when none is found.
bool DetectDialect(const std::vector<TextLine>& lines, CsvDialect* dialect);

// The line number of the file's first content line when it is numbers alone (a file without a
// header), else 0.
int FirstLineOfNumbers(const std::vector<TextLine>& lines);

// Whether the line is a comment ('#') or blank: neither header nor data.
bool IsCommentOrBlank(const std::string& line);

// A comment line's text after its '#'s.
std::string CommentBody(const std::string& line);

// The header's text (a header in a comment without its '#').
std::string HeaderText(const std::vector<TextLine>& lines, const CsvDialect& dialect);

}  // namespace mbid::records::internal
