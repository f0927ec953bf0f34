#pragma once

// What UFF58 reading and writing share: the line cursor, a dataset as read, the reader's class.
// Private to records/. Uff58Reader's members are defined in uff58.cc (the datasets: framing,
// records 1 to 11, one table from all) and uff58_values.cc (the data values, ASCII and binary
// 58b); uff58_write.cc writes measurements.

#include <algorithm>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "mbid/common/error.h"
#include "raw_table.h"

namespace mbid::records::internal {

// The text mbid writes into ID line 5 (record 5) so that its own files read back with the exact
// interval and start time; record 7 prints them with six digits only (E13.5).
constexpr char kMbidTimeTag[] = "mbid sample_interval_s";

bool HostIsLittleEndian();

// A cursor over the file's bytes, line by line, with line numbers for messages.
class Lines {
 public:
  explicit Lines(const std::string& bytes) : bytes_(bytes) {}

  bool AtEnd() const { return at_ >= bytes_.size(); }
  size_t offset() const { return at_; }
  size_t remaining() const { return bytes_.size() - at_; }
  // Number of the line Next() returns next (1-based).
  int next_line() const { return line_ + 1; }
  int line() const { return line_; }

  // The next line without its end ("\n" or "\r\n"); nullopt at the end of the file.
  std::optional<std::string_view> Next() {
    if (AtEnd()) return std::nullopt;
    const size_t end = std::min(bytes_.find('\n', at_), bytes_.size());
    std::string_view text(bytes_.data() + at_, end - at_);
    if (!text.empty() && text.back() == '\r') text.remove_suffix(1);
    at_ = end < bytes_.size() ? end + 1 : end;
    ++line_;
    return text;
  }

  // `count` bytes of binary data; the caller has checked that they exist. Line numbers count
  // the line ends inside them so that later messages name the line a text editor shows.
  std::string_view Bytes(size_t count) {
    std::string_view data(bytes_.data() + at_, count);
    line_ += static_cast<int>(std::count(data.begin(), data.end(), '\n'));
    at_ += count;
    return data;
  }

 private:
  const std::string& bytes_;
  size_t at_ = 0;
  int line_ = 0;
};

bool IsDelimiter(std::string_view line);

// One dataset 58 as read: its time base and its ordinates.
struct Dataset {
  std::string where;  // "dataset 2 (line 40)"
  int first_line = 0;
  std::string name;
  std::string unit;
  std::string time_unit;
  bool even = true;
  double start = 0.0;
  double interval = 0.0;
  std::optional<double> exact_interval;  // from mbid's ID line 5
  std::optional<double> exact_start;
  std::vector<double> abscissa;  // uneven spacing only
  double abscissa_resolution = 0.0;
  std::vector<double> values;
  bool binary = false;
};

// Reads the datasets 58 of a universal file into one table.
class Uff58Reader {
 public:
  Uff58Reader(const std::string& path, const std::string& bytes) : path_(path), lines_(bytes) {}

  RawTable Read();

 private:
  // The datasets (uff58.cc).
  void ReadDataset();
  void SkipDataset(const std::vector<std::string_view>& id, int id_at);
  std::string_view NextRecord(const Dataset& dataset, int record);
  InputError RecordError(const Dataset& dataset, int record, const std::string& problem,
                         const std::string& expected) const;
  void ReadDataset58(const std::vector<std::string_view>& id, int id_at);
  void ReadMbidTimeTag(const std::string& line, int line_number, Dataset* d);
  RawTable Combine();

  // The data values (uff58_values.cc).
  std::vector<double> DecodeBinary(std::string_view data, size_t width, bool big_endian) const;
  void ExpectClosing(const Dataset& d, bool binary);
  std::vector<double> ReadAsciiValues(const Dataset& d, size_t value_count, bool single);
  static bool ParseFixed(std::string_view line, bool single, bool even, size_t limit,
                         std::vector<double>* numbers);
  static bool ParseBlankSeparated(std::string_view line, size_t limit,
                                  std::vector<double>* numbers);

  const std::string& path_;
  Lines lines_;
  std::vector<Dataset> datasets_;
};

}  // namespace mbid::records::internal
