// Universal File Format dataset 58 (function at nodal DOF): time responses in, measured records
// out, in the ASCII form and the binary form 58b (docs/records-formats.md). This file: the
// datasets (framing, records 1 to 11) and one table from them (uff58_internal.h has the reader).

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "mbid/common/error.h"
#include "raw_table.h"
#include "text_util.h"
#include "uff58_internal.h"

namespace mbid::records::internal {
namespace {

constexpr char kUff58File[] =
    "a universal file of dataset 58 time responses (docs/records-formats.md)";

// Record 7, field 1: the ordinate data types of dataset 58.
constexpr int kRealSingle = 2;
constexpr int kRealDouble = 4;
constexpr int kComplexSingle = 5;
constexpr int kComplexDouble = 6;
// Record 6, field 1: a time response; record 8, field 1: time (0: unknown, also accepted).
constexpr int kTimeResponse = 1;
constexpr int kSpecTime = 17;
constexpr int kSpecAcceleration = 12;

// Fixed-width field [begin, begin + width) of a record line, trimmed ("" past its end).
std::string_view Column(std::string_view line, size_t begin, size_t width) {
  if (begin >= line.size()) return {};
  return TrimView(line.substr(begin, width));
}

std::string Label(std::string_view text) {
  std::string label = TrimText(text);
  return label == "NONE" ? std::string() : label;
}

const char* DirectionText(long long direction) {
  static const char* const kNames[] = {"", "+X", "+Y", "+Z", "+RX", "+RY", "+RZ"};
  static const char* const kNegative[] = {"", "-X", "-Y", "-Z", "-RX", "-RY", "-RZ"};
  if (direction >= 0 && direction <= 6) return kNames[direction];
  if (direction < 0 && direction >= -6) return kNegative[-direction];
  return "";
}

}  // namespace

bool IsDelimiter(std::string_view line) { return TrimView(line) == "-1"; }

RawTable Uff58Reader::Read() {
  // Datasets are framed by lines "    -1"; anything before the first frame is not UFF.
  bool seen_frame = false;
  while (auto line = lines_.Next()) {
    if (TrimView(*line).empty()) continue;
    if (!IsDelimiter(*line)) {
      throw InputError(path_, LineField(lines_.line()),
                       seen_frame ? "text between datasets" : "the file does not start with -1",
                       "datasets framed by lines '    -1' (universal file format)");
    }
    seen_frame = true;
    ReadDataset();
  }
  if (datasets_.empty()) {
    throw InputError(path_, "", "no dataset 58 in the file", kUff58File);
  }
  return Combine();
}

// After a frame's opening "-1": the dataset number line, then the dataset through its "-1".
void Uff58Reader::ReadDataset() {
  std::optional<std::string_view> id_line;
  while ((id_line = lines_.Next()) && TrimView(*id_line).empty()) {
  }
  if (!id_line) {
    throw InputError(path_, LineField(lines_.line()), "the file ends after '-1'",
                     "a dataset number line");
  }
  const int id_at = lines_.line();
  const std::vector<std::string_view> id = SplitWhitespace(*id_line);
  if (IsDelimiter(*id_line)) {
    throw InputError(path_, LineField(id_at), "an empty dataset (-1 twice)",
                     "a dataset number line");
  }
  if (id[0] == "58" || id[0] == "58b") {
    ReadDataset58(id, id_at);
  } else {
    SkipDataset(id, id_at);
  }
}

// Another dataset type (units 164, nodes 15, ...): skipped through its closing -1. A binary
// dataset ("2414b ...") states its byte count like 58b and is skipped by it.
void Uff58Reader::SkipDataset(const std::vector<std::string_view>& id, int id_at) {
  const std::string_view type = id[0];
  long long ascii_lines = 0, byte_count = 0;
  if (!type.empty() && type.back() == 'b' && id.size() >= 5 &&
      ParseInteger(id[3], 0, 1000000, &ascii_lines) &&
      ParseInteger(id[4], 0, static_cast<long long>(lines_.remaining()), &byte_count)) {
    for (long long i = 0; i < ascii_lines; ++i) {
      if (!lines_.Next()) break;
    }
    if (static_cast<size_t>(byte_count) <= lines_.remaining()) {
      lines_.Bytes(static_cast<size_t>(byte_count));
    }
  }
  while (auto line = lines_.Next()) {
    if (IsDelimiter(*line)) return;
  }
  throw InputError(path_, LineField(id_at),
                   fmt::format("dataset {} has no closing -1", std::string(type)),
                   "every dataset closed by a line '    -1'");
}

std::string_view Uff58Reader::NextRecord(const Dataset& dataset, int record) {
  auto line = lines_.Next();
  if (!line || IsDelimiter(*line)) {
    throw InputError(path_, fmt::format("{}, record {}", dataset.where, record),
                     line ? "the dataset ends before its header does" : "the file ends",
                     "records 1 to 11 of dataset 58, then the data");
  }
  return *line;
}

InputError Uff58Reader::RecordError(const Dataset& dataset, int record, const std::string& problem,
                                    const std::string& expected) const {
  return InputError(path_,
                    fmt::format("{}, record {} (line {})", dataset.where, record, lines_.line()),
                    problem, expected);
}

void Uff58Reader::ReadDataset58(const std::vector<std::string_view>& id, int id_at) {
  Dataset d;
  d.first_line = id_at;
  d.where = fmt::format("dataset {} (line {})", datasets_.size() + 1, id_at);
  d.binary = id[0] == "58b";

  // 58b: byte order (1 little, 2 big endian), floating point format (2 IEEE 754), number of
  // ASCII lines that follow (11), bytes of data after them.
  bool big_endian = false;
  long long byte_count = 0;
  if (d.binary) {
    long long order = 0, float_format = 0, ascii_lines = 0;
    const std::string field = fmt::format("{}, header", d.where);
    if (id.size() < 5 || !ParseInteger(id[1], 1, 2, &order)) {
      throw InputError(path_, field, "no byte ordering 1 or 2 in the 58b header",
                       "'58b', byte ordering (1 little, 2 big endian), floating point format "
                       "(2 IEEE 754), 11, byte count");
    }
    if (!ParseInteger(id[2], 0, 1000, &float_format) || float_format != 2) {
      throw InputError(path_, field, fmt::format("floating point format '{}'", std::string(id[2])),
                       "2 (IEEE 754); DEC VMS (1) and IBM 370 (3) floats are not read");
    }
    if (!ParseInteger(id[3], 0, 1000, &ascii_lines) || ascii_lines != 11) {
      throw InputError(path_, field, fmt::format("'{}' ASCII lines", std::string(id[3])),
                       "11 ASCII lines (records 1 to 11) before the binary data");
    }
    if (!ParseInteger(id[4], 0, static_cast<long long>(lines_.remaining()), &byte_count)) {
      throw InputError(path_, field,
                       fmt::format("byte count '{}' with {} bytes left in the file",
                                   std::string(id[4]), lines_.remaining()),
                       "the number of bytes of binary data, within the file");
    }
    big_endian = order == 2;
  }

  // Records 1-5: ID lines. ID line 1 names the channel; mbid writes its exact time base into
  // ID line 5.
  std::string id_lines[5];
  for (int r = 1; r <= 5; ++r) id_lines[r - 1] = std::string(NextRecord(d, r));
  const int id5_line = lines_.line();
  d.name = Label(id_lines[0]);

  // Record 6, format 2(I5,I10),2(1X,10A1,I10,I4): function type, ..., response entity, node,
  // direction.
  const std::string_view r6 = NextRecord(d, 6);
  long long function_type = 0, node = 0, direction = 0;
  if (!ParseInteger(Column(r6, 0, 5), -1000000, 1000000, &function_type)) {
    throw RecordError(d, 6, fmt::format("no function type in '{}'", TrimText(r6)),
                      "format 2(I5,I10),2(1X,10A1,I10,I4) starting with the function type");
  }
  if (function_type != kTimeResponse) {
    throw RecordError(d, 6, fmt::format("function type {} (not a time response)", function_type),
                      "function type 1 (time response); spectra and FRFs are not records");
  }
  const std::string entity = Label(Column(r6, 30, 11));
  if (!ParseInteger(Column(r6, 41, 10), -2000000000, 2000000000, &node)) node = 0;
  if (!ParseInteger(Column(r6, 51, 4), -6, 6, &direction)) direction = 0;
  if (d.name.empty()) {
    d.name =
        fmt::format("{}{}{}{}", entity, entity.empty() ? "" : ":", node, DirectionText(direction));
  }

  // Record 7, format 3I10,3E13.5 (read as blank-separated fields, so that wider numbers from
  // other writers read too): ordinate type, count, spacing, abscissa minimum and increment.
  const std::string_view r7 = NextRecord(d, 7);
  const std::vector<std::string_view> f7 = SplitWhitespace(r7);
  long long ordinate_type = 0, count = 0, spacing = 0;
  if (f7.size() < 5 || !ParseInteger(f7[0], -1000000, 1000000, &ordinate_type) ||
      !ParseInteger(f7[1], -4000000000LL, 4000000000LL, &count) ||
      !ParseInteger(f7[2], -1000000, 1000000, &spacing) || !ParseNumber(f7[3], &d.start) ||
      !ParseNumber(f7[4], &d.interval)) {
    throw RecordError(d, 7, fmt::format("'{}' is not a data form record", TrimText(r7)),
                      "ordinate type, number of values, spacing, abscissa minimum and "
                      "increment (3I10,3E13.5)");
  }
  if (ordinate_type == kComplexSingle || ordinate_type == kComplexDouble) {
    throw RecordError(d, 7, fmt::format("complex ordinates (type {})", ordinate_type),
                      "real ordinates: type 2 (single) or 4 (double precision)");
  }
  if (ordinate_type != kRealSingle && ordinate_type != kRealDouble) {
    throw RecordError(d, 7, fmt::format("unknown ordinate data type {}", ordinate_type),
                      "2 (real single) or 4 (real double precision)");
  }
  if (count < 2 || count > kMaxSamples) {
    throw RecordError(d, 7, fmt::format("{} data values", count),
                      fmt::format("2 to {} values", kMaxSamples));
  }
  if (spacing != 0 && spacing != 1) {
    throw RecordError(d, 7, fmt::format("abscissa spacing {}", spacing), "1 (even) or 0 (uneven)");
  }
  d.even = spacing == 1;
  if (d.even && !(std::isfinite(d.start) && std::isfinite(d.interval) && d.interval > 0)) {
    throw RecordError(d, 7,
                      fmt::format("abscissa minimum {} and increment {}", d.start, d.interval),
                      "a finite minimum and a positive finite increment");
  }

  // Record 8 (abscissa) and 9 (ordinate), format I10,3I5,2(1X,20A1): specific data type,
  // unit exponents, axis label, units label.
  const std::string_view r8 = NextRecord(d, 8);
  long long abscissa_type = 0;
  if (!ParseInteger(Column(r8, 0, 10), -1000000, 1000000, &abscissa_type)) {
    throw RecordError(d, 8, fmt::format("no data type in '{}'", TrimText(r8)),
                      "abscissa data characteristics (I10,3I5,2(1X,20A1))");
  }
  if (abscissa_type != kSpecTime && abscissa_type != 0) {
    throw RecordError(d, 8, fmt::format("abscissa data type {} (not time)", abscissa_type),
                      "17 (time) or 0 (unknown)");
  }
  d.time_unit = Label(Column(r8, 46, 21));
  if (d.time_unit.empty()) d.time_unit = "s";  // every UFF unit system measures time in s
  const std::string_view r9 = NextRecord(d, 9);
  d.unit = Label(Column(r9, 46, 21));
  // An acceleration (specific data type 12) in "g" is standard gravity in UFF's usage (test
  // systems write it so), not the gram the unit library reads.
  long long ordinate_data = 0;
  if ((d.unit == "g" || d.unit == "G") &&
      ParseInteger(Column(r9, 0, 10), -1000000, 1000000, &ordinate_data) &&
      ordinate_data == kSpecAcceleration) {
    d.unit = "gn";
  }
  NextRecord(d, 10);
  NextRecord(d, 11);

  if (TrimView(id_lines[4]).substr(0, std::strlen(kMbidTimeTag)) == kMbidTimeTag) {
    ReadMbidTimeTag(id_lines[4], id5_line, &d);
  }

  const size_t per_sample = d.even ? 1 : 2;
  const size_t value_count = static_cast<size_t>(count) * per_sample;
  std::vector<double> numbers;
  if (d.binary) {
    const size_t width = ordinate_type == kRealSingle ? 4 : 8;
    if (static_cast<size_t>(byte_count) != value_count * width) {
      throw InputError(
          path_, fmt::format("{}, header", d.where),
          fmt::format("{} bytes of data for {} values of {} bytes", byte_count, value_count, width),
          fmt::format("{} bytes", value_count * width));
    }
    // The header's count was checked against the file before records 1-11; they took some.
    if (static_cast<size_t>(byte_count) > lines_.remaining()) {
      throw InputError(path_, fmt::format("{}, header", d.where),
                       fmt::format("byte count {} with {} bytes left after the ASCII records",
                                   byte_count, lines_.remaining()),
                       "the number of bytes of binary data, within the file");
    }
    numbers = DecodeBinary(lines_.Bytes(static_cast<size_t>(byte_count)), width, big_endian);
    ExpectClosing(d, /*binary=*/true);
  } else {
    numbers = ReadAsciiValues(d, value_count, ordinate_type == kRealSingle);
  }
  if (d.even) {
    d.values = std::move(numbers);
  } else {
    d.abscissa.resize(static_cast<size_t>(count));
    d.values.resize(static_cast<size_t>(count));
    double largest = 0;
    for (size_t j = 0; j < static_cast<size_t>(count); ++j) {
      d.abscissa[j] = numbers[2 * j];
      d.values[j] = numbers[2 * j + 1];
      largest = std::max(largest, std::abs(d.abscissa[j]));
    }
    // Abscissae print as E13.5 (six digits) or are stored as floats or doubles.
    const double digits = d.binary ? (ordinate_type == kRealSingle ? 0x1p-23 : 0x1p-52) : 1e-5;
    d.abscissa_resolution = largest > 0 ? largest * digits : 0.0;
  }
  datasets_.push_back(std::move(d));
}

void Uff58Reader::ReadMbidTimeTag(const std::string& line, int line_number, Dataset* d) {
  // "mbid sample_interval_s <tau> start_time_s <t0>", the shortest round-trip texts.
  const std::vector<std::string_view> f = SplitWhitespace(line);
  double tau = 0, t0 = 0;
  if (f.size() != 5 || f[3] != "start_time_s" || !ParseNumber(f[2], &tau) ||
      !ParseNumber(f[4], &t0) || !d->even) {
    throw InputError(path_, fmt::format("{}, record 5 (line {})", d->where, line_number),
                     fmt::format("'{}' is not mbid's time line", TrimText(line)),
                     "'mbid sample_interval_s <s> start_time_s <s>' with even abscissa spacing");
  }
  // Record 7 prints six digits: half a unit in the sixth is 5e-6 of the value at most.
  if (!(std::abs(tau - d->interval) <= 5e-6 * std::abs(tau)) ||
      !(std::abs(t0 - d->start) <= 5e-6 * std::max(std::abs(t0), tau))) {
    throw InputError(path_, fmt::format("{}, record 5 (line {})", d->where, line_number),
                     fmt::format("interval {} s and start {} s disagree with record 7 ({}, {})",
                                 tau, t0, d->interval, d->start),
                     "the abscissa increment and minimum of record 7");
  }
  d->exact_interval = tau;
  d->exact_start = t0;
}

// One column per dataset, on the time base of the first; every dataset must share it.
RawTable Uff58Reader::Combine() {
  const Dataset& first = datasets_.front();
  RawTable table;
  table.format = first.binary ? "uff58b" : "uff58";
  table.time_unit = first.time_unit;
  table.time_where = fmt::format("{}, record 7", first.where);
  for (const Dataset& d : datasets_) {
    if (d.binary != first.binary) table.format = "uff58";  // mixed: say the ASCII name
    const auto mismatch = [&](const std::string& what, const std::string& expected) {
      return InputError(path_, fmt::format("{}, record 7", d.where), what, expected);
    };
    if (d.values.size() != first.values.size()) {
      throw mismatch(fmt::format("{} values where {} has {}", d.values.size(), first.where,
                                 first.values.size()),
                     "the same number of samples in every dataset");
    }
    if (d.time_unit != first.time_unit) {
      throw InputError(path_, fmt::format("{}, record 8", d.where),
                       fmt::format("time unit '{}' where {} has '{}'", d.time_unit, first.where,
                                   first.time_unit),
                       "one time unit for all datasets");
    }
    if (d.even != first.even) {
      throw mismatch("even and uneven abscissa spacing mixed",
                     "the same abscissa in every dataset");
    }
    if (d.even) {
      // Records print six digits (E13.5): the same interval prints alike within 5e-6.
      const double tolerance = 5e-6 * first.interval;
      if (!(std::abs(d.interval - first.interval) <= tolerance)) {
        throw mismatch(fmt::format("abscissa increment {} where {} has {}", d.interval, first.where,
                                   first.interval),
                       "one sample interval for all channels");
      }
      if (!(std::abs(d.start - first.start) <= std::max(tolerance, 5e-6 * std::abs(first.start)))) {
        throw mismatch(
            fmt::format("abscissa minimum {} where {} has {}", d.start, first.where, first.start),
            "one start time for all channels");
      }
    } else {
      for (size_t j = 0; j < d.abscissa.size(); ++j) {
        const double tolerance = std::max(d.abscissa_resolution, first.abscissa_resolution);
        if (!(std::abs(d.abscissa[j] - first.abscissa[j]) <= tolerance)) {
          throw mismatch(fmt::format("abscissa {} of sample {} where {} has {}", d.abscissa[j], j,
                                     first.where, first.abscissa[j]),
                         "the same sample times in every dataset");
        }
      }
    }
    RawColumn column;
    column.name = d.name;
    column.unit = d.unit;
    column.where = d.where;
    column.values = d.values;
    table.columns.push_back(std::move(column));
  }
  if (first.even) {
    table.start = first.exact_start.value_or(first.start);
    table.interval = first.exact_interval.value_or(first.interval);
    for (const Dataset& d : datasets_) {
      if (!d.exact_interval) {  // a dataset without mbid's exact values: record 7's only
        table.start = first.start;
        table.interval = first.interval;
        // Record 7 prints the increment as E13.5: six significant digits.
        table.interval_resolution =
            first.interval > 0 ? std::pow(10.0, std::floor(std::log10(first.interval)) - 5) : 0.0;
      }
    }
  } else {
    table.time = first.abscissa;
    table.printed_resolution = first.abscissa_resolution;
  }
  return table;
}

RawTable ReadUff58(const std::string& path) {
  const std::string bytes = ReadWholeFile(path, kUff58File);
  return Uff58Reader(path, bytes).Read();
}

}  // namespace mbid::records::internal
