#pragma once

// The common shape every file reader produces before conversion to SI (import.cc): named
// columns with the units the file states, a time base, and NaN where a cell is empty.

#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace mbid::records::internal {

struct RawColumn {
  std::string name;            // as in the file (trimmed); "" when the file has none
  std::string unit;            // as in the file ("deg", "m/s^2"); "" when the file states none
  std::string where;           // for messages: "column 3", "dataset 2 (line 40)", "variable theta"
  std::vector<double> values;  // one per sample; NaN marks a gap (empty or NaN cell)
  // A column of text, no number in it (a logger's status or event marks): "" for a column of
  // numbers, else its first text cell and where it is ("'OK' at line 2"). Not a channel.
  std::string text;
  // Where the name repeats an earlier column's ("line 1, column 3"); "" when it is unique. Such a
  // column is read by its number only: by name it is ambiguous.
  std::string name_repeated_at;
};

struct RawTable {
  std::string format;   // as ImportReport::format
  std::string dialect;  // as ImportReport::dialect ("" when there is nothing to say)
  std::string source;   // Measurement::source when the file states one, else ""
  // Time base: either a time column (`time`, in `time_unit`, NaN for a gap) or, when
  // `time` is empty, a uniform grid start + j * interval in `time_unit`.
  std::vector<double> time;
  std::string time_unit;  // "" when the file states none
  // `time_unit` is the format's default, not the file's word (a MAT file's time, an LVM file
  // without X_Unit_Label): a logger's ms read as s goes unnoticed but for the step.
  bool time_unit_assumed = false;
  std::string time_name;   // the time column's name in the file ("Zeit"), or ""
  std::string time_where;  // "column 1", ...
  double start = 0.0;
  double interval = 0.0;
  // Place value of the last printed digit of `interval` (a header's "Delta_X 0.000333", UFF
  // record 7's six digits), or 0 when it is exact.
  double interval_resolution = 0.0;
  // Place value of the last printed digit of the time column in `time_unit` (text files), or 0.
  double printed_resolution = 0.0;
  // The sample interval the file states besides its time column (mbid's
  // `# sample_interval_s:`), in s, or 0: used exactly when it agrees with the time column, so
  // that mbid's own files round-trip bit for bit.
  double stated_interval_s = 0.0;
  std::string stated_interval_where;
  // Line number of each sample for messages (text formats), else empty.
  std::vector<int> sample_lines;
  std::vector<RawColumn> columns;
  // True for mbid's own SI formats (CSV with a `time` header and HDF5): values without a stated
  // unit are SI by contract (docs/interfaces.md), not a missing unit.
  bool si_by_contract = false;
};

// Readers of the formats other tools write (docs/records-formats.md). Each reads `path` whole,
// checks it and returns its columns as the file states them; a file that breaks its format is an
// InputError naming `path` and the line, dataset or variable.
RawTable ReadUff58(const std::string& path);  // UFF dataset 58, ASCII and binary (58b)
RawTable ReadLvm(const std::string& path);    // LabVIEW Measurement (.lvm)
RawTable ReadMat(const std::string& path);    // MATLAB .mat, v5 and v7.3

}  // namespace mbid::records::internal
