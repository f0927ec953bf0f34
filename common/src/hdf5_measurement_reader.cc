// mbid's HDF5 measurement file read: the /measurement group, the scenario text, free functions
// (ReadMeasurementH5, ReadScenarioYaml, ReadMeasurement).
#include <H5Cpp.h>
#include <fmt/format.h>

#include <cctype>
#include <cmath>
#include <set>
#include <string>
#include <vector>

#include "hdf5_internal.h"
#include "hdf5_reader_impl.h"
#include "internal.h"
#include "mbid/common/csv_io.h"
#include "mbid/common/error.h"
#include "mbid/common/hdf5_io.h"

namespace mbid {
using internal::AttributeField;
using internal::JoinPath;
using internal::kExpectedH5;
using internal::kH5FormatVersion;

namespace {

void RequireAttribute(const H5Reader& file, const std::string& object, const std::string& name,
                      const std::string& expected) {
  if (!file.HasAttribute(object, name)) {
    throw InputError(file.path(), AttributeField(object, name), "missing", expected);
  }
}

// The root's format = 'mbid' and format_version this program reads.
void CheckFormat(const H5Reader& file) {
  const std::string& path = file.path();
  RequireAttribute(file, "/", "format", "format = 'mbid' (an mbid file, docs/interfaces)");
  const std::string format = file.ReadStringAttribute("/", "format");
  if (format != "mbid") {
    throw InputError(path, AttributeField("/", "format"), "is '" + format + "'", "'mbid'");
  }
  RequireAttribute(file, "/", "format_version",
                   fmt::format("format_version = {}", kH5FormatVersion));
  const long long version = file.ReadIntAttribute("/", "format_version");
  if (version != kH5FormatVersion) {
    throw InputError(
        path, AttributeField("/", "format_version"),
        fmt::format("is {}{}", version,
                    version > kH5FormatVersion ? ", newer than this program reads" : ""),
        fmt::format("{}", kH5FormatVersion));
  }
}

// The group's `channels` attribute: non-empty, unique names other than "time", without '/'.
std::vector<std::string> ReadChannelNames(const H5Reader& file, const std::string& group) {
  const std::string& path = file.path();
  RequireAttribute(file, group, "channels", "the channel names as a string array");
  std::vector<std::string> channels = file.ReadStringArrayAttribute(group, "channels");
  const std::string channels_field = AttributeField(group, "channels");
  if (channels.empty()) {
    throw InputError(path, channels_field, "lists no channels", "at least one channel name");
  }
  std::set<std::string> seen;
  for (const auto& channel : channels) {
    if (channel.empty() || channel == "time" || channel.find('/') != std::string::npos) {
      throw InputError(path, channels_field, "invalid channel name '" + channel + "'",
                       "non-empty names other than 'time', without '/'");
    }
    if (!seen.insert(channel).second) {
      throw InputError(path, channels_field, "channel '" + channel + "' is listed twice",
                       "unique channel names");
    }
  }
  return channels;
}

// The group's `time` dataset in s, at least 2 samples: stated in s, or in the unit
// `seconds_per_unit` converts (it names the unit it read the times in).
Eigen::VectorXd ReadTime(const H5Reader& file, const std::string& group,
                         const SecondsPerTimeUnit& seconds_per_unit, std::string* unit) {
  const std::string& path = file.path();
  const std::string time_path = group + "/time";
  if (!file.Exists(time_path)) {
    throw InputError(path, time_path, "missing dataset", "the sample times in seconds");
  }
  const Eigen::VectorXd time = file.ReadVector(group, "time");
  const Eigen::Index n = time.size();
  if (n < 2) {
    throw InputError(path, time_path, fmt::format("has {} samples", n), "at least 2 samples");
  }
  if (seconds_per_unit) {
    const std::string stated =
        file.HasAttribute(time_path, "units") ? file.ReadUnits(group, "time") : "";
    return seconds_per_unit(stated, AttributeField(time_path, "units"), unit) * time;
  }
  RequireAttribute(file, time_path, "units", "units = 's'");
  *unit = file.ReadUnits(group, "time");
  if (*unit != "s") {
    throw InputError(path, AttributeField(time_path, "units"), "is '" + *unit + "'", "'s'");
  }
  return time;
}

// One channel's dataset: as many finite samples as `time`, with its units.
Eigen::VectorXd ReadChannel(const H5Reader& file, const std::string& group,
                            const std::string& channel, const Eigen::VectorXd& time,
                            std::string* units) {
  const std::string& path = file.path();
  const Eigen::Index n = time.size();
  const std::string object = JoinPath(group, channel);
  if (!file.Exists(object)) {
    throw InputError(path, object,
                     "missing dataset for channel '" + channel + "' (listed in " +
                         AttributeField(group, "channels") + ")",
                     "one dataset per channel");
  }
  const Eigen::VectorXd v = file.ReadVector(group, channel);
  if (v.size() != n) {
    throw InputError(path, object, fmt::format("has {} samples", v.size()),
                     fmt::format("{} samples like {}", n, group + "/time"));
  }
  RequireAttribute(file, object, "units", "a units string such as 'rad'");
  *units = file.ReadUnits(group, channel);
  for (Eigen::Index j = 0; j < n; ++j) {
    if (!std::isfinite(v[j])) {
      throw InputError(path, object,
                       fmt::format("sample {} (t = {} s) is {}", j, time[j],
                                   std::isnan(v[j]) ? "NaN" : (v[j] > 0 ? "+Inf" : "-Inf")),
                       "finite values");
    }
  }
  return v;
}

}  // namespace

Measurement H5Reader::ReadMeasurement(const SecondsPerTimeUnit& seconds_per_unit) const {
  const std::string& path = impl_->path;
  CheckFormat(*this);
  const std::string group = "/measurement";
  if (!Exists(group) ||
      impl_->Run(group, [&] { return impl_->file.childObjType(group); }) != H5O_TYPE_GROUP) {
    throw InputError(path, group, "missing group", "a /measurement group (docs/interfaces)");
  }
  Measurement m;
  m.channels = ReadChannelNames(*this, group);
  RequireAttribute(*this, group, "sample_interval_s", "the sample interval in seconds");
  const double interval = ReadDoubleAttribute(group, "sample_interval_s");
  if (HasAttribute(group, "source")) m.source = ReadStringAttribute(group, "source");

  std::string time_unit;
  const Eigen::VectorXd time = ReadTime(*this, group, seconds_per_unit, &time_unit);
  const Eigen::Index n = time.size();
  m.values.resize(n, static_cast<Eigen::Index>(m.channels.size()));
  for (size_t c = 0; c < m.channels.size(); ++c) {
    std::string units;
    m.values.col(static_cast<Eigen::Index>(c)) =
        ReadChannel(*this, group, m.channels[c], time, &units);
    m.units.push_back(units);
  }

  const std::string time_path = group + "/time";
  // Times stored in single precision, or as epoch seconds, are uniform only to their last bit:
  // that is their resolution, as a printed digit is a text file's.
  const bool single = (time.array() == time.array().cast<float>().cast<double>()).all();
  const double resolution = time.cwiseAbs().maxCoeff() * (single ? 0x1p-23 : 0x1p-52);
  double fitted_start = 0;
  const double tau = CheckUniformTime(
      time, path, [&time_path](Eigen::Index) { return time_path; }, resolution, &fitted_start);
  // The stated interval is exact (mbid's round trips) when it agrees; a writer that took it
  // from two stored times has their resolution in it, and the fitted step is the better value.
  // The fit's own uncertainty from times rounded to `resolution`: res / sqrt(12) * sqrt(12 / n^3).
  const double fit_std = resolution / std::pow(static_cast<double>(time.size()), 1.5);
  const bool exact =
      std::abs(interval - tau) < std::max(kTimeUniformityTolerance * tau, 4 * fit_std);
  if (!std::isfinite(interval) || !(exact || std::abs(interval - tau) <= 2 * resolution)) {
    throw InputError(path, AttributeField(group, "sample_interval_s"),
                     fmt::format("is {} s but {} has a step of {} s{}", interval, time_path, tau,
                                 time_unit == "s" ? "" : " (its times read in " + time_unit + ")"),
                     "the step of the time dataset");
  }
  m.start_time_s = std::abs(time[0] - fitted_start) <= resolution ? time[0] : fitted_start;
  m.sample_interval_s = exact ? interval : tau;
  m.Validate(path);
  return m;
}

std::string H5Reader::ReadScenarioYaml() const {
  if (!HasAttribute("/scenario", "yaml")) return "";
  return ReadStringAttribute("/scenario", "yaml");
}

// ---- free functions -----------------------------------------------------------------------

// The child makes exactly the calls this process makes next, from the same library state (the
// fork's copy): a survey of the file can miss a path, and libhdf5 looped in-process on a
// variable-length string the survey had read without harm.
Measurement ReadMeasurementH5(const std::string& path, const SecondsPerTimeUnit& seconds_per_unit) {
  const auto read = [&] {
    return H5Reader(path, H5Reader::Probe::kNone).ReadMeasurement(seconds_per_unit);
  };
  internal::SurviveInChild(path, kExpectedH5, "the HDF5 library", read);
  return read();
}

std::string ReadScenarioYaml(const std::string& path) {
  const auto read = [&] { return H5Reader(path, H5Reader::Probe::kNone).ReadScenarioYaml(); };
  internal::SurviveInChild(path, kExpectedH5, "the HDF5 library", read);
  return read();
}

Measurement ReadMeasurement(const std::string& path) {
  const std::string accepted = "a measurement file ending in .h5, .hdf5 or .csv";
  internal::CheckReadable(path, accepted);
  const size_t dot = path.find_last_of('.');
  const size_t slash = path.find_last_of('/');
  std::string extension;
  if (dot != std::string::npos && (slash == std::string::npos || dot > slash)) {
    extension = path.substr(dot);
  }
  std::string lower = extension;
  for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (lower == ".h5" || lower == ".hdf5") return ReadMeasurementH5(path);
  if (lower == ".csv") return ReadMeasurementCsv(path);
  throw InputError(
      path, "",
      extension.empty() ? "no file extension" : "unknown file extension '" + extension + "'",
      accepted);
}

}  // namespace mbid
