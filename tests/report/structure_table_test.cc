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

// A record that moves one joint alone (a slew deflection of a platform) leaves the winner's
// other parameters undetermined: its rank then says nothing of those joints, and the table says
// so beside the ranking (a true full model ranked third by 13.6 in BIC read as "very strong").
TEST(StructureTableTest, AWinnerWithUndeterminedParametersIsSaidNotToDecideThoseJoints) {
  using Termination = updating::UpdateResult::Termination;
  updating::StructureRanking ranking;
  ranking.structures = {Candidate("rigid level", 1, 601.6, Termination::kConverged, 8),
                        Candidate("full", 2, 600.9, Termination::kConverged, 12)};
  ranking.structures[0].fit.undetermined = {"c_luff", "d_luff"};
  ranking.structures[1].fit.undetermined = {"c_luff", "d_luff", "c_level"};
  const std::string table = StructureTable(ranking);
  EXPECT_NE(table.find("- rigid level (ranked first): its fit leaves c_luff, d_luff undetermined: "
                       "the records hardly move those joints"),
            std::string::npos)
      << table;
  ranking.structures[0].fit.undetermined.clear();
  EXPECT_EQ(StructureTable(ranking).find("ranked first"), std::string::npos);
}

}  // namespace
}  // namespace mbid::report
