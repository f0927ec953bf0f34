#include "mbid/common/hdf5_io.h"

#include <H5Cpp.h>
#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <mutex>
#include <optional>
#include <set>
#include <stdexcept>

#include "internal.h"
#include "mbid/common/atomic_file.h"
#include "mbid/common/csv_io.h"
#include "mbid/common/error.h"

namespace mbid {
namespace {

constexpr char kExpectedH5[] = "an mbid HDF5 measurement file (docs/interfaces)";
constexpr int kFormatVersion = 1;
// Long vectors (recorded channels) are chunked and compressed; short results stay contiguous.
constexpr hsize_t kChunkThreshold = 4096;
constexpr hsize_t kChunkSize = 65536;  // 512 KiB of doubles: inside HDF5's default chunk cache.
constexpr int kDeflateLevel = 4;       // Most of level 9's gain on smooth signals, much faster.
constexpr size_t kCoreIncrement = 1 << 20;  // in-memory file growth: 1 MiB, few reallocations

// The serial HDF5 library is not thread-safe; every call goes through this lock.
std::recursive_mutex& H5Mutex() {
  static std::recursive_mutex mutex;
  return mutex;
}
using H5Lock = std::lock_guard<std::recursive_mutex>;

// RAII for the few C-API handles used where the C++ API has no equivalent (string arrays).
class Handle {
 public:
  Handle(hid_t id, herr_t (*close)(hid_t), const char* what) : id_(id), close_(close) {
    if (id_ < 0) throw H5::Exception(what, "failed");
  }
  ~Handle() { close_(id_); }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  hid_t get() const { return id_; }

 private:
  hid_t id_;
  herr_t (*close_)(hid_t);
};

void Check(herr_t status, const char* what) {
  if (status < 0) throw H5::Exception(what, "failed");
}

herr_t CollectInnermost(unsigned n, const H5E_error2_t* error, void* data) {
  if (n == 0 && error->desc != nullptr) *static_cast<std::string*>(data) = error->desc;
  return 0;
}

// The C++ exception names the API call; the error stack says why (e.g. "file signature not
// found"). Automatic printing is off, so the stack is still there.
std::string Describe(const H5::Exception& e) {
  std::string innermost;
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_UPWARD, CollectInnermost, &innermost);
  H5Eclear2(H5E_DEFAULT);
  std::string text =
      e.getFuncName().empty() ? e.getDetailMsg() : e.getFuncName() + ": " + e.getDetailMsg();
  if (!innermost.empty()) text += " (" + innermost + ")";
  return text;
}

std::string JoinPath(const std::string& group, const std::string& name) {
  if (group.empty() || group == "/") return "/" + name;
  return group.back() == '/' ? group + name : group + "/" + name;
}

std::string AttributeField(const std::string& object, const std::string& name) {
  return object + " attribute '" + name + "'";
}

std::vector<std::string> PathPrefixes(const std::string& path) {
  std::vector<std::string> prefixes;
  std::string current;
  size_t start = 0;
  while (start < path.size()) {
    size_t end = path.find('/', start);
    if (end == std::string::npos) end = path.size();
    if (end > start) {
      current += "/" + path.substr(start, end - start);
      prefixes.push_back(current);
    }
    start = end + 1;
  }
  return prefixes;
}

// Whether `path` exists, without HDF5 errors for missing or non-group intermediates.
bool ObjectExists(const H5::H5File& file, const std::string& path) {
  const std::vector<std::string> prefixes = PathPrefixes(path);
  if (prefixes.empty()) return true;  // the root
  for (size_t i = 0; i < prefixes.size(); ++i) {
    if (!file.nameExists(prefixes[i])) return false;
    if (i + 1 < prefixes.size() && file.childObjType(prefixes[i]) != H5O_TYPE_GROUP) return false;
  }
  return true;
}

H5O_type_t ObjectType(const H5::H5File& file, const std::string& path) {
  if (PathPrefixes(path).empty()) return H5O_TYPE_GROUP;
  return file.childObjType(path);
}

// A group or dataset, whichever `path` names (H5Object's destructor is protected, so it cannot
// be owned through a base pointer).
class OpenedObject {
 public:
  OpenedObject(const H5::H5File& file, const std::string& path) {
    if (ObjectType(file, path) == H5O_TYPE_DATASET) {
      dataset_.emplace(file.openDataSet(path));
    } else {
      group_.emplace(file.openGroup(PathPrefixes(path).empty() ? "/" : path));
    }
  }
  const H5::H5Object& get() const {
    if (dataset_) return *dataset_;
    return *group_;
  }

 private:
  std::optional<H5::Group> group_;
  std::optional<H5::DataSet> dataset_;
};

H5::StrType VariableUtf8() {
  H5::StrType type(H5::PredType::C_S1, H5T_VARIABLE);
  type.setCset(H5T_CSET_UTF8);
  return type;
}

// ---- writing ------------------------------------------------------------------------------

H5::Group EnsureGroup(H5::H5File& file, const std::string& path) {
  for (const std::string& prefix : PathPrefixes(path)) {
    if (!file.nameExists(prefix)) {
      file.createGroup(prefix);
    } else if (file.childObjType(prefix) != H5O_TYPE_GROUP) {
      throw H5::Exception("EnsureGroup", prefix + " exists and is not a group");
    }
  }
  return file.openGroup(PathPrefixes(path).empty() ? "/" : path);
}

void RemoveIfExists(H5::H5File& file, const std::string& path) {
  if (!PathPrefixes(path).empty() && ObjectExists(file, path)) file.unlink(path);
}

void PrepareAttribute(const H5::H5Object& object, const std::string& name) {
  if (object.attrExists(name)) object.removeAttr(name);
}

void WriteStringAttr(const H5::H5Object& object, const std::string& name,
                     const std::string& value) {
  PrepareAttribute(object, name);
  const H5::StrType type = VariableUtf8();
  object.createAttribute(name, type, H5::DataSpace(H5S_SCALAR)).write(type, value);
}

void WriteStringArrayAttr(const H5::H5Object& object, const std::string& name,
                          const std::vector<std::string>& values) {
  PrepareAttribute(object, name);
  const H5::StrType type = VariableUtf8();
  const hsize_t n = values.size();
  std::vector<const char*> pointers;
  for (const auto& v : values) pointers.push_back(v.c_str());
  object.createAttribute(name, type, H5::DataSpace(1, &n)).write(type, pointers.data());
}

void WriteDoubleAttr(const H5::H5Object& object, const std::string& name, double value) {
  PrepareAttribute(object, name);
  object.createAttribute(name, H5::PredType::IEEE_F64LE, H5::DataSpace(H5S_SCALAR))
      .write(H5::PredType::NATIVE_DOUBLE, &value);
}

void WriteIntAttr(const H5::H5Object& object, const std::string& name, int value) {
  PrepareAttribute(object, name);
  object.createAttribute(name, H5::PredType::STD_I32LE, H5::DataSpace(H5S_SCALAR))
      .write(H5::PredType::NATIVE_INT, &value);
}

void WriteDoubleDataset(H5::H5File& file, const std::string& group, const std::string& name,
                        const std::vector<hsize_t>& dims, const double* data,
                        const std::string& units) {
  EnsureGroup(file, group);
  const std::string path = JoinPath(group, name);
  RemoveIfExists(file, path);
  hsize_t count = 1;
  for (hsize_t d : dims) count *= d;
  H5::DSetCreatPropList properties;
  if (dims.size() == 1 && count >= kChunkThreshold) {
    const hsize_t chunk = std::min(count, kChunkSize);
    properties.setChunk(1, &chunk);
    if (H5Zfilter_avail(H5Z_FILTER_DEFLATE) > 0) {
      properties.setShuffle();
      properties.setDeflate(kDeflateLevel);
    }
  }
  const H5::DataSpace space = dims.empty()
                                  ? H5::DataSpace(H5S_SCALAR)
                                  : H5::DataSpace(static_cast<int>(dims.size()), dims.data());
  H5::DataSet dataset = file.createDataSet(path, H5::PredType::IEEE_F64LE, space, properties);
  if (count > 0) dataset.write(data, H5::PredType::NATIVE_DOUBLE);
  if (!units.empty()) WriteStringAttr(dataset, "units", units);
}

// ---- reading ------------------------------------------------------------------------------

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

// Strings of an attribute or dataset, variable- or fixed-length (h5py and MATLAB write both).
std::vector<std::string> ReadStringData(hid_t id, bool is_attribute) {
  const Handle file_type(is_attribute ? H5Aget_type(id) : H5Dget_type(id), H5Tclose, "H5Xget_type");
  const H5T_class_t type_class = H5Tget_class(file_type.get());
  if (type_class != H5T_STRING) {
    throw ReadProblem{"is of " + TypeClassName(type_class) + " type", "strings"};
  }
  const Handle space(is_attribute ? H5Aget_space(id) : H5Dget_space(id), H5Sclose, "H5Xget_space");
  const hssize_t n = H5Sget_simple_extent_npoints(space.get());
  if (n < 0) throw H5::Exception("H5Sget_simple_extent_npoints", "failed");
  std::vector<std::string> out;
  const auto read = [&](hid_t memory_type, void* buffer) {
    Check(is_attribute ? H5Aread(id, memory_type, buffer)
                       : H5Dread(id, memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, buffer),
          "H5Xread");
  };
  const htri_t variable = H5Tis_variable_str(file_type.get());
  Check(variable, "H5Tis_variable_str");
  if (variable > 0) {
    const Handle memory_type(H5Tcopy(H5T_C_S1), H5Tclose, "H5Tcopy");
    Check(H5Tset_size(memory_type.get(), H5T_VARIABLE), "H5Tset_size");
    // HDF5 does not convert between character sets: read in the file's own.
    Check(H5Tset_cset(memory_type.get(), H5Tget_cset(file_type.get())), "H5Tset_cset");
    std::vector<char*> pointers(static_cast<size_t>(n), nullptr);
    if (n > 0) read(memory_type.get(), pointers.data());
    for (char* p : pointers) out.emplace_back(p == nullptr ? "" : p);
    if (n > 0) H5Dvlen_reclaim(memory_type.get(), space.get(), H5P_DEFAULT, pointers.data());
  } else {
    const size_t size = H5Tget_size(file_type.get());
    const Handle memory_type(H5Tcopy(file_type.get()), H5Tclose, "H5Tcopy");
    std::vector<char> buffer(size * static_cast<size_t>(n) + 1, '\0');
    if (n > 0) read(memory_type.get(), buffer.data());
    const bool space_padded = H5Tget_strpad(file_type.get()) == H5T_STR_SPACEPAD;
    for (hssize_t i = 0; i < n; ++i) {
      std::string s(buffer.data() + static_cast<size_t>(i) * size, size);
      s = s.substr(0, s.find('\0'));
      if (space_padded) s = s.substr(0, s.find_last_not_of(' ') + 1);
      out.push_back(s);
    }
  }
  return out;
}

void CheckNumeric(H5T_class_t type_class) {
  if (type_class != H5T_FLOAT && type_class != H5T_INTEGER) {
    throw ReadProblem{"is of " + TypeClassName(type_class) + " type", "float64 numbers"};
  }
}

}  // namespace

// ---- H5Writer -----------------------------------------------------------------------------

struct H5Writer::Impl {
  Impl(const std::string& path, bool sync) : atomic(path, sync) {}

  // Runs HDF5 calls for `object`, turning HDF5's exceptions into std::runtime_error.
  template <typename Body>
  void Run(const std::string& object, Body&& body) {
    H5Lock lock(H5Mutex());
    if (committed || !file) {
      throw std::logic_error("H5Writer: " + atomic.path() + " is already committed or failed");
    }
    try {
      body(*file);
    } catch (const H5::Exception& e) {
      throw std::runtime_error(
          fmt::format("cannot write {} to HDF5 file {}: {}", object, atomic.path(), Describe(e)));
    }
  }

  AtomicFile atomic;  // declared first: removes the temporary after closing it
  std::unique_ptr<H5::H5File> file;
  bool committed = false;
};

H5Writer::H5Writer(const std::string& path, bool sync) {
  H5Lock lock(H5Mutex());
  H5::Exception::dontPrint();
  impl_ = std::make_unique<Impl>(path, sync);
  try {
    try {
      // In memory (the core driver without a backing store): HDF5 never meets a disk error.
      // HDF5 1.10.8 cannot recover from a failed write or close on disk (a full file system):
      // the file's identifier stays half closed and closing it again, at the latest in
      // H5close at exit, is a segmentation fault. Commit() writes the image itself.
      H5::FileAccPropList access;
      access.setCore(kCoreIncrement, false);
      impl_->file = std::make_unique<H5::H5File>(impl_->atomic.temp_path(), H5F_ACC_TRUNC,
                                                 H5::FileCreatPropList::DEFAULT, access);
    } catch (const H5::Exception& e) {
      throw std::runtime_error(
          fmt::format("cannot create HDF5 file {}: {}", impl_->atomic.temp_path(), Describe(e)));
    }
    impl_->Run("/", [](H5::H5File& file) {
      const H5::Group root = file.openGroup("/");
      WriteStringAttr(root, "format", "mbid");
      WriteIntAttr(root, "format_version", kFormatVersion);
    });
  } catch (...) {
    impl_.reset();  // close and remove the temporary while still holding the HDF5 lock
    throw;
  }
}

H5Writer::~H5Writer() {
  H5Lock lock(H5Mutex());
  impl_.reset();
}

void H5Writer::WriteMeasurement(const Measurement& measurement, const std::string& path) {
  measurement.Validate(impl_->atomic.path());
  impl_->Run(path, [&measurement, &path](H5::H5File& file) {
    RemoveIfExists(file, path);
    const H5::Group group = EnsureGroup(file, path);
    WriteStringArrayAttr(group, "channels", measurement.channels);
    WriteDoubleAttr(group, "sample_interval_s", measurement.sample_interval_s);
    WriteStringAttr(group, "source", measurement.source);
    const std::vector<hsize_t> dims = {static_cast<hsize_t>(measurement.samples())};
    const Eigen::VectorXd time = measurement.CalcTime();
    WriteDoubleDataset(file, path, "time", dims, time.data(), "s");
    for (int c = 0; c < measurement.channel_count(); ++c) {
      WriteDoubleDataset(file, path, measurement.channels[c], dims,
                         measurement.values.col(c).data(), measurement.units[c]);
    }
  });
}

void H5Writer::WriteScenarioYaml(const std::string& yaml_text) {
  WriteStringAttribute("/scenario", "yaml", yaml_text);
}

void H5Writer::WriteVector(const std::string& group, const std::string& name,
                           const Eigen::VectorXd& v, const std::string& units) {
  impl_->Run(JoinPath(group, name), [&](H5::H5File& file) {
    WriteDoubleDataset(file, group, name, {static_cast<hsize_t>(v.size())}, v.data(), units);
  });
}

void H5Writer::WriteMatrix(const std::string& group, const std::string& name,
                           const Eigen::MatrixXd& m, const std::string& units) {
  // HDF5 and numpy are row-major; Eigen's default is column-major.
  const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> row_major = m;
  impl_->Run(JoinPath(group, name), [&](H5::H5File& file) {
    WriteDoubleDataset(file, group, name,
                       {static_cast<hsize_t>(m.rows()), static_cast<hsize_t>(m.cols())},
                       row_major.data(), units);
  });
}

void H5Writer::WriteScalar(const std::string& group, const std::string& name, double value,
                           const std::string& units) {
  impl_->Run(JoinPath(group, name),
             [&](H5::H5File& file) { WriteDoubleDataset(file, group, name, {}, &value, units); });
}

void H5Writer::WriteStrings(const std::string& group, const std::string& name,
                            const std::vector<std::string>& values) {
  const std::string path = JoinPath(group, name);
  impl_->Run(path, [&](H5::H5File& file) {
    EnsureGroup(file, group);
    RemoveIfExists(file, path);
    const H5::StrType type = VariableUtf8();
    const hsize_t n = values.size();
    std::vector<const char*> pointers;
    for (const auto& v : values) pointers.push_back(v.c_str());
    H5::DataSet dataset = file.createDataSet(path, type, H5::DataSpace(1, &n));
    if (n > 0) dataset.write(pointers.data(), type);
  });
}

void H5Writer::WriteStringAttribute(const std::string& group, const std::string& name,
                                    const std::string& value) {
  impl_->Run(AttributeField(group, name), [&](H5::H5File& file) {
    if (!ObjectExists(file, group)) EnsureGroup(file, group);
    WriteStringAttr(OpenedObject(file, group).get(), name, value);
  });
}

void H5Writer::WriteDoubleAttribute(const std::string& group, const std::string& name,
                                    double value) {
  impl_->Run(AttributeField(group, name), [&](H5::H5File& file) {
    if (!ObjectExists(file, group)) EnsureGroup(file, group);
    WriteDoubleAttr(OpenedObject(file, group).get(), name, value);
  });
}

void H5Writer::Commit() {
  std::vector<char> image;
  {
    H5Lock lock(H5Mutex());
    impl_->Run("the file", [&image](H5::H5File& file) {
      file.flush(H5F_SCOPE_GLOBAL);
      const ssize_t size = H5Fget_file_image(file.getId(), nullptr, 0);
      if (size < 0) throw H5::FileIException("H5Fget_file_image", "failed");
      image.resize(static_cast<size_t>(size));
      if (H5Fget_file_image(file.getId(), image.data(), image.size()) != size) {
        throw H5::FileIException("H5Fget_file_image", "failed");
      }
      file.close();
    });
    impl_->file.reset();
  }
  internal::WriteWholeFile(impl_->atomic.temp_path(), image);
  impl_->atomic.Commit();
  impl_->committed = true;
}

// ---- H5Reader -----------------------------------------------------------------------------

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
    CheckNumeric(dataset.getTypeClass());
    const H5::DataSpace space = dataset.getSpace();
    const int actual_rank = space.getSimpleExtentNdims();
    if (actual_rank != rank) {
      throw ReadProblem{fmt::format("has {} dimensions", actual_rank),
                        fmt::format("{} dimensions", rank)};
    }
    dims->assign(static_cast<size_t>(rank), 0);
    if (rank > 0) space.getSimpleExtentDims(dims->data());
    std::vector<double> data(static_cast<size_t>(space.getSimpleExtentNpoints()));
    if (!data.empty()) dataset.read(data.data(), H5::PredType::NATIVE_DOUBLE);
    return data;
  }
};

H5Reader::H5Reader(const std::string& path) {
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
    return impl_->ReadNumeric(object, 0, &dims).at(0);
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
  const auto require_attribute = [&](const std::string& object, const std::string& name,
                                     const std::string& expected) {
    if (!HasAttribute(object, name)) {
      throw InputError(path, AttributeField(object, name), "missing", expected);
    }
  };

  require_attribute("/", "format", "format = 'mbid' (an mbid file, docs/interfaces)");
  const std::string format = ReadStringAttribute("/", "format");
  if (format != "mbid") {
    throw InputError(path, AttributeField("/", "format"), "is '" + format + "'", "'mbid'");
  }
  require_attribute("/", "format_version", fmt::format("format_version = {}", kFormatVersion));
  const long long version = ReadIntAttribute("/", "format_version");
  if (version != kFormatVersion) {
    throw InputError(path, AttributeField("/", "format_version"),
                     fmt::format("is {}{}", version,
                                 version > kFormatVersion ? ", newer than this program reads" : ""),
                     fmt::format("{}", kFormatVersion));
  }

  const std::string group = "/measurement";
  if (!Exists(group) ||
      impl_->Run(group, [&] { return impl_->file.childObjType(group); }) != H5O_TYPE_GROUP) {
    throw InputError(path, group, "missing group", "a /measurement group (docs/interfaces)");
  }
  require_attribute(group, "channels", "the channel names as a string array");
  Measurement m;
  m.channels = ReadStringArrayAttribute(group, "channels");
  const std::string channels_field = AttributeField(group, "channels");
  if (m.channels.empty()) {
    throw InputError(path, channels_field, "lists no channels", "at least one channel name");
  }
  std::set<std::string> seen;
  for (const auto& channel : m.channels) {
    if (channel.empty() || channel == "time" || channel.find('/') != std::string::npos) {
      throw InputError(path, channels_field, "invalid channel name '" + channel + "'",
                       "non-empty names other than 'time', without '/'");
    }
    if (!seen.insert(channel).second) {
      throw InputError(path, channels_field, "channel '" + channel + "' is listed twice",
                       "unique channel names");
    }
  }
  require_attribute(group, "sample_interval_s", "the sample interval in seconds");
  const double interval = ReadDoubleAttribute(group, "sample_interval_s");
  if (HasAttribute(group, "source")) m.source = ReadStringAttribute(group, "source");

  const std::string time_path = group + "/time";
  if (!Exists(time_path)) {
    throw InputError(path, time_path, "missing dataset", "the sample times in seconds");
  }
  const Eigen::VectorXd time = ReadVector(group, "time");
  require_attribute(time_path, "units", "units = 's'");
  const std::string time_units = ReadUnits(group, "time");
  if (time_units != "s") {
    throw InputError(path, AttributeField(time_path, "units"), "is '" + time_units + "'", "'s'");
  }
  const Eigen::Index n = time.size();
  if (n < 2) {
    throw InputError(path, time_path, fmt::format("has {} samples", n), "at least 2 samples");
  }

  m.values.resize(n, static_cast<Eigen::Index>(m.channels.size()));
  for (size_t c = 0; c < m.channels.size(); ++c) {
    const std::string object = JoinPath(group, m.channels[c]);
    if (!Exists(object)) {
      throw InputError(
          path, object,
          "missing dataset for channel '" + m.channels[c] + "' (listed in " + channels_field + ")",
          "one dataset per channel");
    }
    const Eigen::VectorXd v = ReadVector(group, m.channels[c]);
    if (v.size() != n) {
      throw InputError(path, object, fmt::format("has {} samples", v.size()),
                       fmt::format("{} samples like {}", n, time_path));
    }
    require_attribute(object, "units", "a units string such as 'rad'");
    m.units.push_back(ReadUnits(group, m.channels[c]));
    for (Eigen::Index j = 0; j < n; ++j) {
      if (!std::isfinite(v[j])) {
        throw InputError(path, object,
                         fmt::format("sample {} (t = {} s) is {}", j, time[j],
                                     std::isnan(v[j]) ? "NaN" : (v[j] > 0 ? "+Inf" : "-Inf")),
                         "finite values");
      }
    }
    m.values.col(static_cast<Eigen::Index>(c)) = v;
  }

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

Measurement ReadMeasurementH5(const std::string& path) { return H5Reader(path).ReadMeasurement(); }

std::string ReadScenarioYaml(const std::string& path) { return H5Reader(path).ReadScenarioYaml(); }

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
