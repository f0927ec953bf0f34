// H5Writer: mbid's HDF5 files, built in memory and written atomically (docs/file-formats.md).
#include <H5Cpp.h>
#include <fmt/format.h>

#include <algorithm>
#include <optional>
#include <set>
#include <stdexcept>

#include "hdf5_internal.h"
#include "internal.h"
#include "mbid/common/atomic_file.h"
#include "mbid/common/error.h"
#include "mbid/common/hdf5_io.h"

namespace mbid {
using internal::AttributeField;
using internal::Describe;
using internal::H5Lock;
using internal::H5Mutex;
using internal::JoinPath;
using internal::kH5FormatVersion;
using internal::OpenedObject;
using internal::PathPrefixes;
using internal::VariableUtf8;

namespace {

// Long vectors (recorded channels) are chunked and compressed; short results stay contiguous.
constexpr hsize_t kChunkThreshold = 4096;
constexpr hsize_t kChunkSize = 65536;  // 512 KiB of doubles: inside HDF5's default chunk cache.
constexpr int kDeflateLevel = 4;       // Most of level 9's gain on smooth signals, much faster.
constexpr size_t kCoreIncrement = 1 << 20;  // in-memory file growth: 1 MiB, few reallocations

// The objects a writer has created. Its file starts empty (H5F_ACC_TRUNC) and nothing else
// writes to it, so whether a path exists is answered here rather than by HDF5's lookups by
// path, which were a third of the time a campaign case spent on its file (85 datasets).
class ObjectIndex {
 public:
  bool IsGroup(const std::string& path) const { return groups_.count(path) > 0; }
  bool IsDataset(const std::string& path) const { return datasets_.count(path) > 0; }
  void AddGroup(const std::string& path) { groups_.insert(path); }
  void AddDataset(const std::string& path) { datasets_.insert(path); }
  // Forgets `path` and everything under it.
  void Remove(const std::string& path) {
    for (std::set<std::string>* set : {&groups_, &datasets_}) {
      set->erase(path);
      const std::string prefix = path + "/";
      for (auto it = set->lower_bound(prefix); it != set->end() && it->rfind(prefix, 0) == 0;) {
        it = set->erase(it);
      }
    }
  }

 private:
  std::set<std::string> groups_{"/"};
  std::set<std::string> datasets_;
};

// Objects are created without modification times (HDF5 stores them by default): the same
// content gives the same bytes, and a campaign can copy its case files into one file with
// H5Ocopy and still get the same bytes for any number of workers (h5_merge.h).
void Untimed(hid_t properties) {
  internal::Check(H5Pset_obj_track_times(properties, 0), "H5Pset_obj_track_times");
}

const H5::DSetCreatPropList& UntimedDataset() {
  // Never destroyed: a property list closed after HDF5 shut down at exit would be an error.
  static const H5::DSetCreatPropList* const list = [] {
    auto* created = new H5::DSetCreatPropList;
    Untimed(created->getId());
    return created;
  }();
  return *list;
}

void EnsureGroup(H5::H5File& file, ObjectIndex& index, const std::string& path) {
  for (const std::string& prefix : PathPrefixes(path)) {
    if (index.IsGroup(prefix)) continue;
    if (index.IsDataset(prefix)) {
      throw H5::Exception("EnsureGroup", prefix + " exists and is not a group");
    }
    const internal::Handle properties(H5Pcreate(H5P_GROUP_CREATE), H5Pclose, "H5Pcreate");
    Untimed(properties.get());
    const internal::Handle group(
        H5Gcreate2(file.getId(), prefix.c_str(), H5P_DEFAULT, properties.get(), H5P_DEFAULT),
        H5Gclose, "H5Gcreate2");
    index.AddGroup(prefix);
  }
}

void RemoveIfExists(H5::H5File& file, ObjectIndex& index, const std::string& path) {
  if (PathPrefixes(path).empty() || !(index.IsGroup(path) || index.IsDataset(path))) return;
  file.unlink(path);
  index.Remove(path);
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

void WriteDoubleDataset(H5::H5File& file, ObjectIndex& index, const std::string& group,
                        const std::string& name, const std::vector<hsize_t>& dims,
                        const double* data, const std::string& units) {
  EnsureGroup(file, index, group);
  const std::string path = JoinPath(group, name);
  RemoveIfExists(file, index, path);
  hsize_t count = 1;
  for (hsize_t d : dims) count *= d;
  // Short datasets share one (contiguous) property list.
  std::optional<H5::DSetCreatPropList> chunked;
  if (dims.size() == 1 && count >= kChunkThreshold) {
    chunked.emplace();
    Untimed(chunked->getId());
    const hsize_t chunk = std::min(count, kChunkSize);
    chunked->setChunk(1, &chunk);
    if (H5Zfilter_avail(H5Z_FILTER_DEFLATE) > 0) {
      chunked->setShuffle();
      chunked->setDeflate(kDeflateLevel);
    }
  }
  const H5::DSetCreatPropList& properties = chunked ? *chunked : UntimedDataset();
  const H5::DataSpace space = dims.empty()
                                  ? H5::DataSpace(H5S_SCALAR)
                                  : H5::DataSpace(static_cast<int>(dims.size()), dims.data());
  H5::DataSet dataset = file.createDataSet(path, H5::PredType::IEEE_F64LE, space, properties);
  index.AddDataset(path);
  if (count > 0) dataset.write(data, H5::PredType::NATIVE_DOUBLE);
  if (!units.empty()) WriteStringAttr(dataset, "units", units);
}

}  // namespace

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
  ObjectIndex index;
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
      H5::FileCreatPropList creation;
      Untimed(creation.getId());  // the root group
      impl_->file =
          std::make_unique<H5::H5File>(impl_->atomic.temp_path(), H5F_ACC_TRUNC, creation, access);
    } catch (const H5::Exception& e) {
      throw std::runtime_error(
          fmt::format("cannot create HDF5 file {}: {}", impl_->atomic.temp_path(), Describe(e)));
    }
    impl_->Run("/", [](H5::H5File& file) {
      const H5::Group root = file.openGroup("/");
      WriteStringAttr(root, "format", "mbid");
      WriteIntAttr(root, "format_version", kH5FormatVersion);
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
  ObjectIndex& index = impl_->index;
  impl_->Run(path, [&measurement, &path, &index](H5::H5File& file) {
    RemoveIfExists(file, index, path);
    EnsureGroup(file, index, path);
    const H5::Group group = file.openGroup(path);
    WriteStringArrayAttr(group, "channels", measurement.channels);
    WriteDoubleAttr(group, "sample_interval_s", measurement.sample_interval_s);
    WriteStringAttr(group, "source", measurement.source);
    const std::vector<hsize_t> dims = {static_cast<hsize_t>(measurement.samples())};
    const Eigen::VectorXd time = measurement.CalcTime();
    WriteDoubleDataset(file, index, path, "time", dims, time.data(), "s");
    for (int c = 0; c < measurement.channel_count(); ++c) {
      WriteDoubleDataset(file, index, path, measurement.channels[c], dims,
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
    WriteDoubleDataset(file, impl_->index, group, name, {static_cast<hsize_t>(v.size())}, v.data(),
                       units);
  });
}

void H5Writer::WriteMatrix(const std::string& group, const std::string& name,
                           const Eigen::MatrixXd& m, const std::string& units) {
  // HDF5 and numpy are row-major; Eigen's default is column-major.
  const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> row_major = m;
  impl_->Run(JoinPath(group, name), [&](H5::H5File& file) {
    WriteDoubleDataset(file, impl_->index, group, name,
                       {static_cast<hsize_t>(m.rows()), static_cast<hsize_t>(m.cols())},
                       row_major.data(), units);
  });
}

void H5Writer::WriteScalar(const std::string& group, const std::string& name, double value,
                           const std::string& units) {
  impl_->Run(JoinPath(group, name), [&](H5::H5File& file) {
    WriteDoubleDataset(file, impl_->index, group, name, {}, &value, units);
  });
}

void H5Writer::WriteStrings(const std::string& group, const std::string& name,
                            const std::vector<std::string>& values) {
  const std::string path = JoinPath(group, name);
  impl_->Run(path, [&](H5::H5File& file) {
    EnsureGroup(file, impl_->index, group);
    RemoveIfExists(file, impl_->index, path);
    const H5::StrType type = VariableUtf8();
    const hsize_t n = values.size();
    std::vector<const char*> pointers;
    for (const auto& v : values) pointers.push_back(v.c_str());
    H5::DataSet dataset = file.createDataSet(path, type, H5::DataSpace(1, &n), UntimedDataset());
    impl_->index.AddDataset(path);
    if (n > 0) {
      dataset.write(pointers.data(), type, H5::DataSpace::ALL, H5::DataSpace::ALL,
                    internal::SizedTransfer(n));
    }
  });
}

void H5Writer::WriteStringAttribute(const std::string& group, const std::string& name,
                                    const std::string& value) {
  impl_->Run(AttributeField(group, name), [&](H5::H5File& file) {
    if (!impl_->index.IsDataset(group)) EnsureGroup(file, impl_->index, group);
    WriteStringAttr(OpenedObject(file, group).get(), name, value);
  });
}

void H5Writer::WriteDoubleAttribute(const std::string& group, const std::string& name,
                                    double value) {
  impl_->Run(AttributeField(group, name), [&](H5::H5File& file) {
    if (!impl_->index.IsDataset(group)) EnsureGroup(file, impl_->index, group);
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

}  // namespace mbid
