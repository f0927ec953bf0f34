#pragma once

// What the HDF5 writer and reader share: the library lock, error texts, paths and objects.
// Not part of the public API.

#include <H5Cpp.h>

#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace mbid::internal {

inline constexpr char kExpectedH5[] = "an mbid HDF5 measurement file (docs/interfaces)";
inline constexpr int kH5FormatVersion = 1;

// The serial HDF5 library is not thread-safe; every call goes through this lock.
std::recursive_mutex& H5Mutex();
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

// Throws H5::Exception(what) for a negative status.
void Check(herr_t status, const char* what);

// A dataset transfer property list whose conversion buffers fit `elements` values. HDF5's
// default is 1 MiB, allocated at every read or write that converts and zeroed for
// variable-length strings: 12% of a campaign's instructions, whose case files hold many short
// string datasets.
H5::DSetMemXferPropList SizedTransfer(hsize_t elements);

// The C++ exception names the API call; the error stack says why (e.g. "file signature not
// found"). Automatic printing is off, so the stack is still there.
std::string Describe(const H5::Exception& e);

std::string JoinPath(const std::string& group, const std::string& name);
std::string AttributeField(const std::string& object, const std::string& name);
// "/a/b/c" -> "/a", "/a/b", "/a/b/c"; empty for the root.
std::vector<std::string> PathPrefixes(const std::string& path);

// Whether `path` exists, without HDF5 errors for missing or non-group intermediates.
bool ObjectExists(const H5::H5File& file, const std::string& path);
H5O_type_t ObjectType(const H5::H5File& file, const std::string& path);

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

// Variable-length UTF-8 strings, as mbid writes them.
H5::StrType VariableUtf8();

}  // namespace mbid::internal
