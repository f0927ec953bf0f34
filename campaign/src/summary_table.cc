#include "summary_table.h"

#include <fmt/format.h>

#include <fstream>
#include <set>
#include <stdexcept>

#include "mbid/common/atomic_file.h"

namespace mbid::campaign::internal {
namespace {

std::string Cell(const nlohmann::ordered_json& value) {
  if (value.is_null()) return "";
  if (value.is_number_integer()) return fmt::format("{}", value.get<long long>());
  if (value.is_number_unsigned()) return fmt::format("{}", value.get<unsigned long long>());
  if (value.is_number()) return fmt::format("{}", value.get<double>());
  if (value.is_boolean()) return value.get<bool>() ? "true" : "false";
  const std::string text = value.is_string() ? value.get<std::string>() : value.dump();
  if (text.find_first_of(",\"\n\r") == std::string::npos) return text;
  std::string quoted = "\"";
  for (char c : text) {
    if (c == '"') quoted += '"';
    quoted += c;
  }
  return quoted + "\"";
}

}  // namespace

std::vector<std::string> SummaryColumns(const std::vector<nlohmann::ordered_json>& rows) {
  std::vector<std::string> columns;
  std::set<std::string> seen;
  for (const auto& row : rows) {
    for (const auto& item : row.items()) {
      if (seen.insert(item.key()).second) columns.push_back(item.key());
    }
  }
  return columns;
}

void WriteSummaryCsv(const std::vector<nlohmann::ordered_json>& rows, const std::string& path) {
  const std::vector<std::string> columns = SummaryColumns(rows);
  AtomicFile file(path);
  {
    std::ofstream out(file.temp_path());
    for (size_t c = 0; c < columns.size(); ++c) out << (c ? "," : "") << Cell(columns[c]);
    out << "\n";
    for (const auto& row : rows) {
      for (size_t c = 0; c < columns.size(); ++c) {
        const auto it = row.find(columns[c]);
        out << (c ? "," : "") << (it == row.end() ? "" : Cell(*it));
      }
      out << "\n";
    }
    if (!out) throw std::runtime_error("cannot write " + path);
  }
  file.Commit();
}

}  // namespace mbid::campaign::internal
