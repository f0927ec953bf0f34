// H5Reader: mbid's HDF5 files and others' (h5py, MATLAB), every problem an InputError naming
// the file and object (docs/file-formats.md).
#include <H5Cpp.h>
#include <fmt/format.h>

#include <cctype>
#include <cmath>
#include <set>
#include <stdexcept>

#include "hdf5_internal.h"
#include "internal.h"
#include "mbid/common/csv_io.h"
#include "mbid/common/error.h"
#include "mbid/common/hdf5_io.h"
#include "mbid/common/utf8.h"

namespace mbid {
using internal::AttributeField;
using internal::Check;
using internal::Describe;
using internal::H5Lock;
using internal::H5Mutex;
using internal::Handle;
using internal::JoinPath;
using internal::kExpectedH5;
using internal::kH5FormatVersion;
using internal::ObjectExists;
using internal::OpenedObject;

namespace {

// A problem found while reading one object; the caller adds the file and object.
struct ReadProblem {
  std::string problem;
  std::string expected;
};

std::string TypeClassName(H5T_class_t type_class) {
  switch (type_class) {
    case H5T_INTEGER:
      return "integer";
    case H5T_FLOAT:
      return "float";
    case H5T_STRING:
      return "string";
    case H5T_COMPOUND:
      return "compound";
    case H5T_ENUM:
      return "enum";
    case H5T_ARRAY:
      return "array";
    case H5T_VLEN:
      return "variable-length";
    default:
      return "non-numeric";
  }
}

// Limits checked before anything is allocated: a damaged or hostile file may state any size.
// 1e8 samples is the records readers' limit too; names and the scenario text are far smaller.
constexpr hsize_t kMaxNumbers = 100000000;
constexpr hsize_t kMaxStrings = 1000000;
constexpr size_t kMaxStringBytes = size_t{64} << 20;

// The number of elements of a dataspace and its dimensions, refused beyond `limit`.
hsize_t CountElements(hid_t space, hsize_t limit, std::vector<hsize_t>* dims) {
  const H5S_class_t space_class = H5Sget_simple_extent_type(space);
  dims->clear();
  if (space_class == H5S_NULL) return 0;
  if (space_class == H5S_SCALAR) return 1;
  if (space_class != H5S_SIMPLE) throw H5::Exception("H5Sget_simple_extent_type", "failed");
  const int rank = H5Sget_simple_extent_ndims(space);
  if (rank < 0 || rank > H5S_MAX_RANK) throw H5::Exception("H5Sget_simple_extent_ndims", "failed");
  dims->assign(static_cast<size_t>(rank), 0);
  Check(H5Sget_simple_extent_dims(space, dims->data(), nullptr), "H5Sget_simple_extent_dims");
  hsize_t count = 1;
  for (const hsize_t d : *dims) {
    // Checked per factor so that the product cannot overflow before the comparison.
    if (d != 0 && count > limit / d) {
      throw ReadProblem{fmt::format("has dimensions beyond {} elements", limit),
                        fmt::format("at most {} elements", limit)};
    }
    count *= d;
  }
  return count;
}

// Strings of an attribute or dataset, variable- or fixed-length (h5py and MATLAB write both),
// each checked as UTF-8 (they become channel names, units and scenario text).
std::vector<std::string> ReadStringData(hid_t id, bool is_attribute) {
  const Handle file_type(is_attribute ? H5Aget_type(id) : H5Dget_type(id), H5Tclose, "H5Xget_type");
  const H5T_class_t type_class = H5Tget_class(file_type.get());
  if (type_class != H5T_STRING) {
    throw ReadProblem{"is of " + TypeClassName(type_class) + " type", "strings"};
  }
  const Handle space(is_attribute ? H5Aget_space(id) : H5Dget_space(id), H5Sclose, "H5Xget_space");
  std::vector<hsize_t> dims;
  const hsize_t n = CountElements(space.get(), kMaxStrings, &dims);
  std::vector<std::string> out;
  const auto read = [&](hid_t memory_type, void* buffer) {
    Check(is_attribute ? H5Aread(id, memory_type, buffer)
                       : H5Dread(id, memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, buffer),
          "H5Xread");
  };
  const htri_t variable = H5Tis_variable_str(file_type.get());
  Check(variable, "H5Tis_variable_str");
  if (variable > 0) {
    // libhdf5 1.10 can crash or loop on a corrupt global heap here; H5Reader's constructor
    // has read every string of the file in a child process first (SurvivesInChild).
    const Handle memory_type(H5Tcopy(H5T_C_S1), H5Tclose, "H5Tcopy");
    Check(H5Tset_size(memory_type.get(), H5T_VARIABLE), "H5Tset_size");
    // HDF5 does not convert between character sets: read in the file's own.
    Check(H5Tset_cset(memory_type.get(), H5Tget_cset(file_type.get())), "H5Tset_cset");
    std::vector<char*> pointers(static_cast<size_t>(n), nullptr);
    if (n > 0) read(memory_type.get(), pointers.data());
    size_t total = 0;
    for (char* p : pointers) {
      out.emplace_back(p == nullptr ? "" : p);
      total += out.back().size();
    }
    if (n > 0) H5Dvlen_reclaim(memory_type.get(), space.get(), H5P_DEFAULT, pointers.data());
    if (total > kMaxStringBytes) {
      throw ReadProblem{fmt::format("holds {} bytes of text", total),
                        fmt::format("at most {} bytes", kMaxStringBytes)};
    }
  } else {
    const size_t size = H5Tget_size(file_type.get());
    if (size == 0 || (n > 0 && size > kMaxStringBytes / n)) {
      throw ReadProblem{fmt::format("holds {} strings of {} bytes", n, size),
                        fmt::format("at most {} bytes of text", kMaxStringBytes)};
    }
    const Handle memory_type(H5Tcopy(file_type.get()), H5Tclose, "H5Tcopy");
    std::vector<char> buffer(size * static_cast<size_t>(n) + 1, '\0');
    if (n > 0) read(memory_type.get(), buffer.data());
    const bool space_padded = H5Tget_strpad(file_type.get()) == H5T_STR_SPACEPAD;
    for (hsize_t i = 0; i < n; ++i) {
      std::string s(buffer.data() + static_cast<size_t>(i) * size, size);
      s = s.substr(0, s.find('\0'));
      if (space_padded) s = s.substr(0, s.find_last_not_of(' ') + 1);
      out.push_back(s);
    }
  }
  for (size_t i = 0; i < out.size(); ++i) {
    const size_t bad = FindInvalidUtf8(out[i]);
    if (bad != std::string::npos) {
      throw ReadProblem{
          fmt::format("string {} is not UTF-8 (byte 0x{:02X} at byte {})", i + 1,
                      static_cast<unsigned>(static_cast<unsigned char>(out[i][bad])), bad + 1),
          "UTF-8 text"};
    }
  }
  return out;
}

// A numeric attribute or dataset as row-major doubles, its dimensions in `dims`; the rank is
// checked against `rank` unless that is negative.
std::vector<double> ReadNumericData(hid_t id, bool is_attribute, int rank,
                                    std::vector<hsize_t>* dims) {
  const Handle file_type(is_attribute ? H5Aget_type(id) : H5Dget_type(id), H5Tclose, "H5Xget_type");
  const H5T_class_t type_class = H5Tget_class(file_type.get());
  if (type_class != H5T_FLOAT && type_class != H5T_INTEGER) {
    throw ReadProblem{"is of " + TypeClassName(type_class) + " type", "float64 numbers"};
  }
  const Handle space(is_attribute ? H5Aget_space(id) : H5Dget_space(id), H5Sclose, "H5Xget_space");
  const hsize_t n = CountElements(space.get(), kMaxNumbers, dims);
  const int actual_rank = static_cast<int>(dims->size());
  if (rank >= 0 && actual_rank != rank) {
    throw ReadProblem{fmt::format("has {} dimensions", actual_rank),
                      fmt::format("{} dimensions", rank)};
  }
  std::vector<double> data(static_cast<size_t>(n));
  if (n > 0) {
    Check(is_attribute ? H5Aread(id, H5T_NATIVE_DOUBLE, data.data())
                       : H5Dread(id, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, data.data()),
          "H5Xread");
  }
  return data;
}

// ---- the probe in a child process ----------------------------------------------------------

// Reads every string and number of one attribute or dataset as H5Reader would; problems that
// H5Reader reports as InputErrors do not matter here, only whether libhdf5 survives.
void ProbeData(hid_t id, bool is_attribute) {
  try {
    const Handle type(is_attribute ? H5Aget_type(id) : H5Dget_type(id), H5Tclose, "H5Xget_type");
    const H5T_class_t type_class = H5Tget_class(type.get());
    if (type_class == H5T_STRING) {
      ReadStringData(id, is_attribute);
    } else if (type_class == H5T_FLOAT || type_class == H5T_INTEGER) {
      std::vector<hsize_t> dims;
      ReadNumericData(id, is_attribute, -1, &dims);
    }
  } catch (const H5::Exception&) {
  } catch (const ReadProblem&) {
  }
}

herr_t ProbeAttribute(hid_t object, const char* name, const H5A_info_t*, void*) {
  const hid_t attribute = H5Aopen(object, name, H5P_DEFAULT);
  if (attribute >= 0) {
    ProbeData(attribute, true);
    H5Aclose(attribute);
  }
  return 0;
}

herr_t ProbeObject(hid_t root, const char* name, const H5O_info_t* info, void*) {
  const hid_t object = H5Oopen(root, name, H5P_DEFAULT);
  if (object < 0) return 0;
  hsize_t index = 0;
  H5Aiterate2(object, H5_INDEX_NAME, H5_ITER_NATIVE, &index, ProbeAttribute, nullptr);
  if (info->type == H5O_TYPE_DATASET) ProbeData(object, false);
  if (info->type == H5O_TYPE_GROUP) {
    H5G_info_t group_info;  // the link count, as H5Reader's lookups walk the same B-tree
    H5Gget_info(object, &group_info);
  }
  H5Oclose(object);
  return 0;
}

// What the child does: open the file and read all of it.
void ProbeFile(const std::string& path) {
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (file < 0) return;
  H5Ovisit2(file, H5_INDEX_NAME, H5_ITER_NATIVE, ProbeObject, nullptr, H5O_INFO_BASIC);
  H5Fclose(file);
}

}  // namespace

namespace internal {

void ProbeHdf5InChild(const std::string& path, const std::string& expected) {
  SurviveInChild(path, expected, "the HDF5 library", [&] { ProbeFile(path); });
}

}  // namespace internal

namespace {

void CheckNumeric(H5T_class_t type_class) {
  if (type_class != H5T_FLOAT && type_class != H5T_INTEGER) {
    throw ReadProblem{"is of " + TypeClassName(type_class) + " type", "float64 numbers"};
  }
}

// ---- the measurement group ----------------------------------------------------------------

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

// The group's `time` dataset: in s, at least 2 samples.
Eigen::VectorXd ReadTime(const H5Reader& file, const std::string& group) {
  const std::string& path = file.path();
  const std::string time_path = group + "/time";
  if (!file.Exists(time_path)) {
    throw InputError(path, time_path, "missing dataset", "the sample times in seconds");
  }
  const Eigen::VectorXd time = file.ReadVector(group, "time");
  RequireAttribute(file, time_path, "units", "units = 's'");
  const std::string time_units = file.ReadUnits(group, "time");
  if (time_units != "s") {
    throw InputError(path, AttributeField(time_path, "units"), "is '" + time_units + "'", "'s'");
  }
  const Eigen::Index n = time.size();
  if (n < 2) {
    throw InputError(path, time_path, fmt::format("has {} samples", n), "at least 2 samples");
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

struct H5Reader::Impl {
  std::string path;
  H5::H5File file;

  // Runs HDF5 calls about `object`, turning every failure into an InputError naming it.
  template <typename Body>
  auto Run(const std::string& object, Body&& body) const {
    H5Lock lock(H5Mutex());
    try {
      return body();
    } catch (const H5::Exception& e) {
      throw InputError(path, object, "HDF5 error: " + Describe(e), kExpectedH5);
    } catch (const ReadProblem& p) {
      throw InputError(path, object, p.problem, p.expected);
    }
  }

  H5::DataSet OpenDataSet(const std::string& object, const std::string& expected) const {
    if (!ObjectExists(file, object) || file.childObjType(object) != H5O_TYPE_DATASET) {
      throw ReadProblem{"missing dataset", expected};
    }
    return file.openDataSet(object);
  }

  H5::Attribute OpenAttribute(const std::string& object, const std::string& name) const {
    if (!ObjectExists(file, object)) throw ReadProblem{"missing object " + object, "an attribute"};
    const OpenedObject target(file, object);
    if (!target.get().attrExists(name)) {
      throw ReadProblem{"missing", "an attribute '" + name + "'"};
    }
    return target.get().openAttribute(name);
  }

  // Numeric dataset of the given rank, read as row-major doubles; dims returned in `dims`.
  std::vector<double> ReadNumeric(const std::string& object, int rank,
                                  std::vector<hsize_t>* dims) const {
    const H5::DataSet dataset = OpenDataSet(object, "a float64 dataset");
    return ReadNumericData(dataset.getId(), false, rank, dims);
  }
};

H5Reader::H5Reader(const std::string& path, Probe probe) {
  H5Lock lock(H5Mutex());
  H5::Exception::dontPrint();
  internal::CheckReadable(path, kExpectedH5);
  bool is_hdf5 = false;
  try {
    is_hdf5 = H5::H5File::isHdf5(path);
  } catch (const H5::Exception&) {
    H5Eclear2(H5E_DEFAULT);
  }
  if (!is_hdf5) throw InputError(path, "", "not an HDF5 file", kExpectedH5);
  if (probe == Probe::kEverything) internal::ProbeHdf5InChild(path, kExpectedH5);
  impl_ = std::make_unique<Impl>();
  impl_->path = path;
  try {
    impl_->file.openFile(path, H5F_ACC_RDONLY);
  } catch (const H5::Exception& e) {
    throw InputError(path, "", "cannot open as HDF5: " + Describe(e), kExpectedH5);
  }
}

H5Reader::~H5Reader() {
  H5Lock lock(H5Mutex());
  impl_.reset();
}

const std::string& H5Reader::path() const { return impl_->path; }

bool H5Reader::Exists(const std::string& object) const {
  return impl_->Run(object, [&] { return ObjectExists(impl_->file, object); });
}

bool H5Reader::HasAttribute(const std::string& object, const std::string& name) const {
  return impl_->Run(AttributeField(object, name), [&] {
    return ObjectExists(impl_->file, object) &&
           OpenedObject(impl_->file, object).get().attrExists(name);
  });
}

Eigen::VectorXd H5Reader::ReadVector(const std::string& group, const std::string& name) const {
  const std::string object = JoinPath(group, name);
  return impl_->Run(object, [&] {
    std::vector<hsize_t> dims;
    const std::vector<double> data = impl_->ReadNumeric(object, 1, &dims);
    return Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(data.data(), data.size()));
  });
}

Eigen::MatrixXd H5Reader::ReadMatrix(const std::string& group, const std::string& name) const {
  const std::string object = JoinPath(group, name);
  return impl_->Run(object, [&] {
    std::vector<hsize_t> dims;
    const std::vector<double> data = impl_->ReadNumeric(object, 2, &dims);
    using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
    return Eigen::MatrixXd(Eigen::Map<const RowMajor>(
        data.data(), static_cast<Eigen::Index>(dims[0]), static_cast<Eigen::Index>(dims[1])));
  });
}

double H5Reader::ReadScalar(const std::string& group, const std::string& name) const {
  const std::string object = JoinPath(group, name);
  return impl_->Run(object, [&] {
    std::vector<hsize_t> dims;
    const std::vector<double> data = impl_->ReadNumeric(object, 0, &dims);
    if (data.empty()) throw ReadProblem{"is empty (a null dataspace)", "a scalar number"};
    return data.front();
  });
}

std::vector<std::string> H5Reader::ReadStrings(const std::string& group,
                                               const std::string& name) const {
  const std::string object = JoinPath(group, name);
  return impl_->Run(object, [&] {
    const H5::DataSet dataset = impl_->OpenDataSet(object, "a string dataset");
    return ReadStringData(dataset.getId(), false);
  });
}

std::string H5Reader::ReadUnits(const std::string& group, const std::string& name) const {
  return ReadStringAttribute(JoinPath(group, name), "units");
}

std::string H5Reader::ReadStringAttribute(const std::string& object,
                                          const std::string& name) const {
  return impl_->Run(AttributeField(object, name), [&] {
    const H5::Attribute attribute = impl_->OpenAttribute(object, name);
    const std::vector<std::string> values = ReadStringData(attribute.getId(), true);
    if (values.size() != 1) {
      throw ReadProblem{fmt::format("has {} strings", values.size()), "a single string"};
    }
    return values.front();
  });
}

std::vector<std::string> H5Reader::ReadStringArrayAttribute(const std::string& object,
                                                            const std::string& name) const {
  return impl_->Run(AttributeField(object, name), [&] {
    const H5::Attribute attribute = impl_->OpenAttribute(object, name);
    return ReadStringData(attribute.getId(), true);
  });
}

double H5Reader::ReadDoubleAttribute(const std::string& object, const std::string& name) const {
  return impl_->Run(AttributeField(object, name), [&] {
    const H5::Attribute attribute = impl_->OpenAttribute(object, name);
    CheckNumeric(attribute.getTypeClass());
    if (attribute.getSpace().getSimpleExtentNpoints() != 1) {
      throw ReadProblem{"is not a single number", "a scalar number"};
    }
    double value = 0;
    attribute.read(H5::PredType::NATIVE_DOUBLE, &value);
    return value;
  });
}

long long H5Reader::ReadIntAttribute(const std::string& object, const std::string& name) const {
  return impl_->Run(AttributeField(object, name), [&] {
    const H5::Attribute attribute = impl_->OpenAttribute(object, name);
    if (attribute.getTypeClass() != H5T_INTEGER) {
      throw ReadProblem{"is of " + TypeClassName(attribute.getTypeClass()) + " type", "an integer"};
    }
    if (attribute.getSpace().getSimpleExtentNpoints() != 1) {
      throw ReadProblem{"is not a single number", "a scalar integer"};
    }
    long long value = 0;
    attribute.read(H5::PredType::NATIVE_LLONG, &value);
    return value;
  });
}

Measurement H5Reader::ReadMeasurement() const {
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

  const Eigen::VectorXd time = ReadTime(*this, group);
  const Eigen::Index n = time.size();
  m.values.resize(n, static_cast<Eigen::Index>(m.channels.size()));
  for (size_t c = 0; c < m.channels.size(); ++c) {
    std::string units;
    m.values.col(static_cast<Eigen::Index>(c)) =
        ReadChannel(*this, group, m.channels[c], time, &units);
    m.units.push_back(units);
  }

  const std::string time_path = group + "/time";
  const double tau = CheckUniformTime(time, path, [&time_path](Eigen::Index) { return time_path; });
  if (!std::isfinite(interval) || !(std::abs(interval - tau) < kTimeUniformityTolerance * tau)) {
    throw InputError(path, AttributeField(group, "sample_interval_s"),
                     fmt::format("is {} s but {} has a step of {} s", interval, time_path, tau),
                     "the step of the time dataset");
  }
  m.start_time_s = time[0];
  m.sample_interval_s = interval;
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
Measurement ReadMeasurementH5(const std::string& path) {
  const auto read = [&] { return H5Reader(path, H5Reader::Probe::kNone).ReadMeasurement(); };
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
