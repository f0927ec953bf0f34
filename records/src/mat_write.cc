// Writing a measurement as a MAT v5 file in mbid's own layout (WriteMat).

#include <fmt/format.h>
#include <matio.h>

#include <iterator>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "mat_internal.h"
#include "mbid/common/atomic_file.h"
#include "mbid/records/records.h"

namespace mbid::records {
namespace internal {
namespace {

// Variables of mbid's own layout besides the channels (a channel variable avoids these names).
const char* const kMbidVariables[] = {
    "mbid_layout",       "source",       "channels",         "units", "time",
    "channel_variables", "start_time_s", "sample_interval_s"};

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
