#pragma once

// What MAT reading and writing share: texts, matio handles, VarInfo and the reader's class.
// Private to records/. MatReader's members are defined in mat.cc (the file and its variables),
// mat_v5_check.cc (a v5 file's structure) and mat_layouts.cc (the record layouts); mat_write.cc
// writes mbid's layout.

#include <fmt/format.h>
#include <matio.h>

#include <initializer_list>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "mbid/common/error.h"
#include "mbid/common/hdf5_io.h"
#include "raw_table.h"

namespace mbid::records::internal {

// Not inline: an internal-linkage constant per file (uff58's has the same name).
constexpr char kMatFile[] = "a MATLAB .mat file, v5 or v7.3 (docs/records-formats.md)";
constexpr char kMbidLayout[] = "mbid measurement 1";

// Text from a file for a message: printable ASCII only, at most 64 characters.
std::string Printable(const std::string& text);

// matio reports problems through a log function that prints to stderr; mbid reports them as
// InputErrors instead.
void SilenceMatio();

struct MatFileCloser {
  void operator()(mat_t* mat) const { Mat_Close(mat); }
};
struct MatVarFreer {
  void operator()(matvar_t* var) const { Mat_VarFree(var); }
};
using MatFile = std::unique_ptr<mat_t, MatFileCloser>;
using MatVar = std::unique_ptr<matvar_t, MatVarFreer>;

bool IsNumericClass(matio_classes c);
const char* ClassName(matio_classes c);

// What a variable's header says, before any of its data is read.
struct VarInfo {
  std::string name;
  matio_classes class_type = MAT_C_EMPTY;
  bool complex = false;
  bool logical = false;
  bool compressed = false;
  // A v7.3 numeric variable whose class matio could not read (read through HDF5 instead).
  bool through_hdf5 = false;
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

VarInfo InfoOf(const matvar_t& var, const std::string& name);

// Reads a MAT file's record in one of the layouts of docs/records-formats.md.
class MatReader {
 public:
  explicit MatReader(const std::string& path) : path_(path) {}

  RawTable Read();

 private:
  // The file and its variables (mat.cc).
  InputError VarError(const std::string& name, const std::string& problem,
                      const std::string& expected) const;
  void ReadHead();
  void ReadDirectory();
  void RecoverV73Class(VarInfo* info);
  MatVar Load(const VarInfo& info);
  std::vector<double> Doubles(const matvar_t& var, const std::string& name) const;
  double Scalar(const std::string& name);
  std::vector<std::string> CharRows(const matvar_t& var, const std::string& name) const;
  std::vector<std::string> Strings(const matvar_t& var, const std::string& name) const;
  std::vector<std::string> StringsVar(const std::string& name);
  std::vector<double> VectorVar(const std::string& name, size_t length);

  // A v5 file's structure (mat_v5_check.cc).
  void CheckV5Structure();
  static bool HostIsLittle();

  // The record layouts (mat_layouts.cc).
  RawTable ReadMbidLayout();
  std::optional<std::string> FindFirst(std::initializer_list<const char*> names) const;
  bool TimeFromScalars(RawTable* table);
  void SetTimeColumn(std::vector<double> time, const VarInfo& info, RawTable* table);
  RawTable ReadLabLayout();
  std::vector<std::vector<double>> Columns(const std::vector<double>& values, size_t rows,
                                           size_t cols, bool samples_in_rows) const;
  std::vector<std::string> Labels(const std::vector<std::string>& given, size_t count,
                                  const std::string& where) const;
  void AddColumns(std::vector<std::vector<double>> data, const std::vector<std::string>& names,
                  const std::vector<std::string>& units, const std::string& where,
                  RawTable* table) const;
  RawTable ReadStruct(const std::string& name, RawTable& table);
  std::vector<std::string> OptionalStrings(std::initializer_list<const char*> keys);
  RawTable ReadMatrix(const std::string& name, RawTable& table);
  RawTable ReadVectors(const std::vector<std::string>& vectors, RawTable& table);

  const std::string& path_;
  MatFile mat_;
  std::unique_ptr<H5Reader> h5_;  // a v7.3 file as HDF5, opened where matio fell short
  double file_size_ = 0;
  std::vector<std::string> order_;
  std::map<std::string, VarInfo> infos_;
};

}  // namespace mbid::records::internal
