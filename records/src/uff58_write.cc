// Writing a measurement as a universal file of datasets 58, ASCII or binary 58b (WriteUff58).

#include <fmt/format.h>

#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include "mbid/common/atomic_file.h"
#include "mbid/common/error.h"
#include "mbid/records/records.h"
#include "uff58_internal.h"

namespace mbid::records {
namespace internal {
namespace {

// Specific data type of record 9 for the SI units mbid writes; 0 (unknown) for others.
int SpecificDataType(const std::string& unit) {
  if (unit == "m" || unit == "rad") return 8;           // displacement
  if (unit == "m/s" || unit == "rad/s") return 11;      // velocity
  if (unit == "m/s^2" || unit == "rad/s^2") return 12;  // acceleration
  if (unit == "N") return 13;                           // excitation force
  return 0;
}

}  // namespace

}  // namespace internal

void WriteUff58(const Measurement& measurement, const std::string& path, bool binary) {
  measurement.Validate(path);
  for (size_t c = 0; c < measurement.channels.size(); ++c) {
    const std::string& name = measurement.channels[c];
    const std::string& unit = measurement.units[c];
    if (name.size() > 80 || unit.size() > 20) {
      throw InputError(path, name, "channel name longer than 80 or unit longer than 20 characters",
                       "names that fit ID line 1 (80 characters) and units record 9 (20)");
    }
  }
  AtomicFile file(path);
  std::FILE* out = std::fopen(file.temp_path().c_str(), "wb");
  if (out == nullptr) throw std::runtime_error("cannot create " + file.temp_path());
  bool ok = true;
  const auto write = [&](const std::string& text) {
    ok = ok && std::fwrite(text.data(), 1, text.size(), out) == text.size();
  };
  const Eigen::Index samples = measurement.samples();
  const std::string source = measurement.source.substr(0, 70);
  for (Eigen::Index c = 0; c < measurement.channel_count(); ++c) {
    std::string text = "    -1\n";
    if (binary) {
      // Byte ordering of this machine, IEEE 754 floats, 11 ASCII lines, then the doubles.
      text += fmt::format("{:>6}b{:>6}{:>6}{:>12}{:>12}{:>6}{:>6}{:>12}{:>12}\n", 58,
                          internal::HostIsLittleEndian() ? 1 : 2, 2, 11, samples * 8, 0, 0, 0, 0);
    } else {
      text += "    58\n";
    }
    text += measurement.channels[static_cast<size_t>(c)] + "\n";  // ID line 1: the channel
    text += "mbid " + source + "\n";                              // ID line 2: the source
    text += "NONE\nNONE\n";                                       // ID lines 3, 4
    text += fmt::format("{} {} start_time_s {}\n", internal::kMbidTimeTag,
                        measurement.sample_interval_s, measurement.start_time_s);
    // Record 6: time response, response node = channel number, scalar direction.
    text += fmt::format("{:>5}{:>10}{:>5}{:>10} {:<10}{:>10}{:>4} {:<10}{:>10}{:>4}\n", 1, c + 1, 1,
                        0, "NONE", c + 1, 0, "NONE", 0, 0);
    // Record 7: real double ordinates, even spacing, minimum, increment, z value.
    text += fmt::format("{:>10}{:>10}{:>10}{:13.5E}{:13.5E}{:13.5E}\n", 4, samples, 1,
                        measurement.start_time_s, measurement.sample_interval_s, 0.0);
    const std::string& unit = measurement.units[static_cast<size_t>(c)];
    const std::string axis = measurement.channels[static_cast<size_t>(c)].substr(0, 20);
    text += fmt::format("{:>10}{:>5}{:>5}{:>5} {:<20} {:<20}\n", 17, 0, 0, 0, "Time", "s");
    text += fmt::format("{:>10}{:>5}{:>5}{:>5} {:<20} {:<20}\n", internal::SpecificDataType(unit),
                        0, 0, 0, axis, unit);
    text += fmt::format("{:>10}{:>5}{:>5}{:>5} {:<20} {:<20}\n", 0, 0, 0, 0, "NONE", "NONE");
    text += fmt::format("{:>10}{:>5}{:>5}{:>5} {:<20} {:<20}\n", 0, 0, 0, 0, "NONE", "NONE");
    write(text);
    text.clear();
    if (binary) {
      std::vector<double> column(static_cast<size_t>(samples));
      for (Eigen::Index j = 0; j < samples; ++j)
        column[static_cast<size_t>(j)] = measurement.values(j, c);
      ok = ok && std::fwrite(column.data(), sizeof(double), column.size(), out) == column.size();
      text += "\n";
    } else {
      for (Eigen::Index j = 0; j < samples; ++j) {
        text += fmt::format("{:20.12E}", measurement.values(j, c));
        if (j % 4 == 3 || j == samples - 1) text += '\n';
        if (text.size() > (1 << 20)) {
          write(text);
          text.clear();
        }
      }
    }
    text += "    -1\n";
    write(text);
  }
  ok = (std::fclose(out) == 0) && ok;
  if (!ok) throw std::runtime_error("cannot write " + file.temp_path());
  file.Commit();
}

}  // namespace mbid::records
