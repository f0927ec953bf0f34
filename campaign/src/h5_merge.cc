#include "h5_merge.h"

#include <hdf5.h>

#include <algorithm>
#include <stdexcept>

namespace mbid::campaign::internal {
namespace {

// An HDF5 identifier closed on scope exit.
class Id {
 public:
  Id(hid_t id, herr_t (*close)(hid_t), const std::string& what) : id_(id), close_(close) {
    if (id_ < 0) throw std::runtime_error("HDF5: " + what + " failed");
  }
  ~Id() {
    if (id_ >= 0) close_(id_);
  }
  Id(const Id&) = delete;
  Id& operator=(const Id&) = delete;
  hid_t get() const { return id_; }
  void Close() {
    const hid_t id = id_;
    id_ = -1;
    if (close_(id) < 0) throw std::runtime_error("HDF5: closing failed");
  }

 private:
  hid_t id_;
  herr_t (*close_)(hid_t);
};

void Check(herr_t status, const std::string& what) {
  if (status < 0) throw std::runtime_error("HDF5: " + what + " failed");
}

// Link or attribute names of an object in increasing name order (HDF5's name index).
herr_t CollectLink(hid_t, const char* name, const H5L_info_t*, void* names) {
  static_cast<std::vector<std::string>*>(names)->push_back(name);
  return 0;
}
herr_t CollectAttribute(hid_t, const char* name, const H5A_info_t*, void* names) {
  static_cast<std::vector<std::string>*>(names)->push_back(name);
  return 0;
}

// Values are read and written in the file's own type: bytes go through unconverted.
// Variable-length data (strings) come back as pointers that HDF5 allocated.
struct Buffer {
  Buffer(hid_t type, hid_t space, const std::string& what)
      : type_(type),
        space_(space),
        variable_(H5Tdetect_class(type, H5T_VLEN) > 0 || H5Tis_variable_str(type) > 0) {
    const hssize_t points = H5Sget_simple_extent_npoints(space);
    if (points < 0) throw std::runtime_error("HDF5: extent of " + what + " failed");
    points_ = static_cast<size_t>(points);
    bytes_.assign(points_ * H5Tget_size(type) + 1, 0);
  }
  ~Buffer() {
    if (variable_ && filled_) H5Dvlen_reclaim(type_, space_, H5P_DEFAULT, bytes_.data());
  }
  void* data() { return bytes_.data(); }
  size_t points() const { return points_; }
  void MarkFilled() { filled_ = true; }

 private:
  hid_t type_, space_;
  bool variable_;
  bool filled_ = false;
  size_t points_ = 0;
  std::vector<unsigned char> bytes_;
};

void CopyAttributes(hid_t source, hid_t target, const std::vector<std::string>& skip,
                    const std::string& where) {
  std::vector<std::string> names;
  Check(H5Aiterate2(source, H5_INDEX_NAME, H5_ITER_INC, nullptr, CollectAttribute, &names),
        "listing attributes of " + where);
  for (const std::string& name : names) {
    if (std::find(skip.begin(), skip.end(), name) != skip.end()) continue;
    const std::string what = where + " attribute " + name;
    const Id attribute(H5Aopen(source, name.c_str(), H5P_DEFAULT), H5Aclose, "opening " + what);
    const Id type(H5Aget_type(attribute.get()), H5Tclose, "type of " + what);
    const Id space(H5Aget_space(attribute.get()), H5Sclose, "space of " + what);
    Buffer buffer(type.get(), space.get(), what);
    Check(H5Aread(attribute.get(), type.get(), buffer.data()), "reading " + what);
    buffer.MarkFilled();
    if (H5Aexists(target, name.c_str()) > 0) Check(H5Adelete(target, name.c_str()), what);
    const Id copy(
        H5Acreate2(target, name.c_str(), type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT),
        H5Aclose, "creating " + what);
    Check(H5Awrite(copy.get(), type.get(), buffer.data()), "writing " + what);
  }
}

hid_t CreateGroupWithoutTimes(hid_t parent, const std::string& name, const std::string& where) {
  const Id properties(H5Pcreate(H5P_GROUP_CREATE), H5Pclose, "group properties");
  Check(H5Pset_obj_track_times(properties.get(), 0), "group properties");
  const hid_t group = H5Gcreate2(parent, name.c_str(), H5P_DEFAULT, properties.get(), H5P_DEFAULT);
  if (group < 0) throw std::runtime_error("HDF5: creating group " + where + " failed");
  return group;
}

// Each object under `source` (in name order) with everything beneath it, by HDF5's own object
// copy: the bytes follow from the source's, which H5Writer writes without modification times.
// Reading and re-creating every dataset and attribute took three times as long.
void CopyChildren(hid_t source, hid_t target, const std::string& where) {
  std::vector<std::string> names;
  Check(H5Literate(source, H5_INDEX_NAME, H5_ITER_INC, nullptr, CollectLink, &names),
        "listing " + where);
  for (const std::string& name : names) {
    const std::string path = where == "/" ? "/" + name : where + "/" + name;
    Check(H5Ocopy(source, name.c_str(), target, name.c_str(), H5P_DEFAULT, H5P_DEFAULT),
          "copying " + path);
  }
}

}  // namespace

struct DeterministicH5File::Impl {
  std::string path;
  hid_t file = -1;
};

DeterministicH5File::DeterministicH5File(const std::string& path)
    : impl_(std::make_unique<Impl>()) {
  impl_->path = path;
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  const Id properties(H5Pcreate(H5P_FILE_CREATE), H5Pclose, "file properties");
  Check(H5Pset_obj_track_times(properties.get(), 0), "file properties");
  impl_->file = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, properties.get(), H5P_DEFAULT);
  if (impl_->file < 0) throw std::runtime_error("cannot create HDF5 file " + path);
}

DeterministicH5File::~DeterministicH5File() {
  if (impl_->file >= 0) H5Fclose(impl_->file);
}

void DeterministicH5File::CreateGroup(const std::string& group) {
  const size_t slash = group.find_last_of('/');
  const std::string parent = slash == 0 ? "/" : group.substr(0, slash);
  const Id parent_id(H5Gopen2(impl_->file, parent.c_str(), H5P_DEFAULT), H5Gclose,
                     "opening " + parent + " in " + impl_->path);
  Id(CreateGroupWithoutTimes(parent_id.get(), group.substr(slash + 1), group), H5Gclose, group);
}

void DeterministicH5File::CopyTree(const std::string& source, const std::string& group,
                                   const std::vector<std::string>& skip_root_attributes) {
  try {
    // Read whole into memory (a case file is a few hundred kB): one read instead of HDF5's
    // many small ones.
    const Id access(H5Pcreate(H5P_FILE_ACCESS), H5Pclose, "file access properties");
    Check(H5Pset_fapl_core(access.get(), 1 << 20, 0), "file access properties");
    const Id input(H5Fopen(source.c_str(), H5F_ACC_RDONLY, access.get()), H5Fclose,
                   "opening " + source);
    const Id root(H5Gopen2(input.get(), "/", H5P_DEFAULT), H5Gclose, "root of " + source);
    if (group != "/" && H5Lexists(impl_->file, group.c_str(), H5P_DEFAULT) <= 0) {
      CreateGroup(group);
    }
    const Id target(H5Gopen2(impl_->file, group.c_str(), H5P_DEFAULT), H5Gclose,
                    "opening " + group);
    CopyAttributes(root.get(), target.get(), skip_root_attributes, group);
    CopyChildren(root.get(), target.get(), group);
  } catch (const std::runtime_error& error) {
    throw std::runtime_error("copying " + source + " into " + impl_->path + ": " + error.what());
  }
}

void DeterministicH5File::Close() {
  const hid_t file = impl_->file;
  impl_->file = -1;
  Check(H5Fclose(file), "closing " + impl_->path);
}

}  // namespace mbid::campaign::internal
