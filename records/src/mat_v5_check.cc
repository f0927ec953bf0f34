// A MAT v5 file's structure checked before matio reads it (MatReader::CheckV5Structure).

#include <fmt/format.h>
#include <matio.h>
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>

#include "mat_internal.h"
#include "mbid/common/error.h"
#include "text_util.h"

namespace mbid::records::internal {
namespace {

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

}  // namespace

// A v5 file (version 0x0100 at byte 124, endian mark "IM" or "MI" at 126): its arrays'
// dimensions against their bytes, before matio trusts them.
void MatReader::CheckV5Structure() {
  const std::string bytes = ReadWholeFile(path_, kMatFile);
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

bool MatReader::HostIsLittle() {
  const std::uint16_t probe = 1;
  unsigned char first = 0;
  std::memcpy(&first, &probe, 1);
  return first == 1;
}

}  // namespace mbid::records::internal
