#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace mbid::campaign::internal {

// The columns of summary.csv: every key of the rows, in the order of first appearance (rows
// in case order), so that the table is the same however the cases were scheduled.
std::vector<std::string> SummaryColumns(const std::vector<nlohmann::ordered_json>& rows);

// summary.csv, written atomically: a header of column names, one line per case; numbers in the
// shortest form that reads back to the same double, null as an empty cell, text quoted as
// RFC 4180 says when it holds a comma, quote or line break.
void WriteSummaryCsv(const std::vector<nlohmann::ordered_json>& rows, const std::string& path);

}  // namespace mbid::campaign::internal
