// `mbid plan`: ranks candidate tests by the information they add to the recorded ones
// (D-optimal, updating/plan.h) at the estimate the recorded tests give (as `mbid update`).
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cmath>
#include <iostream>
#include <map>
#include <string>
#include <vector>

#include "mbid/app/commands.h"
#include "mbid/common/error.h"
#include "mbid/common/json_io.h"
#include "mbid/updating/fisher.h"
#include "mbid/updating/output_error.h"
#include "mbid/updating/plan.h"
#include "mbid/updating/plan_alternatives.h"
#include "mbid/validation/plan_candidates.h"
#include "mbid/validation/recorded_tests.h"
#include "mbid/validation/scenario.h"

namespace mbid::app {
using validation::CandidateFile;
using validation::FillCandidateNoise;
using validation::LoadedTest;
using validation::LoadScenario;
using validation::LoadTests;
using validation::ReadCandidateFile;
using validation::RecordedUpdate;
using validation::Scenario;
using validation::UpdateFromTests;

namespace {

std::string Cell(double relative_std) {
  return std::isfinite(relative_std) ? fmt::format("{:.3g}", relative_std) : std::string("inf");
}

// Parameter k's column: its name's width, at least 8.
size_t Width(const updating::TestPlan& plan, Eigen::Index k) {
  return std::max<size_t>(8, plan.parameters[static_cast<size_t>(k)].size());
}

void PrintPlan(const updating::TestPlan& plan, const std::string& estimate_source) {
  std::cout << fmt::format(
      "plan: {} candidate(s) against {} recorded test(s), at the {} values; score = log det of "
      "the Fisher information of all tests (log coordinates), best first\n",
      plan.candidates.size(), plan.recorded_tests, estimate_source);
  size_t w = 20;  // the longest name sets the first column, so that the others line up
  for (const updating::CandidateScore& candidate : plan.candidates) {
    w = std::max(w, candidate.name.size());
  }
  std::string header = fmt::format("{:<{}} {:>10} {:>9}", "candidate", w, "score", "gain");
  for (const std::string& name : plan.parameters) {
    header += fmt::format(" {:>{}}", name, std::max<size_t>(8, name.size()));
  }
  std::cout << header << "\n";
  if (plan.recorded_tests > 0) {
    std::string row =
        fmt::format("{:<{}} {:>10.4g} {:>9}", "(recorded only)", w, plan.recorded_score, "");
    for (Eigen::Index k = 0; k < plan.current_relative_std.size(); ++k) {
      row += fmt::format(" {:>{}}", Cell(plan.current_relative_std[k]), Width(plan, k));
    }
    std::cout << row << "\n";
  }
  for (const updating::CandidateScore& candidate : plan.candidates) {
    std::string row =
        fmt::format("{:<{}} {:>10.4g} {:>9}", candidate.name, w, candidate.score,
                    std::isfinite(candidate.gain) ? fmt::format("{:.4g}", candidate.gain) : "-");
    for (Eigen::Index k = 0; k < candidate.relative_std.size(); ++k) {
      row += fmt::format(" {:>{}}", Cell(candidate.relative_std[k]), Width(plan, k));
    }
    std::cout << row << "\n";
  }
  std::cout << "(columns per parameter: expected relative standard deviation with the recorded "
               "tests; inf = undetermined)\n";
  for (const updating::CandidateScore& candidate : plan.candidates) {
    if (candidate.moves_nothing) {
      std::cout << "candidate " << candidate.name
                << ": its test moves no output by its sensors' noise; it adds nothing\n";
    }
  }
}

void PrintAlternatives(const updating::AlternativesPlan& plan,
                       const std::vector<updating::AlternativeMinimumValues>& alternatives) {
  for (size_t a = 0; a < alternatives.size(); ++a) {
    std::vector<std::string> can, cannot;
    for (const updating::CandidateAtAlternatives& entry : plan.candidates) {
      (entry.cannot_separate[a] ? cannot : can)
          .push_back(fmt::format("{} ({:.3g})", entry.name, entry.separation[a]));
    }
    std::cout << fmt::format(
        "alternative minimum from {} (2 x cost excess {:.3g}, F-test threshold {:.3g}): may be "
        "told apart by {}; cannot by {} (chi-square separation of the noise-free outputs)\n",
        alternatives[a].label, alternatives[a].cost_excess, plan.thresholds[a],
        can.empty() ? "none" : fmt::format("{}", fmt::join(can, ", ")),
        cannot.empty() ? "none" : fmt::format("{}", fmt::join(cannot, ", ")));
  }
}

}  // namespace

int RunPlanCommand(const std::string& scenario_path, const std::vector<std::string>& data_paths,
                   const std::string& candidates_path, const CommonOptions& common) {
  const Scenario scenario = LoadScenario(scenario_path);
  const auto model = scenario.MakeModel();
  updating::UpdatingSettings settings = scenario.updating;
  settings.options.quiet = common.quiet;
  // The candidates are checked before any long work starts.
  CandidateFile file = ReadCandidateFile(candidates_path, scenario, *model);
  const identification::IdentificationOptions identification_options = scenario.identification;
  const std::vector<LoadedTest> tests =
      LoadTests(data_paths, scenario, *model, identification_options, common.import, false);

  updating::PlanOptions options;
  options.sensitivity = settings.options.sensitivity;
  options.rank_tolerance = settings.options.rank_tolerance;
  options.undetermined_relative_std = settings.options.undetermined_relative_std;
  options.threads = settings.options.threads;
  for (const updating::ParameterSetting& setting : settings.options.parameters) {
    options.parameters.push_back(setting.name);
  }
  std::vector<updating::TestDesign> recorded;
  std::map<std::string, double> recorded_noise;
  std::string estimate_source = "scenario";
  std::vector<std::string> recorded_undetermined;
  bool non_unique = false;
  std::vector<updating::AlternativeMinimumValues> alternatives;
  long residual_count = 0;
  double significance = settings.global_search.significance;
  if (!tests.empty()) {
    const RecordedUpdate update =
        UpdateFromTests(*model, tests, settings, [&common](const std::string& line) {
          if (!common.quiet) std::cerr << "mbid: " << line << "\n";
        });
    const updating::UpdateResult& result = update.search.best;
    if (result.termination != updating::UpdateResult::Termination::kConverged) {
      throw NumericalError("updating", "the recorded tests' fit: " + result.termination_name() +
                                           ": " + result.message);
    }
    updating::ApplyEstimates(result, *model);
    // What the fit itself leaves undetermined, by its std and by other minima of equal fit
    // (the global search): the plan's F is local to this estimate and does not see the latter.
    recorded_undetermined = result.undetermined;
    non_unique = update.search.non_unique;
    residual_count = update.search.residual_count;
    for (const updating::SearchMinimum& minimum : update.search.minima) {
      if (!minimum.alternative) continue;
      updating::AlternativeMinimumValues alternative;
      alternative.label = fmt::format("{}", fmt::join(minimum.starts, ", "));
      for (const updating::ParameterEstimate& p : minimum.fit.parameters) {
        if (p.test.empty()) alternative.values[p.name] = p.value;
      }
      alternative.cost_excess = 2 * (minimum.cost - update.search.minima.front().cost);
      alternatives.push_back(alternative);
    }
    estimate_source = "estimated";
    // The noise of each channel: the weights of the fit (the identification's residual noise
    // unless the updating section gives one), averaged over the tests that have the channel.
    std::map<std::string, std::pair<double, int>> noise_sums;
    for (size_t t = 0; t < update.records.size(); ++t) {
      const updating::TestFit& fit = result.tests[t];
      recorded.push_back(updating::MakeRecordedDesign(update.records[t], fit.noise_std,
                                                      settings.options.integrator));
      for (size_t c = 0; c < fit.channels.size(); ++c) {
        auto& [sum, count] = noise_sums[fit.channels[c]];
        sum += fit.noise_std[static_cast<Eigen::Index>(c)];
        ++count;
      }
    }
    for (const auto& [channel, sum_count] : noise_sums) {
      recorded_noise[channel] = sum_count.first / sum_count.second;
    }
  }
  FillCandidateNoise(file, recorded_noise, scenario.sensors.noise_std);
  const updating::TestPlan plan =
      updating::PlanNextTest(*model, recorded, file.candidates, options);
  updating::AlternativesPlan at_alternatives;
  if (!alternatives.empty()) {
    if (!common.quiet) {
      std::cerr << fmt::format("mbid: plan: the candidates at {} alternative minimum(s) too\n",
                               alternatives.size());
    }
    at_alternatives =
        updating::PlanAtAlternatives(*model, recorded, file.candidates, plan, alternatives, options,
                                     residual_count, significance);
  }

  nlohmann::json summary;
  summary["candidates"] =
      validation::CandidateScoresToJson(plan, file, at_alternatives, alternatives);
  summary["parameters"] = plan.parameters;
  summary["estimate"] = validation::PerParameterJson(plan.parameters, plan.values);
  summary["estimate_source"] = estimate_source;
  summary["recorded_tests"] = data_paths;
  summary["recorded_score"] = NumberOrNull(plan.recorded_score);
  summary["recorded_undetermined"] = recorded_undetermined;
  summary["recorded_non_unique"] = non_unique;
  if (!alternatives.empty()) {
    nlohmann::json list = nlohmann::json::array();
    for (size_t a = 0; a < alternatives.size(); ++a) {
      nlohmann::json values = nlohmann::json::object();
      for (const auto& [name, value] : alternatives[a].values) values[name] = value;
      list.push_back({{"label", alternatives[a].label},
                      {"values", values},
                      {"cost_excess", NumberOrNull(alternatives[a].cost_excess)},
                      {"threshold", NumberOrNull(at_alternatives.thresholds[a])}});
    }
    summary["alternatives"] = list;
  }
  summary["current_relative_std"] =
      validation::PerParameterJson(plan.parameters, plan.current_relative_std);
  summary["undetermined_relative_std"] = options.undetermined_relative_std;
  summary["score"] =
      "log det(F_recorded + F_candidate + ridge I), F the Fisher information in log coordinates";
  summary["wall_time_s"] = plan.wall_time_s;
  if (!common.json_path.empty()) WriteJson(summary, common.json_path);
  if (common.json_path != "-") {
    PrintPlan(plan, estimate_source);
    if (!recorded_undetermined.empty()) {
      std::cout << fmt::format("the recorded tests' fit leaves undetermined: {}{}\n",
                               fmt::join(recorded_undetermined, ", "),
                               non_unique ? " (other minima of equal fit: the plan is local to the "
                                            "best one)"
                                          : "");
    }
    PrintAlternatives(at_alternatives, alternatives);
  }
  return 0;
}

}  // namespace mbid::app
