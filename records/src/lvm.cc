// LabVIEW Measurement files (.lvm, "Write To Measurement File"): the text layout with a file
// header, segment headers and tab- or comma-separated columns (docs/records-formats.md).

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "mbid/common/error.h"
#include "mbid/common/utf8.h"
#include "raw_table.h"
#include "text_util.h"

namespace mbid::records::internal {
namespace {

constexpr char kLvmFile[] = "a LabVIEW measurement file (.lvm, docs/records-formats.md)";
constexpr char kEndOfHeader[] = "***End_of_Header***";

enum class XColumns { kOne, kMulti, kNone };

// The decimal place of a number's last printed digit, as a power of ten: "0.0123" -> -4,
// "1.5E-3" -> -4, "12" -> 0.
int PrintedPlace(std::string_view text) {
  const size_t exponent_at = std::min(text.find_first_of("eE"), text.size());
  const int exponent =
      exponent_at < text.size() ? std::atoi(std::string(text.substr(exponent_at + 1)).c_str()) : 0;
  const size_t point = text.find('.');
  const int decimals = point < exponent_at ? static_cast<int>(exponent_at - point - 1) : 0;
  return exponent - decimals;
}

struct Line {
  int number = 0;
  std::string text;
};

struct Segment {
  int header_line = 0;  // 0: no segment header
  std::map<std::string, std::vector<std::string>> keys;
  std::map<std::string, int> key_lines;
  std::vector<std::string> names;  // from the column-name row, channel columns only
  int names_line = 0;
  std::vector<double> time;               // X column (One / Multi)
  std::vector<std::vector<double>> data;  // [channel][row]
  std::vector<int> rows;                  // line of each row
};

class LvmReader {
 public:
  LvmReader(const std::string& path, const std::string& text) : path_(path) {
    size_t at = 0;
    int number = 0;
    while (at < text.size()) {
      const size_t end = std::min(text.find('\n', at), text.size());
      std::string line = text.substr(at, end - at);
      if (!line.empty() && line.back() == '\r') line.pop_back();
      lines_.push_back({++number, std::move(line)});
      at = end + 1;
    }
  }

  RawTable Read() {
    if (lines_.empty() || TrimView(SplitFirst(lines_[0].text)) != "LabVIEW Measurement") {
      throw InputError(path_, LineField(1), "the first line is not 'LabVIEW Measurement'",
                       kLvmFile);
    }
    ReadFileHeader();
    std::vector<Segment> segments;
    while (true) {
      SkipBlank();
      if (at_ >= lines_.size()) break;
      segments.push_back(ReadSegment(segments.size()));
    }
    if (segments.empty()) {
      throw InputError(path_, LineField(lines_.back().number), "no data after the header",
                       "a segment of samples after ***End_of_Header***");
    }
    return Combine(segments);
  }

 private:
  // The key of a header line: its text up to the first tab or comma (before the separator is
  // known: LabVIEW writes keys with the file's own separator).
  static std::string_view SplitFirst(std::string_view text) {
    return text.substr(0, std::min(text.find_first_of("\t,"), text.size()));
  }

  std::vector<std::string> Fields(const std::string& text) const {
    std::vector<std::string> fields;
    size_t start = 0;
    while (true) {
      const size_t end = text.find(separator_, start);
      fields.push_back(TrimText(std::string_view(text).substr(start, end - start)));
      if (end == std::string::npos) break;
      start = end + 1;
    }
    while (!fields.empty() && fields.back().empty()) fields.pop_back();  // trailing separators
    return fields;
  }

  bool IsEndOfHeader(const std::string& text) const {
    return TrimText(SplitFirst(text)) == kEndOfHeader;
  }

  void SkipBlank() {
    while (at_ < lines_.size() && TrimView(lines_[at_].text).empty()) ++at_;
  }

  // A number cell: "" is a gap (NaN); nullopt for text that is not a number.
  std::optional<double> Cell(std::string cell) const {
    if (cell.empty()) return std::numeric_limits<double>::quiet_NaN();
    if (decimal_comma_) std::replace(cell.begin(), cell.end(), ',', '.');
    double value = 0;
    if (!ParseNumber(cell, &value)) return std::nullopt;
    return value;
  }

  void ReadFileHeader() {
    size_t end = 1;
    while (end < lines_.size() && !IsEndOfHeader(lines_[end].text)) ++end;
    if (end >= lines_.size()) {
      throw InputError(path_, LineField(1), "no ***End_of_Header*** after 'LabVIEW Measurement'",
                       "a file header closed by ***End_of_Header***");
    }
    std::string separator, decimal = ".", x_columns = "One";
    int separator_line = 0, decimal_line = 0, x_line = 0;
    for (size_t i = 1; i < end; ++i) {
      const std::string& text = lines_[i].text;
      const std::string_view key = TrimView(SplitFirst(text));
      const size_t cut = std::min(text.find_first_of("\t,"), text.size());
      // The value: the field after the key (a comma value is itself a field when the separator
      // is a tab, e.g. "Decimal_Separator\t,").
      std::string value;
      if (cut < text.size()) {
        const std::string rest = text.substr(cut + 1);
        value = TrimText(std::string_view(rest).substr(0, std::min(rest.find('\t'), rest.size())));
      }
      if (key == "Separator") {
        separator = value;
        separator_line = lines_[i].number;
      } else if (key == "Decimal_Separator") {
        decimal = value.empty() && cut < text.size() && text[cut] == ',' ? "," : value;
        decimal_line = lines_[i].number;
      } else if (key == "X_Columns") {
        x_columns = value;
        x_line = lines_[i].number;
      }
    }
    if (separator == "Tab" || separator.empty()) {
      separator_ = '\t';  // LabVIEW's default; files without the key use it
    } else if (separator == "Comma") {
      separator_ = ',';
    } else {
      throw InputError(path_, LineField(separator_line), fmt::format("separator '{}'", separator),
                       "Separator Tab or Comma");
    }
    if (decimal == ",") {
      if (separator_ == ',') {
        throw InputError(path_, LineField(decimal_line),
                         "decimal comma with comma-separated columns",
                         "Decimal_Separator ',' only with Separator Tab");
      }
      decimal_comma_ = true;
    } else if (decimal != ".") {
      throw InputError(path_, LineField(decimal_line),
                       fmt::format("decimal separator '{}'", decimal),
                       "Decimal_Separator '.' or ','");
    }
    if (x_columns == "One") {
      x_columns_ = XColumns::kOne;
    } else if (x_columns == "Multi") {
      x_columns_ = XColumns::kMulti;
    } else if (x_columns == "No") {
      x_columns_ = XColumns::kNone;
    } else {
      throw InputError(path_, LineField(x_line), fmt::format("X_Columns '{}'", x_columns),
                       "X_Columns One, Multi or No");
    }
    at_ = end + 1;
  }

  // Does a segment header (closed by ***End_of_Header***) start here, before any data row?
  bool HeaderFollows() const {
    for (size_t i = at_; i < lines_.size(); ++i) {
      if (IsEndOfHeader(lines_[i].text)) return true;
      const std::vector<std::string> fields = Fields(lines_[i].text);
      if (!fields.empty() && !fields[0].empty() && Cell(fields[0])) return false;  // data
    }
    return false;
  }

  Segment ReadSegment(size_t index) {
    Segment s;
    if (HeaderFollows()) {
      s.header_line = lines_[at_].number;
      for (; !IsEndOfHeader(lines_[at_].text); ++at_) {
        std::vector<std::string> fields = Fields(lines_[at_].text);
        if (fields.empty()) continue;
        const std::string key = fields[0];
        fields.erase(fields.begin());
        s.keys[key] = std::move(fields);
        s.key_lines[key] = lines_[at_].number;
      }
      ++at_;
      SkipBlank();
    } else if (index > 0) {
      throw InputError(
          path_, LineField(lines_[at_].number),
          fmt::format("'{}' is neither data nor a segment header", lines_[at_].text.substr(0, 40)),
          "a segment header closed by ***End_of_Header***");
    }
    const int declared_channels = DeclaredChannels(s);

    // The column-name row: "X_Value<sep>name<sep>...<sep>Comment".
    if (at_ < lines_.size()) {
      std::vector<std::string> fields = Fields(lines_[at_].text);
      if (!fields.empty() && !fields[0].empty() && !Cell(fields[0])) {
        s.names_line = lines_[at_].number;
        if (!fields.empty() && fields.back() == "Comment") fields.pop_back();
        for (size_t k = 0; k < fields.size(); ++k) {
          const bool x_column = (x_columns_ == XColumns::kOne && k == 0) ||
                                (x_columns_ == XColumns::kMulti && k % 2 == 0);
          if (!x_column) s.names.push_back(fields[k]);
        }
        ++at_;
      }
    }
    int channels = declared_channels;
    if (channels == 0) channels = static_cast<int>(s.names.size());
    if (channels == 0 && at_ < lines_.size()) {
      // Neither Channels nor names: the first data row tells.
      const int fields = static_cast<int>(Fields(lines_[at_].text).size());
      channels = x_columns_ == XColumns::kOne     ? fields - 1
                 : x_columns_ == XColumns::kMulti ? fields / 2
                                                  : fields;
    }
    if (channels < 1) {
      throw InputError(path_, LineField(at_ < lines_.size() ? lines_[at_].number : 0),
                       "no channel columns", "at least one channel after the X column");
    }
    if (!s.names.empty() && static_cast<int>(s.names.size()) != channels) {
      throw InputError(path_, LineField(s.names_line),
                       fmt::format("{} channel names for {} channels", s.names.size(), channels),
                       "one name per channel (Channels in the segment header)");
    }
    const int x_count = x_columns_ == XColumns::kOne     ? 1
                        : x_columns_ == XColumns::kMulti ? channels
                                                         : 0;
    const size_t width = static_cast<size_t>(channels + x_count);
    s.data.resize(static_cast<size_t>(channels));
    for (; at_ < lines_.size(); ++at_) {
      const Line& line = lines_[at_];
      if (TrimView(line.text).empty()) continue;
      std::vector<std::string> fields = Fields(line.text);
      if (fields.empty()) continue;                       // only separators
      if (!fields[0].empty() && !Cell(fields[0])) break;  // the next segment's header
      if (fields.size() > width + 1) {
        throw InputError(path_, LineField(line.number), fmt::format("{} fields", fields.size()),
                         fmt::format("{} columns (and a comment)", width));
      }
      fields.resize(width);  // the comment goes; missing cells are gaps
      std::vector<double> row(width);
      for (size_t k = 0; k < width; ++k) {
        const std::optional<double> value = Cell(fields[k]);
        if (!value) {
          throw InputError(
              path_, fmt::format("line {}, column {}", line.number, k + 1),
              fmt::format("'{}' is not a number", fields[k]),
              decimal_comma_ ? "a number with a decimal comma" : "a number with a decimal point");
        }
        row[k] = *value;
      }
      if (x_columns_ == XColumns::kOne) {
        s.time.push_back(row[0]);
        UpdatePlace(fields[0]);
        for (int c = 0; c < channels; ++c) s.data[c].push_back(row[static_cast<size_t>(c) + 1]);
      } else if (x_columns_ == XColumns::kMulti) {
        s.time.push_back(row[0]);
        UpdatePlace(fields[0]);
        for (int c = 0; c < channels; ++c) {
          const double x = row[2 * static_cast<size_t>(c)];
          if (!(std::isnan(x) && std::isnan(row[0])) && x != row[0]) {
            throw InputError(path_, fmt::format("line {}, column {}", line.number, 2 * c + 1),
                             fmt::format("X value {} where the first X column has {}", x, row[0]),
                             "all channels sampled at the same times");
          }
          s.data[c].push_back(row[2 * static_cast<size_t>(c) + 1]);
        }
      } else {
        for (int c = 0; c < channels; ++c) s.data[c].push_back(row[static_cast<size_t>(c)]);
      }
      s.rows.push_back(line.number);
    }
    if (s.rows.empty()) {
      throw InputError(path_, LineField(s.header_line > 0 ? s.header_line : lines_.back().number),
                       "a segment without samples", "rows of samples after the header");
    }
    CheckDeclaredSamples(s);
    return s;
  }

  // A number's text with a decimal point where the file writes a decimal comma.
  std::string WithDecimalPoint(std::string text) const {
    if (decimal_comma_) std::replace(text.begin(), text.end(), ',', '.');
    return text;
  }

  // The coarsest last digit of the X column's texts (a writer that drops trailing zeros prints
  // "0.02" beside "0.025"; zero itself says nothing).
  void UpdatePlace(const std::string& text) {
    const std::string copy = WithDecimalPoint(text);
    double value = 0;
    if (!ParseNumber(copy, &value) || value == 0.0) return;
    time_place_ = std::max(time_place_, PrintedPlace(copy));
  }

  int DeclaredChannels(const Segment& s) const {
    const auto it = s.keys.find("Channels");
    if (it == s.keys.end()) return 0;
    long long channels = 0;
    if (it->second.empty() || !ParseInteger(it->second[0], 1, 100000, &channels)) {
      throw InputError(path_, LineField(s.key_lines.at("Channels")),
                       "'Channels' is not a channel count", "Channels <1 to 100000>");
    }
    return static_cast<int>(channels);
  }

  // Samples (per channel) in the segment header, when present, must match the rows: a file cut
  // short shows here.
  void CheckDeclaredSamples(const Segment& s) const {
    const auto it = s.keys.find("Samples");
    if (it == s.keys.end()) return;
    long long most = 0;
    for (const std::string& field : it->second) {
      long long n = 0;
      if (field.empty()) continue;
      if (!ParseInteger(field, 0, kMaxSamples, &n)) {
        throw InputError(path_, LineField(s.key_lines.at("Samples")),
                         fmt::format("'{}' is not a sample count", field), "Samples <count> ...");
      }
      most = std::max(most, n);
    }
    if (most != static_cast<long long>(s.rows.size())) {
      throw InputError(path_, LineField(s.key_lines.at("Samples")),
                       fmt::format("{} samples declared, {} rows follow", most, s.rows.size()),
                       "as many rows as Samples declares");
    }
  }

  // Per-channel header value `key` of channel c (LabVIEW repeats it per channel), or "".
  static std::string KeyValue(const Segment& s, const std::string& key, size_t c) {
    const auto it = s.keys.find(key);
    if (it == s.keys.end() || it->second.empty()) return {};
    return c < it->second.size() ? it->second[c] : it->second.back();
  }

  double GridNumber(const Segment& s, const std::string& key, size_t c) const {
    const std::string text = KeyValue(s, key, c);
    const std::optional<double> value = Cell(text);
    if (text.empty() || !value || !std::isfinite(*value)) {
      throw InputError(
          path_, s.key_lines.count(key) ? LineField(s.key_lines.at(key)) : LineField(s.header_line),
          text.empty() ? fmt::format("no {} for channel {}", key, c + 1)
                       : fmt::format("{} '{}' is not a number", key, text),
          "X0 and Delta_X per channel when the file has no X column");
    }
    return *value;
  }

  RawTable Combine(std::vector<Segment>& segments) {
    Segment& first = segments.front();
    const size_t channels = first.data.size();
    RawTable table;
    table.format = "lvm";
    table.time_unit = "s";
    const std::string x_unit = KeyValue(first, "X_Unit_Label", 0);
    if (!x_unit.empty()) table.time_unit = x_unit;
    table.time_unit_assumed = x_unit.empty();
    const std::string x_dimension = KeyValue(first, "X_Dimension", 0);
    if (!x_dimension.empty() && x_dimension != "Time") {
      throw InputError(path_, LineField(first.key_lines["X_Dimension"]),
                       fmt::format("X_Dimension '{}'", x_dimension), "X_Dimension Time");
    }
    for (size_t c = 0; c < channels; ++c) {
      RawColumn column;
      column.name = first.names.empty() ? fmt::format("channel {}", c + 1) : first.names[c];
      column.unit = KeyValue(first, "Y_Unit_Label", c);
      // LabVIEW and DAQmx label an accelerometer's channel "g": standard gravity, as in UFF58,
      // not the gram the unit library reads (the format's own example was refused).
      if (column.unit == "g") column.unit = "gn";
      column.where = fmt::format("channel {}", c + 1);  // import.cc adds the name
      table.columns.push_back(std::move(column));
    }
    if (x_columns_ == XColumns::kNone) {
      table.start = GridNumber(first, "X0", 0);
      table.interval = GridNumber(first, "Delta_X", 0);
      table.interval_resolution =
          std::pow(10.0, PrintedPlace(WithDecimalPoint(KeyValue(first, "Delta_X", 0))));
      table.time_where = LineField(first.key_lines.count("Delta_X") ? first.key_lines["Delta_X"]
                                                                    : first.header_line);
      if (!(table.interval > 0)) {
        throw InputError(path_, table.time_where, fmt::format("Delta_X {}", table.interval),
                         "a positive Delta_X");
      }
      for (size_t c = 1; c < channels; ++c) {
        if (GridNumber(first, "X0", c) != table.start ||
            GridNumber(first, "Delta_X", c) != table.interval) {
          throw InputError(
              path_, table.time_where,
              fmt::format("channel {} has X0 {} and Delta_X {}, channel 1 {} and {}", c + 1,
                          GridNumber(first, "X0", c), GridNumber(first, "Delta_X", c), table.start,
                          table.interval),
              "one time grid for all channels");
        }
      }
    } else {
      table.time_where = "X_Value column";
      table.printed_resolution = std::pow(10.0, time_place_);
    }

    // Later segments continue the first: same channels, names and units, and (without X columns)
    // X0 where the previous segment ended.
    size_t samples = first.rows.size();
    for (size_t k = 1; k < segments.size(); ++k) {
      const Segment& s = segments[k];
      const std::string where = LineField(s.header_line);
      if (s.data.size() != channels ||
          (!s.names.empty() && !first.names.empty() && s.names != first.names)) {
        throw InputError(path_, where, fmt::format("segment {} has other channels", k + 1),
                         "segments with the channels of the first (they are concatenated)");
      }
      for (size_t c = 0; c < channels; ++c) {
        const std::string unit = KeyValue(s, "Y_Unit_Label", c);
        if (!unit.empty() && unit != table.columns[c].unit) {
          throw InputError(
              path_, where,
              fmt::format("segment {} has unit '{}' for {}", k + 1, unit, table.columns[c].name),
              fmt::format("the unit of the first segment, '{}'", table.columns[c].unit));
        }
      }
      if (x_columns_ == XColumns::kNone) {
        const double x0 = GridNumber(s, "X0", 0);
        const double dx = GridNumber(s, "Delta_X", 0);
        const double expected = table.start + static_cast<double>(samples) * table.interval;
        if (!(std::abs(dx - table.interval) <= 1e-9 * table.interval) ||
            !(std::abs(x0 - expected) <= 1e-6 * table.interval + 1e-12 * std::abs(expected))) {
          throw InputError(path_, where,
                           fmt::format("segment {} starts at X0 {} with Delta_X {}", k + 1, x0, dx),
                           fmt::format("X0 {} and Delta_X {}, continuing the previous segment",
                                       expected, table.interval));
        }
      }
      samples += s.rows.size();
    }
    for (Segment& s : segments) {
      table.time.insert(table.time.end(), s.time.begin(), s.time.end());
      table.sample_lines.insert(table.sample_lines.end(), s.rows.begin(), s.rows.end());
      for (size_t c = 0; c < channels; ++c) {
        table.columns[c].values.insert(table.columns[c].values.end(), s.data[c].begin(),
                                       s.data[c].end());
      }
    }
    return table;
  }

  const std::string& path_;
  std::vector<Line> lines_;
  size_t at_ = 0;
  char separator_ = '\t';
  bool decimal_comma_ = false;
  XColumns x_columns_ = XColumns::kOne;
  int time_place_ = std::numeric_limits<int>::min();
};

}  // namespace

RawTable ReadLvm(const std::string& path) {
  const std::string text = ReadWholeFile(path, kLvmFile);
  ValidateUtf8Text(text, path);
  return LvmReader(path, text).Read();
}

}  // namespace mbid::records::internal
