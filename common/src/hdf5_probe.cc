// The child process that reads a whole HDF5 file first, so that a libhdf5 crash is an InputError.
#include <H5Cpp.h>

#include <string>
#include <vector>

#include "hdf5_internal.h"
#include "hdf5_reader_impl.h"
#include "internal.h"

namespace mbid {
using internal::Handle;
using internal::ReadNumericData;
using internal::ReadProblem;
using internal::ReadStringData;

namespace {

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

}  // namespace mbid
