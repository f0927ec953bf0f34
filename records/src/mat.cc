// MATLAB .mat files (v5 and the HDF5-based v7.3) through matio: the layouts of
// docs/records-formats.md in, mbid's own layout out. This file: the helpers the reader and
// writer share, and the reader's file and variables (mat_internal.h has the reader's class).

#include <fmt/format.h>
#include <matio.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "mat_internal.h"
#include "mbid/common/error.h"
#include "mbid/records/records.h"
#include "raw_table.h"
#include "text_util.h"

namespace mbid::records {
namespace internal {
namespace {

// The log function SilenceMatio installs: matio's messages are not printed.
void SilentLog(int /*level*/, char* /*message*/) {}

}  // namespace

std::string Printable(const std::string& text) {
  std::string out;
  for (char ch : text.substr(0, 64)) out += (ch >= 32 && ch < 127) ? ch : '?';
  return text.size() > 64 ? out + "..." : out;
}

void SilenceMatio() {
  static std::once_flag once;
  std::call_once(once, [] { Mat_LogInitFunc("mbid", SilentLog); });
}

bool IsNumericClass(matio_classes c) {
  switch (c) {
    case MAT_C_DOUBLE:
    case MAT_C_SINGLE:
    case MAT_C_INT8:
    case MAT_C_UINT8:
    case MAT_C_INT16:
    case MAT_C_UINT16:
    case MAT_C_INT32:
    case MAT_C_UINT32:
    case MAT_C_INT64:
    case MAT_C_UINT64:
      return true;
    default:
      return false;
  }
}

const char* ClassName(matio_classes c) {
  switch (c) {
    case MAT_C_EMPTY:
      return "empty";
    case MAT_C_CELL:
      return "cell";
    case MAT_C_STRUCT:
      return "struct";
    case MAT_C_OBJECT:
      return "object";
    case MAT_C_CHAR:
      return "char";
    case MAT_C_SPARSE:
      return "sparse";
    case MAT_C_DOUBLE:
      return "double";
    case MAT_C_SINGLE:
      return "single";
    case MAT_C_INT8:
      return "int8";
    case MAT_C_UINT8:
      return "uint8";
    case MAT_C_INT16:
      return "int16";
    case MAT_C_UINT16:
      return "uint16";
    case MAT_C_INT32:
      return "int32";
    case MAT_C_UINT32:
      return "uint32";
    case MAT_C_INT64:
      return "int64";
    case MAT_C_UINT64:
      return "uint64";
    case MAT_C_FUNCTION:
      return "function handle";
    case MAT_C_OPAQUE:
      return "opaque";
  }
  return "unknown";
}

VarInfo InfoOf(const matvar_t& var, const std::string& name) {
  VarInfo info;
  info.name = name;
  info.class_type = var.class_type;
  info.complex = var.isComplex != 0;
  info.logical = var.isLogical != 0;
  info.compressed = var.compression != MAT_COMPRESSION_NONE;
  info.elements = 1;
  if (var.rank > 0 && var.dims != nullptr) {
    for (int d = 0; d < var.rank && d < 64; ++d) {
      info.dims.push_back(var.dims[d]);
      info.elements *= static_cast<double>(var.dims[d]);
    }
  } else {
    info.elements = 0;
  }
  // MATLAB writes no trailing singleton dimensions; drop any all the same.
  while (info.dims.size() > 2 && info.dims.back() == 1) info.dims.pop_back();
  return info;
}

RawTable MatReader::Read() {
  SilenceMatio();
  ReadHead();
  CheckV5Structure();
  mat_.reset(Mat_Open(path_.c_str(), MAT_ACC_RDONLY));
  if (!mat_) {
    throw InputError(path_, "", "not a MAT file matio can open", kMatFile);
  }
  if (Mat_GetVersion(mat_.get()) == MAT_FT_MAT4) {
    throw InputError(path_, "", "a MATLAB v4 file (or not a MAT file at all)", kMatFile);
  }
  ReadDirectory();
  if (infos_.count("mbid_layout")) return ReadMbidLayout();
  return ReadLabLayout();
}

InputError MatReader::VarError(const std::string& name, const std::string& problem,
                               const std::string& expected) const {
  return InputError(path_, "variable " + Printable(name), problem, expected);
}

// The first bytes, read plainly, so that a missing or unreadable file is an InputError
// like the other readers' (matio would only say NULL); also the file size for bounds.
void MatReader::ReadHead() {
  std::FILE* file = std::fopen(path_.c_str(), "rb");
  if (file == nullptr) {
    throw InputError(path_, "", std::string("cannot open: ") + std::strerror(errno), kMatFile);
  }
  char head[128];
  const size_t n = std::fread(head, 1, sizeof(head), file);
  const bool failed = std::ferror(file) != 0;
  const int error = errno;
  std::fseek(file, 0, SEEK_END);
  const long size = std::ftell(file);
  std::fclose(file);
  if (failed) {
    throw InputError(path_, "", std::string("cannot read: ") + std::strerror(error), kMatFile);
  }
  if (n < 128) {
    throw InputError(path_, "", fmt::format("{} bytes, shorter than a MAT header", n), kMatFile);
  }
  file_size_ = size > 0 ? static_cast<double>(size) : 0.0;
}

// Every variable's header (class, dimensions), without data.
void MatReader::ReadDirectory() {
  while (true) {
    MatVar var(Mat_VarReadNextInfo(mat_.get()));
    if (!var) break;
    if (order_.size() >= 100000) {
      throw InputError(path_, "", "more than 100000 variables", kMatFile);
    }
    const std::string name = var->name != nullptr ? var->name : "";
    if (name.empty() || infos_.count(name)) continue;
    VarInfo info = InfoOf(*var, name);
    if (info.class_type == MAT_C_EMPTY && info.elements > 0 &&
        Mat_GetVersion(mat_.get()) == MAT_FT_MAT73) {
      RecoverV73Class(&info);
    }
    if (info.numeric() && info.dims.size() > 2) {
      throw VarError(name,
                     fmt::format("a {}-dimensional array ({})", info.dims.size(), info.Shape()),
                     "vectors or a 2-D matrix (samples x columns)");
    }
    order_.push_back(name);
    infos_[name] = std::move(info);
  }
  if (order_.empty()) {
    throw InputError(path_, "", "no variables could be read", kMatFile);
  }
}

// matio reads a v7.3 variable's MATLAB_class only when the string is null-terminated; h5py
// (hdf5storage) writes it null-padded, which matio takes for an empty array of the stated size.
// Such a numeric variable is read through HDF5, as MATLAB would.
void MatReader::RecoverV73Class(VarInfo* info) {
  static const std::map<std::string, matio_classes> classes = {
      {"double", MAT_C_DOUBLE}, {"single", MAT_C_SINGLE}, {"int8", MAT_C_INT8},
      {"uint8", MAT_C_UINT8},   {"int16", MAT_C_INT16},   {"uint16", MAT_C_UINT16},
      {"int32", MAT_C_INT32},   {"uint32", MAT_C_UINT32}, {"int64", MAT_C_INT64},
      {"uint64", MAT_C_UINT64}};
  if (!h5_) h5_ = std::make_unique<H5Reader>(path_);
  const std::string object = "/" + info->name;
  if (!h5_->Exists(object) || !h5_->HasAttribute(object, "MATLAB_class")) return;
  std::string name = h5_->ReadStringAttribute(object, "MATLAB_class");
  name.erase(std::find(name.begin(), name.end(), '\0'), name.end());
  const auto known = classes.find(name);
  if (known == classes.end()) return;
  info->class_type = known->second;
  info->through_hdf5 = true;
}

// A whole variable; its size is checked against the file before matio allocates it.
MatVar MatReader::Load(const VarInfo& info) {
  if (info.through_hdf5) {
    // HDF5's row-major (columns, rows) is MATLAB's column-major (rows, columns).
    const Eigen::MatrixXd stored = h5_->ReadMatrix("/", info.name);
    const Eigen::MatrixXd column_major = stored.transpose();
    if (static_cast<double>(column_major.size()) != info.elements || info.dims.size() != 2) {
      throw VarError(
          info.name,
          fmt::format("{} numbers where its header says {}", column_major.size(), info.Shape()),
          "a complete numeric array");
    }
    size_t dims[2] = {info.dims[0], info.dims[1]};
    // Mat_VarCreate copies the data (no MAT_F_DONT_COPY_DATA).
    MatVar var(Mat_VarCreate(info.name.c_str(), MAT_C_DOUBLE, MAT_T_DOUBLE, 2, dims,
                             const_cast<double*>(column_major.data()), 0));
    if (!var) throw VarError(info.name, "its data cannot be read", "a complete variable");
    return var;
  }
  // Every element of an uncompressed v5 variable takes at least a byte of the file (a cell's
  // or struct's at least an 8-byte tag).
  const bool container = info.class_type == MAT_C_CELL || info.class_type == MAT_C_STRUCT;
  const double bytes =
      info.elements * (container ? 8.0 : std::max<double>(1, Mat_SizeOfClass(info.class_type)));
  if (info.elements > static_cast<double>(kMaxSamples) * 16 ||
      (!info.compressed && Mat_GetVersion(mat_.get()) == MAT_FT_MAT5 && bytes > file_size_)) {
    throw VarError(info.name,
                   fmt::format("{} elements declared ({}) in a file of {} bytes", info.elements,
                               info.Shape(), file_size_),
                   "no more data than the file holds");
  }
  MatVar var(Mat_VarRead(mat_.get(), info.name.c_str()));
  if (!var) throw VarError(info.name, "its data cannot be read", "a complete variable");
  return var;
}

// A real numeric array's elements as doubles, column-major.
std::vector<double> MatReader::Doubles(const matvar_t& var, const std::string& name) const {
  const VarInfo info = InfoOf(var, name);
  if (!info.numeric() || info.complex) {
    throw VarError(name,
                   fmt::format("a {}{}", info.complex ? "complex " : "",
                               info.logical ? "logical array" : info.Shape()),
                   "a real numeric array (double, single or integer)");
  }
  const size_t n = static_cast<size_t>(info.elements);
  if (var.data == nullptr && n > 0) {
    throw VarError(name, "no data", "a complete numeric array");
  }
  std::vector<double> out(n);
  const auto convert = [&](auto* typed) {
    for (size_t i = 0; i < n; ++i) out[i] = static_cast<double>(typed[i]);
  };
  switch (var.class_type) {
    case MAT_C_DOUBLE:
      convert(static_cast<const double*>(var.data));
      break;
    case MAT_C_SINGLE:
      convert(static_cast<const float*>(var.data));
      break;
    case MAT_C_INT8:
      convert(static_cast<const std::int8_t*>(var.data));
      break;
    case MAT_C_UINT8:
      convert(static_cast<const std::uint8_t*>(var.data));
      break;
    case MAT_C_INT16:
      convert(static_cast<const std::int16_t*>(var.data));
      break;
    case MAT_C_UINT16:
      convert(static_cast<const std::uint16_t*>(var.data));
      break;
    case MAT_C_INT32:
      convert(static_cast<const std::int32_t*>(var.data));
      break;
    case MAT_C_UINT32:
      convert(static_cast<const std::uint32_t*>(var.data));
      break;
    case MAT_C_INT64:
      convert(static_cast<const std::int64_t*>(var.data));
      break;
    case MAT_C_UINT64:
      convert(static_cast<const std::uint64_t*>(var.data));
      break;
    default:
      break;
  }
  return out;
}

double MatReader::Scalar(const std::string& name) {
  const VarInfo& info = infos_.at(name);
  if (!info.numeric() || !info.scalar() || info.complex) {
    throw VarError(name, fmt::format("a {}", info.Shape()), "a real number (1x1 numeric)");
  }
  const MatVar var = Load(info);
  const double value = Doubles(*var, name)[0];
  if (!std::isfinite(value)) {
    throw VarError(name, fmt::format("{}", value), "a finite number");
  }
  return value;
}

// A char row (or a char matrix's rows, trailing blanks trimmed).
std::vector<std::string> MatReader::CharRows(const matvar_t& var, const std::string& name) const {
  const VarInfo info = InfoOf(var, name);
  if (info.class_type != MAT_C_CHAR || info.dims.size() != 2) {
    throw VarError(name, fmt::format("a {}", info.Shape()), "text (a char array)");
  }
  const size_t rows = info.dims[0], cols = info.dims[1];
  if (info.elements == 0) return std::vector<std::string>(rows == 1 ? 1 : 0);  // '' or none
  const size_t width = var.data_type == MAT_T_UINT16 || var.data_type == MAT_T_UTF16 ? 2 : 1;
  // The characters matio holds bound the rows and columns (hostile dims otherwise).
  if (var.data == nullptr || var.data_type == MAT_T_UTF32 ||
      static_cast<double>(var.nbytes) < info.elements * static_cast<double>(width)) {
    throw VarError(name, "unreadable characters", "text in ASCII or UTF-8/16");
  }
  std::vector<std::string> out(rows);
  for (size_t r = 0; r < rows; ++r) {
    for (size_t k = 0; k < cols; ++k) {
      const size_t i = r + k * rows;
      unsigned code = 0;
      if (width == 2) {
        std::uint16_t unit = 0;
        std::memcpy(&unit, static_cast<const char*>(var.data) + 2 * i, 2);
        code = unit;
      } else {
        code = static_cast<const unsigned char*>(var.data)[i];
      }
      out[r] += code < 256 ? static_cast<char>(code) : '?';
    }
    out[r] = TrimText(out[r]);
  }
  return out;
}

// Names or units: a cell array of char rows, or a char matrix (one per row).
std::vector<std::string> MatReader::Strings(const matvar_t& var, const std::string& name) const {
  if (var.class_type == MAT_C_CHAR) {
    if (var.rank == 2 && var.dims[0] == 1) return {CharRows(var, name)[0]};  // one name
    return CharRows(var, name);
  }
  if (var.class_type != MAT_C_CELL) {
    throw VarError(name, fmt::format("a {}", InfoOf(var, name).Shape()),
                   "a cell array of text or a char matrix");
  }
  const VarInfo info = InfoOf(var, name);
  std::vector<std::string> out;
  for (size_t i = 0; i < static_cast<size_t>(info.elements); ++i) {
    matvar_t* cell = Mat_VarGetCell(const_cast<matvar_t*>(&var), static_cast<int>(i));
    const std::string where = fmt::format("{}{{{}}}", name, i + 1);
    if (cell == nullptr) throw VarError(where, "an unreadable cell", "text");
    const std::vector<std::string> rows = CharRows(*cell, where);
    if (rows.size() > 1) throw VarError(where, "several rows of text", "one name per cell");
    out.push_back(rows.empty() ? std::string() : rows[0]);
  }
  return out;
}

std::vector<std::string> MatReader::StringsVar(const std::string& name) {
  const MatVar var = Load(infos_.at(name));
  return Strings(*var, name);
}

std::vector<double> MatReader::VectorVar(const std::string& name, size_t length) {
  const VarInfo& info = infos_.at(name);
  if (!info.numeric() || info.vector_length() == 0) {
    throw VarError(name, fmt::format("a {}", info.Shape()), "a numeric vector of samples");
  }
  if (length != 0 && info.vector_length() != length) {
    throw VarError(name, fmt::format("{} samples", info.vector_length()),
                   fmt::format("{} samples like the other vectors", length));
  }
  const MatVar var = Load(info);
  return Doubles(*var, name);
}

RawTable ReadMat(const std::string& path) {
  // matio trusts much of a file (and libhdf5 under it, for v7.3, can crash on a corrupt one):
  // the whole read is tried in a child process first.
  SilenceMatio();
  mbid::internal::SurviveInChild(path, kMatFile, "matio", [&] { MatReader(path).Read(); });
  return MatReader(path).Read();
}

}  // namespace internal

}  // namespace mbid::records
