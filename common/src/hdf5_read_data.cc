// The raw reads of an HDF5 attribute's or dataset's strings and numbers, sizes checked first.
#include <H5Cpp.h>
#include <fmt/format.h>

#include <string>
#include <vector>

#include "hdf5_internal.h"
#include "hdf5_reader_impl.h"
#include "mbid/common/utf8.h"

namespace mbid::internal {
namespace {

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

}  // namespace

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
    Check(is_attribute
              ? H5Aread(id, memory_type, buffer)
              : H5Dread(id, memory_type, H5S_ALL, H5S_ALL, SizedTransfer(n).getId(), buffer),
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

}  // namespace mbid::internal
