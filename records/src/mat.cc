// MATLAB .mat files (v5 and the HDF5-based v7.3) through matio: the layouts of
// docs/records-formats.md in, mbid's own layout out.

#include <fmt/format.h>
#include <matio.h>
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "mbid/common/atomic_file.h"
#include "mbid/common/error.h"
#include "mbid/records/records.h"
#include "raw_table.h"
#include "text_util.h"

namespace mbid::records {
namespace internal {
namespace {

constexpr char kExpectedFile[] = "a MATLAB .mat file, v5 or v7.3 (docs/records-formats.md)";
constexpr char kMbidLayout[] = "mbid measurement 1";
// Variables of mbid's own layout besides the channels (a channel variable avoids these names).
const char* const kMbidVariables[] = {
    "mbid_layout",       "source",       "channels",         "units", "time",
    "channel_variables", "start_time_s", "sample_interval_s"};

// Text from a file for a message: printable ASCII only, at most 64 characters.
std::string Printable(const std::string& text) {
  std::string out;
  for (char ch : text.substr(0, 64)) out += (ch >= 32 && ch < 127) ? ch : '?';
  return text.size() > 64 ? out + "..." : out;
}

// matio reports problems through a log function that prints to stderr; mbid reports them as
// InputErrors instead.
void SilentLog(int /*level*/, char* /*message*/) {}

void SilenceMatio() {
  static std::once_flag once;
  std::call_once(once, [] { Mat_LogInitFunc("mbid", SilentLog); });
}

struct MatFileCloser {
  void operator()(mat_t* mat) const { Mat_Close(mat); }
};
struct MatVarFreer {
  void operator()(matvar_t* var) const { Mat_VarFree(var); }
};
using MatFile = std::unique_ptr<mat_t, MatFileCloser>;
using MatVar = std::unique_ptr<matvar_t, MatVarFreer>;

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

// A structural check of a v5 file before matio reads it: every array's dimensions must fit the
// bytes its element holds (matio trusts them, and a damaged cell of 2e9 elements makes it loop
// for minutes). Compressed elements are inflated for the check (up to kMaxInflated bytes).
constexpr double kMaxInflated = 4.0e9;
constexpr int kMiInt8 = 1, kMiInt32 = 5, kMiUint32 = 6, kMiMatrix = 14, kMiCompressed = 15;

class V5Check {
 public:
  V5Check(const std::string& path, bool swap) : path_(path), swap_(swap) {}

  // The data elements after the 128-byte header.
  void TopLevel(const unsigned char* p, size_t n) {
    size_t at = 0;
    int index = 0;
    while (n - at >= 8) {
      ++index;
      Element e = Tag(p + at, n - at, fmt::format("data element {}", index));
      const std::string where = fmt::format("data element {} (byte {})", index, 128 + at);
      if (e.type == kMiCompressed) {
        const std::string inflated = Inflate(e.data, e.bytes, where);
        const auto* q = reinterpret_cast<const unsigned char*>(inflated.data());
        Element inner = Tag(q, inflated.size(), where);
        if (inner.type == kMiMatrix) Matrix(inner, where, 0);
        at += 8 + e.bytes;  // compressed elements are not padded
      } else {
        if (e.type == kMiMatrix) Matrix(e, where, 0);
        at += e.total;
      }
    }
  }

 private:
  struct Element {
    std::uint32_t type = 0;
    size_t bytes = 0;  // of data
    size_t total = 0;  // tag, data and padding to 8 bytes
    const unsigned char* data = nullptr;
  };

  std::uint32_t U32(const unsigned char* p) const {
    unsigned char b[4];
    std::memcpy(b, p, 4);
    if (swap_) std::reverse(b, b + 4);
    std::uint32_t v = 0;
    std::memcpy(&v, b, 4);
    return v;
  }

  [[noreturn]] void Fail(const std::string& where, const std::string& problem) const {
    throw InputError(path_, where, problem, "a complete MAT v5 file (docs/records-formats.md)");
  }

  Element Tag(const unsigned char* p, size_t n, const std::string& where) const {
    if (n < 8) Fail(where, "a data element cut short");
    Element e;
    const std::uint32_t first = U32(p);
    if ((first >> 16) != 0) {  // small element: type and size in 4 bytes, data in the next 4
      e.type = first & 0xffff;
      e.bytes = first >> 16;
      if (e.bytes > 4) Fail(where, "a small data element of more than 4 bytes");
      e.total = 8;
      e.data = p + 4;
      return e;
    }
    e.type = first;
    e.bytes = U32(p + 4);
    if (e.bytes > n - 8) {
      Fail(where, fmt::format("a data element of {} bytes with {} left", e.bytes, n - 8));
    }
    e.data = p + 8;
    e.total = std::min(n, 8 + ((e.bytes + 7) / 8) * 8);
    return e;
  }

  // An array: flags, dimensions, name, then contents that must hold every element.
  void Matrix(const Element& e, const std::string& where, int depth) {
    if (depth > 16) Fail(where, "arrays nested more than 16 deep");
    if (e.bytes == 0) return;  // an empty cell element
    const unsigned char* p = e.data;
    size_t n = e.bytes, at = 0;
    const auto next = [&]() {
      Element sub = Tag(p + at, n - at, where);
      at += sub.total;
      return sub;
    };
    const Element flags = next();
    if (flags.type != kMiUint32 || flags.bytes < 8) Fail(where, "no array flags");
    const std::uint32_t array_class = U32(flags.data) & 0xff;
    const Element dims = next();
    if (dims.type != kMiInt32 || dims.bytes < 8 || dims.bytes % 4 != 0) {
      Fail(where, "no dimensions");
    }
    double elements = 1;
    for (size_t k = 0; k < dims.bytes / 4; ++k) {
      elements *= static_cast<double>(static_cast<std::int32_t>(U32(dims.data + 4 * k)));
    }
    if (elements < 0) Fail(where, "negative dimensions");
    const Element name = next();
    if (name.type != kMiInt8) Fail(where, "no array name");
    const std::string var = std::string(reinterpret_cast<const char*>(name.data), name.bytes);
    const std::string here = var.empty() ? where : fmt::format("variable {}", Printable(var));
    const double rest = static_cast<double>(n - std::min(n, at));
    if (array_class == MAT_C_CELL || array_class == MAT_C_STRUCT) {
      double fields = 1;
      if (array_class == MAT_C_STRUCT) {
        const Element length = next();
        const Element names = next();
        const double width = length.bytes >= 4 ? U32(length.data) : 0;
        fields = width > 0 ? std::floor(static_cast<double>(names.bytes) / width) : 0;
      }
      // Each element (cell, or field of a struct element) is an array with an 8-byte tag.
      if (elements * fields * 8 > rest) {
        Fail(here, fmt::format("{} elements declared in {} bytes", elements * fields, rest));
      }
      for (double k = 0; k < elements * fields; ++k) {
        const Element sub = next();
        if (sub.type != kMiMatrix) Fail(here, "a cell or field that is not an array");
        Matrix(sub, here, depth + 1);
      }
    } else if (array_class != MAT_C_OBJECT && array_class != MAT_C_SPARSE &&
               array_class != MAT_C_OPAQUE && array_class != MAT_C_FUNCTION) {
      // Numbers and characters: at least one byte each (MATLAB may store them narrower).
      if (elements > rest) {
        Fail(here, fmt::format("{} elements declared in {} bytes", elements, rest));
      }
      while (n - std::min(n, at) >= 8) next();  // real and imaginary parts within the array
    }
  }

  std::string Inflate(const unsigned char* p, size_t n, const std::string& where) const {
    z_stream z{};
    if (inflateInit(&z) != Z_OK) Fail(where, "zlib cannot start");
    z.next_in = const_cast<unsigned char*>(p);
    z.avail_in = static_cast<uInt>(std::min<size_t>(n, 0xffffffffu));
    std::string out;
    unsigned char buffer[65536];
    int status = Z_OK;
    while (status == Z_OK) {
      z.next_out = buffer;
      z.avail_out = sizeof(buffer);
      status = inflate(&z, Z_NO_FLUSH);
      out.append(reinterpret_cast<const char*>(buffer), sizeof(buffer) - z.avail_out);
      if (static_cast<double>(out.size()) > kMaxInflated) status = Z_MEM_ERROR;
      if (status == Z_BUF_ERROR && z.avail_in == 0) break;
    }
    inflateEnd(&z);
    if (status != Z_STREAM_END) Fail(where, "a compressed variable that does not inflate");
    return out;
  }

  const std::string& path_;
  bool swap_;
};

// What a variable's header says, before any of its data is read.
struct VarInfo {
  std::string name;
  matio_classes class_type = MAT_C_EMPTY;
  bool complex = false;
  bool logical = false;
  bool compressed = false;
  std::vector<size_t> dims;
  double elements = 0;  // product of dims (a double: no overflow on hostile dims)

  bool numeric() const { return IsNumericClass(class_type) && !logical; }
  bool scalar() const { return elements == 1; }
  // Samples when a vector (one dimension above 1), else 0.
  size_t vector_length() const {
    if (dims.size() != 2 || elements < 2) return 0;
    if (dims[0] == 1) return dims[1];
    if (dims[1] == 1) return dims[0];
    return 0;
  }
  bool matrix() const { return dims.size() == 2 && dims[0] >= 2 && dims[1] >= 2; }
  std::string Shape() const {
    std::string text;
    for (size_t d : dims) text += (text.empty() ? "" : "x") + std::to_string(d);
    return fmt::format("{} {}", text, ClassName(class_type));
  }
};

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

class MatReader {
 public:
  explicit MatReader(const std::string& path) : path_(path) {}

  RawTable Read() {
    SilenceMatio();
    ReadHead();
    CheckV5Structure();
    mat_.reset(Mat_Open(path_.c_str(), MAT_ACC_RDONLY));
    if (!mat_) {
      throw InputError(path_, "", "not a MAT file matio can open", kExpectedFile);
    }
    if (Mat_GetVersion(mat_.get()) == MAT_FT_MAT4) {
      throw InputError(path_, "", "a MATLAB v4 file (or not a MAT file at all)", kExpectedFile);
    }
    ReadDirectory();
    if (infos_.count("mbid_layout")) return ReadMbidLayout();
    return ReadLabLayout();
  }

 private:
  InputError VarError(const std::string& name, const std::string& problem,
                      const std::string& expected) const {
    return InputError(path_, "variable " + Printable(name), problem, expected);
  }

  // The first bytes, read plainly, so that a missing or unreadable file is an InputError
  // like the other readers' (matio would only say NULL); also the file size for bounds.
  void ReadHead() {
    std::FILE* file = std::fopen(path_.c_str(), "rb");
    if (file == nullptr) {
      throw InputError(path_, "", std::string("cannot open: ") + std::strerror(errno),
                       kExpectedFile);
    }
    char head[128];
    const size_t n = std::fread(head, 1, sizeof(head), file);
    const bool failed = std::ferror(file) != 0;
    const int error = errno;
    std::fseek(file, 0, SEEK_END);
    const long size = std::ftell(file);
    std::fclose(file);
    if (failed) {
      throw InputError(path_, "", std::string("cannot read: ") + std::strerror(error),
                       kExpectedFile);
    }
    if (n < 128) {
      throw InputError(path_, "", fmt::format("{} bytes, shorter than a MAT header", n),
                       kExpectedFile);
    }
    file_size_ = size > 0 ? static_cast<double>(size) : 0.0;
  }

  // A v5 file (version 0x0100 at byte 124, endian mark "IM" or "MI" at 126): its arrays'
  // dimensions against their bytes, before matio trusts them.
  void CheckV5Structure() {
    const std::string bytes = ReadWholeFile(path_, kExpectedFile);
    if (bytes.size() < 128) return;
    const bool little_mark = bytes[126] == 'I' && bytes[127] == 'M';
    const bool big_mark = bytes[126] == 'M' && bytes[127] == 'I';
    if (!little_mark && !big_mark) return;  // not v5 (matio decides)
    const bool swap = little_mark != HostIsLittle();
    unsigned char version[2] = {static_cast<unsigned char>(bytes[124]),
                                static_cast<unsigned char>(bytes[125])};
    if (swap) std::swap(version[0], version[1]);
    std::uint16_t v = 0;
    std::memcpy(&v, version, 2);
    if (v != 0x0100) return;  // 0x0200: v7.3, an HDF5 file
    V5Check(path_, swap)
        .TopLevel(reinterpret_cast<const unsigned char*>(bytes.data()) + 128, bytes.size() - 128);
  }

  static bool HostIsLittle() {
    const std::uint16_t probe = 1;
    unsigned char first = 0;
    std::memcpy(&first, &probe, 1);
    return first == 1;
  }

  // Every variable's header (class, dimensions), without data.
  void ReadDirectory() {
    while (true) {
      MatVar var(Mat_VarReadNextInfo(mat_.get()));
      if (!var) break;
      if (order_.size() >= 100000) {
        throw InputError(path_, "", "more than 100000 variables", kExpectedFile);
      }
      const std::string name = var->name != nullptr ? var->name : "";
      if (name.empty() || infos_.count(name)) continue;
      VarInfo info = InfoOf(*var, name);
      if (info.numeric() && info.dims.size() > 2) {
        throw VarError(name,
                       fmt::format("a {}-dimensional array ({})", info.dims.size(), info.Shape()),
                       "vectors or a 2-D matrix (samples x columns)");
      }
      order_.push_back(name);
      infos_[name] = std::move(info);
    }
    if (order_.empty()) {
      throw InputError(path_, "", "no variables could be read", kExpectedFile);
    }
  }

  // A whole variable; its size is checked against the file before matio allocates it.
  MatVar Load(const VarInfo& info) {
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
  std::vector<double> Doubles(const matvar_t& var, const std::string& name) const {
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

  double Scalar(const std::string& name) {
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
  std::vector<std::string> CharRows(const matvar_t& var, const std::string& name) const {
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
  std::vector<std::string> Strings(const matvar_t& var, const std::string& name) const {
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

  std::vector<std::string> StringsVar(const std::string& name) {
    const MatVar var = Load(infos_.at(name));
    return Strings(*var, name);
  }

  std::vector<double> VectorVar(const std::string& name, size_t length) {
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

  // Layout (a): what WriteMat writes.
  RawTable ReadMbidLayout() {
    const std::vector<std::string> tag = StringsVar("mbid_layout");
    if (tag.size() != 1 || tag[0] != kMbidLayout) {
      throw VarError("mbid_layout", fmt::format("'{}'", tag.empty() ? "" : Printable(tag[0])),
                     fmt::format("'{}'", kMbidLayout));
    }
    for (const char* required :
         {"channels", "units", "channel_variables", "sample_interval_s", "start_time_s"}) {
      if (!infos_.count(required)) {
        throw InputError(path_, "variable " + std::string(required), "missing",
                         "every variable of mbid's layout (docs/records-formats.md)");
      }
    }
    const std::vector<std::string> channels = StringsVar("channels");
    const std::vector<std::string> units = StringsVar("units");
    const std::vector<std::string> variables = StringsVar("channel_variables");
    if (units.size() != channels.size() || variables.size() != channels.size() ||
        channels.empty()) {
      throw VarError("channels",
                     fmt::format("{} channels, {} units, {} channel_variables", channels.size(),
                                 units.size(), variables.size()),
                     "one unit and one variable per channel");
    }
    RawTable table;
    table.format = "mat";
    table.si_by_contract = true;
    table.time_unit = "s";
    table.time_where = "variable sample_interval_s";
    table.interval = Scalar("sample_interval_s");
    table.start = Scalar("start_time_s");
    size_t length = 0;
    for (size_t c = 0; c < channels.size(); ++c) {
      if (!infos_.count(variables[c])) {
        throw VarError(
            "channel_variables",
            fmt::format("variable '{}' of channel '{}' is missing", variables[c], channels[c]),
            "one vector per channel");
      }
      RawColumn column;
      column.name = channels[c];
      column.unit = units[c];
      column.where = "variable " + variables[c];
      column.values = VectorVar(variables[c], length);
      length = column.values.size();
      table.columns.push_back(std::move(column));
    }
    return table;
  }

  std::optional<std::string> FindFirst(std::initializer_list<const char*> names) const {
    for (const char* name : names) {
      if (infos_.count(name)) return std::string(name);
    }
    return std::nullopt;
  }

  // Times from a scalar rate or interval (and start), when one is present.
  bool TimeFromScalars(RawTable* table) {
    const auto rate = FindFirst({"fs", "Fs", "sample_rate_hz"});
    const auto step = FindFirst({"dt", "sample_interval_s"});
    if (rate && step) {
      throw VarError(*step, fmt::format("both {} and {} give the sampling", *rate, *step),
                     "one of a sample rate (fs, Fs, sample_rate_hz) or an interval (dt, "
                     "sample_interval_s)");
    }
    if (!rate && !step) return false;
    const std::string name = rate ? *rate : *step;
    const double value = Scalar(name);
    if (!(value > 0)) {
      throw VarError(name, fmt::format("{}", value), "a positive sample rate or interval");
    }
    table->interval = rate ? 1.0 / value : value;
    table->time_where = "variable " + name;
    if (const auto start = FindFirst({"t0", "start_time_s"})) table->start = Scalar(*start);
    return true;
  }

  void SetTimeColumn(std::vector<double> time, const VarInfo& info, RawTable* table) {
    double largest = 0;
    for (double t : time) largest = std::max(largest, std::abs(t));
    // Single-precision times are exact to a float's last bit only.
    if (info.class_type == MAT_C_SINGLE) table->printed_resolution = largest * 0x1p-23;
    table->time = std::move(time);
    table->time_where = "variable " + info.name;
  }

  // Layouts (b) and (c): a lab's struct, one matrix, or vectors.
  RawTable ReadLabLayout() {
    RawTable table;
    table.format = "mat";
    table.time_unit = "s";
    // (b) a struct with fields time and data.
    std::vector<std::string> structs;
    std::vector<std::string> matrices;
    std::vector<std::string> vectors;
    for (const std::string& name : order_) {
      const VarInfo& info = infos_.at(name);
      if (info.class_type == MAT_C_STRUCT) {
        structs.push_back(name);
      } else if (info.numeric() && info.matrix()) {
        matrices.push_back(name);
      } else if (info.numeric() && info.vector_length() > 0) {
        vectors.push_back(name);
      }
    }
    std::vector<std::string> record_structs;
    for (const std::string& name : structs) {
      const MatVar var = Load(infos_.at(name));
      if (Mat_VarGetStructFieldByName(var.get(), "time", 0) != nullptr &&
          Mat_VarGetStructFieldByName(var.get(), "data", 0) != nullptr) {
        record_structs.push_back(name);
      }
    }
    if (record_structs.size() > 1) {
      throw VarError(
          record_structs[1],
          fmt::format("a second struct with time and data (after {})", record_structs[0]),
          "one record per file");
    }
    if (record_structs.size() == 1) return ReadStruct(record_structs[0], table);
    if (matrices.size() > 1) {
      throw VarError(matrices[1], fmt::format("a second matrix (after {})", matrices[0]),
                     "one matrix of samples x columns, or vectors");
    }
    if (matrices.size() == 1) {
      if (!vectors.empty()) {
        throw VarError(vectors[0], fmt::format("a vector beside the matrix {}", matrices[0]),
                       "one matrix of samples x columns, or vectors (not both)");
      }
      return ReadMatrix(matrices[0], table);
    }
    return ReadVectors(vectors, table);
  }

  // Samples along the longer dimension of `info` (a record has more samples than columns).
  std::vector<std::vector<double>> Columns(const std::vector<double>& values, size_t rows,
                                           size_t cols, bool samples_in_rows) const {
    const size_t n = samples_in_rows ? rows : cols, k = samples_in_rows ? cols : rows;
    std::vector<std::vector<double>> out(k, std::vector<double>(n));
    for (size_t c = 0; c < k; ++c) {
      for (size_t j = 0; j < n; ++j) {
        out[c][j] = samples_in_rows ? values[j + c * rows] : values[c + j * rows];
      }
    }
    return out;
  }

  // Optional names/units for `count` data columns; a list one longer names the time column
  // first.
  std::vector<std::string> Labels(const std::vector<std::string>& given, size_t count,
                                  const std::string& where) const {
    if (given.empty()) return std::vector<std::string>(count);
    if (given.size() == count) return given;
    if (given.size() == count + 1) return {given.begin() + 1, given.end()};
    throw VarError(where, fmt::format("{} entries for {} data columns", given.size(), count),
                   "one entry per data column (or one more, naming time first)");
  }

  void AddColumns(std::vector<std::vector<double>> data, const std::vector<std::string>& names,
                  const std::vector<std::string>& units, const std::string& where,
                  RawTable* table) const {
    for (size_t c = 0; c < data.size(); ++c) {
      RawColumn column;
      column.name = names[c].empty() ? fmt::format("column {}", c + 1) : names[c];
      column.unit = units[c];
      column.where = fmt::format("{}, column {}", where, c + 1);
      column.values = std::move(data[c]);
      table->columns.push_back(std::move(column));
    }
  }

  RawTable ReadStruct(const std::string& name, RawTable& table) {
    const MatVar var = Load(infos_.at(name));
    const auto field = [&](const char* field_name) {
      return Mat_VarGetStructFieldByName(var.get(), field_name, 0);
    };
    if (InfoOf(*var, name).elements != 1) {
      throw VarError(name, fmt::format("a {} struct array", InfoOf(*var, name).Shape()),
                     "a 1x1 struct");
    }
    const std::string time_name = name + ".time", data_name = name + ".data";
    const VarInfo time_info = InfoOf(*field("time"), time_name);
    const VarInfo data_info = InfoOf(*field("data"), data_name);
    if (!time_info.numeric() || time_info.vector_length() == 0) {
      throw VarError(time_name, fmt::format("a {}", time_info.Shape()), "a vector of times");
    }
    if (!data_info.numeric() || data_info.dims.size() != 2) {
      throw VarError(data_name, fmt::format("a {}", data_info.Shape()),
                     "a numeric matrix, samples x channels");
    }
    const size_t n = time_info.vector_length();
    const size_t rows = data_info.dims[0], cols = data_info.dims[1];
    if (rows != n && cols != n) {
      throw VarError(data_name, fmt::format("{}x{} for {} times", rows, cols, n),
                     "one row (or column) per time");
    }
    SetTimeColumn(Doubles(*field("time"), time_name), time_info, &table);
    auto data = Columns(Doubles(*field("data"), data_name), rows, cols, rows == n);
    std::vector<std::string> names, units;
    for (const char* key : {"names", "channels", "labels"}) {
      if (matvar_t* f = field(key)) {
        names = Strings(*f, name + "." + key);
        break;
      }
    }
    if (matvar_t* f = field("units")) units = Strings(*f, name + ".units");
    const size_t count = data.size();
    AddColumns(std::move(data), Labels(names, count, name + ".names"),
               Labels(units, count, name + ".units"), "variable " + data_name, &table);
    return table;
  }

  std::vector<std::string> OptionalStrings(std::initializer_list<const char*> keys) {
    if (const auto name = FindFirst(keys)) return StringsVar(*name);
    return {};
  }

  RawTable ReadMatrix(const std::string& name, RawTable& table) {
    const VarInfo& info = infos_.at(name);
    const MatVar var = Load(info);
    const size_t rows = info.dims[0], cols = info.dims[1];
    auto columns = Columns(Doubles(*var, name), rows, cols, rows >= cols);
    // With a rate or interval every column is a channel; without, the first is time.
    if (!TimeFromScalars(&table)) {
      VarInfo time_info = info;
      time_info.name = name + ", column 1";
      SetTimeColumn(std::move(columns.front()), time_info, &table);
      columns.erase(columns.begin());
    }
    if (columns.empty()) {
      throw VarError(name, fmt::format("a {} with only a time column", info.Shape()),
                     "time and at least one channel column");
    }
    const auto names = OptionalStrings({"channels", "names", "labels"});
    const auto units = OptionalStrings({"units"});
    const std::string names_var = FindFirst({"channels", "names", "labels"}).value_or("names");
    const size_t count = columns.size();
    AddColumns(std::move(columns), Labels(names, count, names_var), Labels(units, count, "units"),
               "variable " + name, &table);
    return table;
  }

  RawTable ReadVectors(const std::vector<std::string>& vectors, RawTable& table) {
    const auto time_name = FindFirst({"time", "t", "Time"});
    if (time_name && infos_.at(*time_name).vector_length() == 0) {
      throw VarError(*time_name, fmt::format("a {}", infos_.at(*time_name).Shape()),
                     "a vector of times");
    }
    const bool from_scalars = TimeFromScalars(&table);
    if (time_name && from_scalars) {
      throw VarError(*time_name, "both a time vector and " + table.time_where.substr(9),
                     "either a time vector or a sample rate/interval");
    }
    if (!time_name && !from_scalars) {
      throw InputError(path_, "", "no time base",
                       "a time vector (time, t), a sample rate (fs, Fs, sample_rate_hz) or "
                       "an interval (dt, sample_interval_s); or one matrix with time first");
    }
    size_t length = 0;
    if (time_name) {
      SetTimeColumn(VectorVar(*time_name, 0), infos_.at(*time_name), &table);
      length = table.time.size();
    }
    for (const std::string& name : vectors) {
      if (time_name && name == *time_name) continue;
      RawColumn column;
      column.name = name;
      column.where = "variable " + name;
      column.values = VectorVar(name, length);
      length = column.values.size();
      table.columns.push_back(std::move(column));
    }
    if (table.columns.empty()) {
      throw InputError(path_, "", "no channel vectors",
                       "numeric vectors of samples, one per channel");
    }
    return table;
  }

  const std::string& path_;
  MatFile mat_;
  double file_size_ = 0;
  std::vector<std::string> order_;
  std::map<std::string, VarInfo> infos_;
};

// A MATLAB identifier for a channel: letters, digits and '_', starting with a letter, at most
// 63 characters, unlike mbid's own variable names and the other channels'.
std::string VariableName(const std::string& channel, std::set<std::string>* taken) {
  std::string name;
  for (char ch : channel) {
    const bool ok = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') ||
                    (ch >= '0' && ch <= '9') || ch == '_';
    name += ok ? ch : '_';
  }
  if (name.empty() || !((name[0] >= 'a' && name[0] <= 'z') || (name[0] >= 'A' && name[0] <= 'Z'))) {
    name = "ch_" + name;
  }
  name = name.substr(0, 63);
  std::string unique = name;
  for (int k = 2; taken->count(unique); ++k) {
    const std::string suffix = "_" + std::to_string(k);
    unique = name.substr(0, 63 - suffix.size()) + suffix;
  }
  taken->insert(unique);
  return unique;
}

MatVar CharVar(const char* name, const std::string& text) {
  size_t dims[2] = {1, text.size()};
  return MatVar(
      Mat_VarCreate(name, MAT_C_CHAR, MAT_T_UTF8, 2, dims, const_cast<char*>(text.data()), 0));
}

MatVar CellVar(const char* name, const std::vector<std::string>& texts) {
  size_t dims[2] = {1, texts.size()};
  MatVar cell(Mat_VarCreate(name, MAT_C_CELL, MAT_T_CELL, 2, dims, nullptr, 0));
  if (!cell) return cell;
  for (size_t i = 0; i < texts.size(); ++i) {
    MatVar text = CharVar(nullptr, texts[i]);
    if (!text) return nullptr;
    Mat_VarSetCell(cell.get(), static_cast<int>(i), text.release());  // the cell owns it
  }
  return cell;
}

MatVar DoubleVar(const char* name, const double* data, size_t rows) {
  size_t dims[2] = {rows, 1};
  return MatVar(
      Mat_VarCreate(name, MAT_C_DOUBLE, MAT_T_DOUBLE, 2, dims, const_cast<double*>(data), 0));
}

}  // namespace

RawTable ReadMat(const std::string& path) {
  // matio trusts much of a file (and libhdf5 under it, for v7.3, can crash on a corrupt one):
  // the whole read is tried in a child process first.
  SilenceMatio();
  mbid::internal::SurviveInChild(path, kExpectedFile, "matio", [&] { MatReader(path).Read(); });
  return MatReader(path).Read();
}

}  // namespace internal

void WriteMat(const Measurement& measurement, const std::string& path) {
  measurement.Validate(path);
  internal::SilenceMatio();
  AtomicFile file(path);
  std::set<std::string> taken(std::begin(internal::kMbidVariables),
                              std::end(internal::kMbidVariables));
  std::vector<std::string> variables;
  for (const std::string& channel : measurement.channels) {
    variables.push_back(internal::VariableName(channel, &taken));
  }
  const std::string header = "MATLAB 5.0 MAT-file, written by mbid (docs/records-formats.md)";
  {
    internal::MatFile mat(Mat_CreateVer(file.temp_path().c_str(), header.c_str(), MAT_FT_MAT5));
    if (!mat) throw std::runtime_error("cannot create " + file.temp_path());
    bool ok = true;
    const auto write = [&](internal::MatVar var) {
      ok = ok && var && Mat_VarWrite(mat.get(), var.get(), MAT_COMPRESSION_NONE) == 0;
    };
    const size_t samples = static_cast<size_t>(measurement.samples());
    write(internal::CharVar("mbid_layout", internal::kMbidLayout));
    write(internal::CharVar("source", measurement.source));
    write(internal::CellVar("channels", measurement.channels));
    write(internal::CellVar("units", measurement.units));
    write(internal::CellVar("channel_variables", variables));
    write(internal::DoubleVar("sample_interval_s", &measurement.sample_interval_s, 1));
    write(internal::DoubleVar("start_time_s", &measurement.start_time_s, 1));
    const Eigen::VectorXd time = measurement.CalcTime();
    write(internal::DoubleVar("time", time.data(), samples));
    for (size_t c = 0; c < variables.size(); ++c) {
      const Eigen::VectorXd column = measurement.values.col(static_cast<Eigen::Index>(c));
      write(internal::DoubleVar(variables[c].c_str(), column.data(), samples));
    }
    ok = Mat_Close(mat.release()) == 0 && ok;  // flushes the file
    if (!ok) throw std::runtime_error("cannot write " + file.temp_path());
  }
  file.Commit();
}

}  // namespace mbid::records
