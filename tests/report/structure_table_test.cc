// The structure report's table (`mbid structure`, docs/structure.md): a candidate whose fit
// stopped before converging is ranked by where it stopped, so the table says its cost and
// criteria are upper bounds; converged and skipped candidates carry no such remark.
#include <gtest/gtest.h>

#include <string>

#include "mbid/report/structure_report.h"

namespace mbid::report {
namespace {

updating::StructureFit Candidate(const std::string& name, int rank, double cost,
                                 updating::UpdateResult::Termination termination, int iterations) {
  updating::StructureFit fit;
  fit.name = name;
  fit.rank = rank;
  fit.cost = cost;
  fit.coordinates = {"x1", "x2"};
  fit.parameter_count = 4;
  fit.fit.termination = termination;
  fit.fit.iterations = iterations;
  return fit;
}

TEST(StructureTableTest, AFitThatStoppedEarlyIsMarkedAsAnUpperBound) {
  using Termination = updating::UpdateResult::Termination;
  updating::StructureRanking ranking;
  ranking.structures = {Candidate("full", 1, 601.6, Termination::kConverged, 8),
                        Candidate("rigid x1", 2, 5.5e6, Termination::kNoConvergence, 51),
                        Candidate("rigid x2", 3, 1.2e7, Termination::kConverged, 49),
                        Candidate("rigid x3", 4, NAN, Termination::kFailure, 0)};
  ranking.structures[3].skipped = "its fit failed";
  const std::string table = StructureTable(ranking);
  EXPECT_NE(table.find("- rigid x1: its fit stopped before converging (no_convergence after 51 "
                       "iterations): its cost and criteria are upper bounds"),
            std::string::npos)
      << table;
  EXPECT_EQ(table.find("- full: its fit stopped"), std::string::npos) << table;
  EXPECT_EQ(table.find("- rigid x2: its fit stopped"), std::string::npos) << table;
  // A skipped candidate is "not ranked", not an upper bound.
  EXPECT_NE(table.find("- rigid x3: not ranked: its fit failed"), std::string::npos) << table;
  EXPECT_EQ(table.find("- rigid x3: its fit stopped"), std::string::npos) << table;
}

}  // namespace
}  // namespace mbid::report
