// The record layouts of a MAT file: mbid's own (a), a lab's struct (b), one matrix or vectors (c).

#include <fmt/format.h>
#include <matio.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "mat_internal.h"
#include "mbid/common/error.h"
#include "raw_table.h"

namespace mbid::records::internal {

// Layout (a): what WriteMat writes.
RawTable MatReader::ReadMbidLayout() {
  const std::vector<std::string> tag = StringsVar("mbid_layout");
  if (tag.size() != 1 || tag[0] != kMbidLayout) {
    throw VarError("mbid_layout", fmt::format("'{}'", tag.empty() ? "" : Printable(tag[0])),
                   fmt::format("'{}'", kMbidLayout));
  }
  for (const char* required :
       {"channels", "units", "channel_variables", "sample_interval_s", "start_time_s"}) {
    if (!infos_.count(required)) {
      throw InputError(path_, "variable " + std::string(required), "missing",
                       "every variable of mbid's layout (docs/records-formats.md)");
    }
  }
  const std::vector<std::string> channels = StringsVar("channels");
  const std::vector<std::string> units = StringsVar("units");
  const std::vector<std::string> variables = StringsVar("channel_variables");
  if (units.size() != channels.size() || variables.size() != channels.size() || channels.empty()) {
    throw VarError("channels",
                   fmt::format("{} channels, {} units, {} channel_variables", channels.size(),
                               units.size(), variables.size()),
                   "one unit and one variable per channel");
  }
  RawTable table;
  table.format = "mat";
  table.si_by_contract = true;
  table.time_unit = "s";
  table.time_where = "variable sample_interval_s";
  table.interval = Scalar("sample_interval_s");
  table.start = Scalar("start_time_s");
  size_t length = 0;
  for (size_t c = 0; c < channels.size(); ++c) {
    if (!infos_.count(variables[c])) {
      throw VarError(
          "channel_variables",
          fmt::format("variable '{}' of channel '{}' is missing", variables[c], channels[c]),
          "one vector per channel");
    }
    RawColumn column;
    column.name = channels[c];
    column.unit = units[c];
    column.where = "variable " + variables[c];
    column.values = VectorVar(variables[c], length);
    length = column.values.size();
    table.columns.push_back(std::move(column));
  }
  return table;
}

std::optional<std::string> MatReader::FindFirst(std::initializer_list<const char*> names) const {
  for (const char* name : names) {
    if (infos_.count(name)) return std::string(name);
  }
  return std::nullopt;
}

// Times from a scalar rate or interval (and start), when one is present.
bool MatReader::TimeFromScalars(RawTable* table) {
  const auto rate = FindFirst({"fs", "Fs", "sample_rate_hz"});
  const auto step = FindFirst({"dt", "sample_interval_s"});
  if (rate && step) {
    throw VarError(*step, fmt::format("both {} and {} give the sampling", *rate, *step),
                   "one of a sample rate (fs, Fs, sample_rate_hz) or an interval (dt, "
                   "sample_interval_s)");
  }
  if (!rate && !step) return false;
  const std::string name = rate ? *rate : *step;
  const double value = Scalar(name);
  if (!(value > 0)) {
    throw VarError(name, fmt::format("{}", value), "a positive sample rate or interval");
  }
  table->interval = rate ? 1.0 / value : value;
  table->time_where = "variable " + name;
  if (const auto start = FindFirst({"t0", "start_time_s"})) table->start = Scalar(*start);
  return true;
}

void MatReader::SetTimeColumn(std::vector<double> time, const VarInfo& info, RawTable* table) {
  double largest = 0;
  for (double t : time) largest = std::max(largest, std::abs(t));
  // Single-precision times are exact to a float's last bit only.
  if (info.class_type == MAT_C_SINGLE) table->printed_resolution = largest * 0x1p-23;
  table->time = std::move(time);
  table->time_where = "variable " + info.name;
}

// Layouts (b) and (c): a lab's struct, one matrix, or vectors.
RawTable MatReader::ReadLabLayout() {
  RawTable table;
  table.format = "mat";
  table.time_unit = "s";
  table.time_unit_assumed = true;  // a lab's file: MAT carries no units
  // (b) a struct with fields time and data.
  std::vector<std::string> structs;
  std::vector<std::string> matrices;
  std::vector<std::string> vectors;
  for (const std::string& name : order_) {
    const VarInfo& info = infos_.at(name);
    if (info.class_type == MAT_C_STRUCT) {
      structs.push_back(name);
    } else if (info.numeric() && info.matrix()) {
      matrices.push_back(name);
    } else if (info.numeric() && info.vector_length() > 0) {
      vectors.push_back(name);
    }
  }
  std::vector<std::string> record_structs;
  for (const std::string& name : structs) {
    const MatVar var = Load(infos_.at(name));
    if (Mat_VarGetStructFieldByName(var.get(), "time", 0) != nullptr &&
        Mat_VarGetStructFieldByName(var.get(), "data", 0) != nullptr) {
      record_structs.push_back(name);
    }
  }
  if (record_structs.size() > 1) {
    throw VarError(record_structs[1],
                   fmt::format("a second struct with time and data (after {})", record_structs[0]),
                   "one record per file");
  }
  if (record_structs.size() == 1) return ReadStruct(record_structs[0], table);
  if (matrices.size() > 1) {
    throw VarError(matrices[1], fmt::format("a second matrix (after {})", matrices[0]),
                   "one matrix of samples x columns, or vectors");
  }
  if (matrices.size() == 1) {
    if (!vectors.empty()) {
      throw VarError(vectors[0], fmt::format("a vector beside the matrix {}", matrices[0]),
                     "one matrix of samples x columns, or vectors (not both)");
    }
    return ReadMatrix(matrices[0], table);
  }
  return ReadVectors(vectors, table);
}

// Samples along the longer dimension of `info` (a record has more samples than columns).
std::vector<std::vector<double>> MatReader::Columns(const std::vector<double>& values, size_t rows,
                                                    size_t cols, bool samples_in_rows) const {
  const size_t n = samples_in_rows ? rows : cols, k = samples_in_rows ? cols : rows;
  std::vector<std::vector<double>> out(k, std::vector<double>(n));
  for (size_t c = 0; c < k; ++c) {
    for (size_t j = 0; j < n; ++j) {
      out[c][j] = samples_in_rows ? values[j + c * rows] : values[c + j * rows];
    }
  }
  return out;
}

// Optional names/units for `count` data columns; a list one longer names the time column
// first.
std::vector<std::string> MatReader::Labels(const std::vector<std::string>& given, size_t count,
                                           const std::string& where) const {
  if (given.empty()) return std::vector<std::string>(count);
  if (given.size() == count) return given;
  if (given.size() == count + 1) return {given.begin() + 1, given.end()};
  throw VarError(where, fmt::format("{} entries for {} data columns", given.size(), count),
                 "one entry per data column (or one more, naming time first)");
}

void MatReader::AddColumns(std::vector<std::vector<double>> data,
                           const std::vector<std::string>& names,
                           const std::vector<std::string>& units, const std::string& where,
                           RawTable* table) const {
  for (size_t c = 0; c < data.size(); ++c) {
    RawColumn column;
    column.name = names[c].empty() ? fmt::format("column {}", c + 1) : names[c];
    column.unit = units[c];
    column.where = fmt::format("{}, column {}", where, c + 1);
    column.values = std::move(data[c]);
    table->columns.push_back(std::move(column));
  }
}

RawTable MatReader::ReadStruct(const std::string& name, RawTable& table) {
  const MatVar var = Load(infos_.at(name));
  const auto field = [&](const char* field_name) {
    return Mat_VarGetStructFieldByName(var.get(), field_name, 0);
  };
  if (InfoOf(*var, name).elements != 1) {
    throw VarError(name, fmt::format("a {} struct array", InfoOf(*var, name).Shape()),
                   "a 1x1 struct");
  }
  const std::string time_name = name + ".time", data_name = name + ".data";
  const VarInfo time_info = InfoOf(*field("time"), time_name);
  const VarInfo data_info = InfoOf(*field("data"), data_name);
  if (!time_info.numeric() || time_info.vector_length() == 0) {
    throw VarError(time_name, fmt::format("a {}", time_info.Shape()), "a vector of times");
  }
  if (!data_info.numeric() || data_info.dims.size() != 2) {
    throw VarError(data_name, fmt::format("a {}", data_info.Shape()),
                   "a numeric matrix, samples x channels");
  }
  const size_t n = time_info.vector_length();
  const size_t rows = data_info.dims[0], cols = data_info.dims[1];
  if (rows != n && cols != n) {
    throw VarError(data_name, fmt::format("{}x{} for {} times", rows, cols, n),
                   "one row (or column) per time");
  }
  SetTimeColumn(Doubles(*field("time"), time_name), time_info, &table);
  auto data = Columns(Doubles(*field("data"), data_name), rows, cols, rows == n);
  std::vector<std::string> names, units;
  for (const char* key : {"names", "channels", "labels"}) {
    if (matvar_t* f = field(key)) {
      names = Strings(*f, name + "." + key);
      break;
    }
  }
  if (matvar_t* f = field("units")) units = Strings(*f, name + ".units");
  const size_t count = data.size();
  AddColumns(std::move(data), Labels(names, count, name + ".names"),
             Labels(units, count, name + ".units"), "variable " + data_name, &table);
  return table;
}

std::vector<std::string> MatReader::OptionalStrings(std::initializer_list<const char*> keys) {
  if (const auto name = FindFirst(keys)) return StringsVar(*name);
  return {};
}

RawTable MatReader::ReadMatrix(const std::string& name, RawTable& table) {
  const VarInfo& info = infos_.at(name);
  const MatVar var = Load(info);
  const size_t rows = info.dims[0], cols = info.dims[1];
  auto columns = Columns(Doubles(*var, name), rows, cols, rows >= cols);
  // With a rate or interval every column is a channel; without, the first is time.
  if (!TimeFromScalars(&table)) {
    VarInfo time_info = info;
    time_info.name = name + ", column 1";
    SetTimeColumn(std::move(columns.front()), time_info, &table);
    columns.erase(columns.begin());
  }
  if (columns.empty()) {
    throw VarError(name, fmt::format("a {} with only a time column", info.Shape()),
                   "time and at least one channel column");
  }
  const auto names = OptionalStrings({"channels", "names", "labels"});
  const auto units = OptionalStrings({"units"});
  const std::string names_var = FindFirst({"channels", "names", "labels"}).value_or("names");
  const size_t count = columns.size();
  AddColumns(std::move(columns), Labels(names, count, names_var), Labels(units, count, "units"),
             "variable " + name, &table);
  return table;
}

RawTable MatReader::ReadVectors(const std::vector<std::string>& vectors, RawTable& table) {
  const auto time_name = FindFirst({"time", "t", "Time"});
  if (time_name && infos_.at(*time_name).vector_length() == 0) {
    throw VarError(*time_name, fmt::format("a {}", infos_.at(*time_name).Shape()),
                   "a vector of times");
  }
  const bool from_scalars = TimeFromScalars(&table);
  if (time_name && from_scalars) {
    throw VarError(*time_name, "both a time vector and " + table.time_where.substr(9),
                   "either a time vector or a sample rate/interval");
  }
  if (!time_name && !from_scalars) {
    throw InputError(path_, "", "no time base",
                     "a time vector (time, t), a sample rate (fs, Fs, sample_rate_hz) or "
                     "an interval (dt, sample_interval_s); or one matrix with time first");
  }
  size_t length = 0;
  if (time_name) {
    SetTimeColumn(VectorVar(*time_name, 0), infos_.at(*time_name), &table);
    length = table.time.size();
  }
  for (const std::string& name : vectors) {
    if (time_name && name == *time_name) continue;
    RawColumn column;
    column.name = name;
    column.where = "variable " + name;
    column.values = VectorVar(name, length);
    length = column.values.size();
    table.columns.push_back(std::move(column));
  }
  if (table.columns.empty()) {
    throw InputError(path_, "", "no channel vectors",
                     "numeric vectors of samples, one per channel");
  }
  return table;
}

}  // namespace mbid::records::internal
