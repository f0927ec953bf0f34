#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "mbid/updating/structure.h"

namespace mbid::report {

// The outputs of `mbid structure` (docs/structure.md).

// {"structures": [{"rank", "name", "rigid", "coordinates", "parameters", "cost", "aic", "bic",
// "delta_bic", "prediction_error", ...}, ...]} best first; NaN as null.
nlohmann::json StructureRankingToJson(const updating::StructureRanking& ranking,
                                      const std::vector<std::string>& records);

// The ranking as a markdown table (rank, structure, k, cost, AIC, BIC, delta BIC, prediction
// error), one line per candidate, plus the skipped candidates' reasons.
std::string StructureTable(const updating::StructureRanking& ranking);

// The report files beside the HDF5 file `h5_path` ("out/ranking.h5"): "out/ranking.md" and the
// figure "out/ranking-criteria.png".
struct StructureReportPaths {
  std::string markdown;
  std::string figure;
};
StructureReportPaths ReportPathsBeside(const std::string& h5_path);

// Refuses (InputError naming the file, exit 2) report files that exist and are not an earlier
// structure report of mbid's: the user's files are never overwritten. Call before the work.
void CheckReportPaths(const StructureReportPaths& paths);

// Writes the report (atomically; the figure only where gnuplot is installed, else a note).
void WriteStructureReport(const updating::StructureRanking& ranking,
                          const std::string& scenario_name, const std::vector<std::string>& records,
                          const StructureReportPaths& paths);

}  // namespace mbid::report

namespace mbid {
class H5Writer;
}

namespace mbid::report {

// /structure of the HDF5 file: one entry per candidate, best first (docs/file-formats.md).
void WriteStructureGroup(H5Writer& file, const updating::StructureRanking& ranking);

}  // namespace mbid::report
