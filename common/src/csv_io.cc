#include "mbid/common/csv_io.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>

#include "internal.h"
#include "mbid/common/atomic_file.h"
#include "mbid/common/error.h"
#include "mbid/common/utf8.h"

namespace mbid {
namespace {

constexpr char kExpectedFile[] = "a CSV measurement file (docs/interfaces)";

// The decimal place of a number's last printed digit, as a power of ten: "0.0123" -> -4,
// "1.5e-3" -> -4, "12" -> 0. A time printed with few digits is uniform only to 10^place.
int PrintedPlace(const std::string& text) {
  const size_t exponent_at = std::min(text.find_first_of("eE"), text.size());
  const int exponent = exponent_at < text.size() ? std::atoi(text.c_str() + exponent_at + 1) : 0;
  const size_t point = text.find('.');
  const int decimals = point < exponent_at ? static_cast<int>(exponent_at - point - 1) : 0;
  return exponent - decimals;
}

std::vector<std::string> SplitFields(const std::string& line) {
  std::vector<std::string> fields;
  size_t start = 0;
  while (true) {
    const size_t comma = line.find(',', start);
    fields.push_back(internal::Trim(line.substr(start, comma - start)));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return fields;
}

std::string Unquote(const std::string& name) {
  if (name.size() >= 2 && name.front() == '"' && name.back() == '"') {
    return name.substr(1, name.size() - 2);
  }
  return name;
}

std::string LineField(int line) { return fmt::format("line {}", line); }

// Optional metadata in comments, written by WriteMeasurementCsv so that a round trip is exact:
// "# source: ...", "# sample_interval_s: ...", "# units: rad,rad".
struct CsvMetadata {
  std::string source;
  std::string sample_interval_text;
  int sample_interval_line = 0;
  std::vector<std::string> units;
  int units_line = 0;
};

void ParseMetadataComment(const std::string& comment, int line, CsvMetadata* metadata) {
  const std::string body = internal::Trim(comment.substr(comment.find('#') + 1));
  const auto value_of = [&body](const std::string& key) -> std::optional<std::string> {
    if (body.compare(0, key.size() + 1, key + ":") != 0) return std::nullopt;
    return internal::Trim(body.substr(key.size() + 1));
  };
  if (auto source = value_of("source")) {
    metadata->source = *source;
  } else if (auto interval = value_of("sample_interval_s")) {
    metadata->sample_interval_text = *interval;
    metadata->sample_interval_line = line;
  } else if (auto units = value_of("units")) {
    metadata->units = SplitFields(*units);
    metadata->units_line = line;
  }
}

}  // namespace

Measurement ReadMeasurementCsv(const std::string& path) {
  const std::string text = internal::ReadTextFile(path, kExpectedFile);
  ValidateUtf8Text(text, path);
  std::istringstream stream(text);
  std::string line;
  int line_number = 0;

  CsvMetadata metadata;
  std::vector<std::string> header;
  int header_line = 0;
  std::vector<int> row_lines;
  // The finest decimal place any time prints: writers drop trailing zeros ("0.02" beside
  // "0.025").
  int time_place = std::numeric_limits<int>::max();
  std::vector<double> cells;  // row-major, header.size() per row

  while (std::getline(stream, line)) {
    ++line_number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const std::string trimmed = internal::Trim(line);
    if (trimmed.empty()) continue;
    if (trimmed.front() == '#') {
      ParseMetadataComment(trimmed, line_number, &metadata);
      continue;
    }
    if (header.empty()) {
      header_line = line_number;
      for (const auto& field : SplitFields(trimmed)) header.push_back(Unquote(field));
      if (header.front() != "time") {
        throw InputError(path, LineField(line_number),
                         "the first column is '" + header.front() + "', not 'time'",
                         "a header 'time,<channel>,...' with time in seconds first");
      }
      if (header.size() < 2) {
        throw InputError(path, LineField(line_number), "the header has no channel columns",
                         "a header 'time,<channel>,...'");
      }
      std::set<std::string> seen;
      for (size_t c = 0; c < header.size(); ++c) {
        if (header[c].empty()) {
          throw InputError(path, fmt::format("line {}, column {}", line_number, c + 1),
                           "empty column name", "a channel name");
        }
        if (!seen.insert(header[c]).second) {
          throw InputError(path, fmt::format("line {}, column {}", line_number, c + 1),
                           "column name '" + header[c] + "' appears twice", "unique channel names");
        }
      }
      continue;
    }
    const std::vector<std::string> fields = SplitFields(trimmed);
    if (fields.size() != header.size()) {
      throw InputError(path, LineField(line_number), fmt::format("{} fields", fields.size()),
                       fmt::format("{} fields as in the header ({})", header.size(),
                                   internal::Join(header, ",")));
    }
    time_place = std::min(time_place, PrintedPlace(fields[0]));
    for (size_t c = 0; c < fields.size(); ++c) {
      double value = 0;
      const auto status = internal::ParseDouble(fields[c], &value);
      const std::string where =
          fmt::format("line {}, column {} ({})", line_number, c + 1, header[c]);
      if (status != internal::ParseStatus::kOk) {
        throw InputError(path, where, "'" + fields[c] + "' is not a number",
                         "a decimal number in SI units");
      }
      if (!std::isfinite(value)) {
        throw InputError(path, where, "'" + fields[c] + "' is not finite", "a finite number");
      }
      cells.push_back(value);
    }
    row_lines.push_back(line_number);
  }

  if (header.empty()) {
    throw InputError(path, "", "no header line", "a header 'time,<channel>,...' and data rows");
  }
  const Eigen::Index rows = static_cast<Eigen::Index>(row_lines.size());
  if (rows < 2) {
    throw InputError(path, LineField(header_line),
                     fmt::format("{} data rows after the header", rows), "at least 2 samples");
  }
  const Eigen::Index columns = static_cast<Eigen::Index>(header.size());
  const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>
      table(cells.data(), rows, columns);

  Measurement m;
  m.channels.assign(header.begin() + 1, header.end());
  m.units.assign(m.channels.size(), "rad");
  if (metadata.units_line > 0) {
    std::vector<std::string> units = metadata.units;
    // "# units: s,rad,rad" may include the time column.
    if (units.size() == header.size() && units.front() == "s") units.erase(units.begin());
    if (units.size() != m.channels.size()) {
      throw InputError(
          path, LineField(metadata.units_line),
          fmt::format("'# units:' lists {} units for {} channels", units.size(), m.channels.size()),
          "one unit per channel, in header order");
    }
    m.units = units;
  }
  if (!metadata.source.empty()) m.source = metadata.source;

  const Eigen::VectorXd time = table.col(0);
  double start_s = time[0];
  const double tau = CheckUniformTime(
      time, path,
      [&row_lines](Eigen::Index j) { return LineField(row_lines[static_cast<size_t>(j)]); },
      std::pow(10.0, time_place), &start_s);
  m.start_time_s = start_s;
  m.sample_interval_s = tau;
  if (metadata.sample_interval_line > 0) {
    // The exact interval, when it agrees with the time column, makes the round trip exact.
    double exact = 0;
    if (internal::ParseDouble(metadata.sample_interval_text, &exact) !=
            internal::ParseStatus::kOk ||
        !(std::abs(exact - tau) < kTimeUniformityTolerance * tau)) {
      throw InputError(path, LineField(metadata.sample_interval_line),
                       fmt::format("'# sample_interval_s: {}' disagrees with the time column "
                                   "(step {} s)",
                                   metadata.sample_interval_text, tau),
                       "the step of the time column");
    }
    m.sample_interval_s = exact;
  }
  m.values = table.rightCols(columns - 1);
  m.Validate(path);
  return m;
}

void WriteMeasurementCsv(const Measurement& measurement, const std::string& path) {
  measurement.Validate(path);
  AtomicFile file(path);
  std::FILE* out = std::fopen(file.temp_path().c_str(), "wb");
  if (out == nullptr) throw std::runtime_error("cannot create " + file.temp_path());
  std::string text;
  text += "# mbid measurement: time in seconds, values in SI units (angles in radians)\n";
  text += "# source: " + measurement.source + "\n";
  // Shortest representation that parses back to the same double (exact round trip).
  text += fmt::format("# sample_interval_s: {}\n", measurement.sample_interval_s);
  text += "# units: " + internal::Join(measurement.units, ",") + "\n";
  text += "time," + internal::Join(measurement.channels, ",") + "\n";
  const Eigen::VectorXd time = measurement.CalcTime();
  bool ok = true;
  for (Eigen::Index j = 0; j < measurement.samples() && ok; ++j) {
    text += fmt::format("{}", time[j]);
    for (Eigen::Index c = 0; c < measurement.channel_count(); ++c) {
      text += fmt::format(",{}", measurement.values(j, c));
    }
    text += '\n';
    if (text.size() > (1 << 20)) {
      ok = std::fwrite(text.data(), 1, text.size(), out) == text.size();
      text.clear();
    }
  }
  ok = ok && std::fwrite(text.data(), 1, text.size(), out) == text.size();
  ok = (std::fclose(out) == 0) && ok;
  if (!ok) throw std::runtime_error("cannot write " + file.temp_path());
  file.Commit();
}

}  // namespace mbid
