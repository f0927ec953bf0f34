#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "mbid/model/mechanical_model.h"
#include "mbid/updating/output_error.h"

namespace mbid::updating {

// Route 2 from many starts. A local fit from a design model 25-35% off can end in a far minimum
// of the oscillatory output error (a slipped cycle, two joints trading roles) whose Fisher
// standard deviations look as small as the true one's. The search fits from the given starts
// (the scenario's or explicit values, every admissible Route-1 set) and from a seeded
// space-filling design over the bounds, keeps every distinct end point, and reports those whose
// cost the records cannot tell from the best (an F-test on the weighted cost) as alternatives:
// two or more left means the minimum is not unique, in the parameters named.
//
// To stay within a few local fits of work, the design points are screened first: each is fitted
// on the first `screen_fraction` of every record (fewer cycles to slip, fewer minima, a
// fraction of the cost per simulation) for at most `screen_iterations`; only the best distinct
// screened ends, and the given starts, are fitted on the whole records.
struct GlobalSearchOptions {
  bool enabled = true;     // false: one local fit from the first start
  int design_starts = 12;  // space-filling points (scrambled Halton in log p over the bounds)
  std::uint64_t seed = 1;  // of the design's scrambling
  // Screening of the design points (the given starts are fitted in full directly).
  double screen_fraction = 0.3;
  int screen_iterations = 20;
  // A screen integrates the state at this relative tolerance where the fit's own is tighter,
  // and loosens the absolute and the sensitivities' tolerances by the same factor: it only
  // seeks a basin, whose end is fitted again at the fit's own tolerances. At 1e-5 the
  // simulation's error stays far below a noise of 1% of the signal; the crane's load-drop
  // update took 0.55 of the CPU it took with the screens at 1e-8 (docs/performance.md).
  double screen_relative_tolerance = 1e-5;
  // Whole-record fits from at most this many distinct screened ends, best screened cost first.
  int full_fits = 3;
  // Two end points are one minimum when every tuned log-scale parameter agrees to this
  // (relative; linear-scale ones relative to max(|value|, 1e-6)) or to within 3 of their
  // combined standard deviations.
  double cluster_tolerance = 0.02;
  // An end point is an alternative to the best when the F-test of their weighted costs, with
  // the tuned parameters' count and the residuals' degrees of freedom, does not separate them
  // at this level.
  double significance = 0.05;
  int threads = 1;  // local fits in parallel (each fit then runs single-threaded)
  // The given starts hold every parameter set that matches the identified poles (Route 1
  // solved on as many modes as coordinates): when the best of them fits the records to their
  // noise, the design is skipped (an equally good minimum reproduces the poles, so it is one of
  // them). Set by the caller.
  bool complete_starts = false;
  // Whether a converged fit explains the records where its own judgment (explains_records) is
  // not the last word: records whose detected release the caller places after the search
  // (validation/release_profile.h), where a release a fraction of a sample off leaves a misfit
  // the placed fit does not have. Asked of the best given start when complete_starts and no
  // fit explains the records itself, with the search's own records and options; unset: the
  // fits' own judgment.
  std::function<bool(const std::vector<TestRecord>&, const UpdateOptions&, const UpdateResult&)>
      explains_records;
  // Otherwise the sets with the best end's own poles (eq. 7 on its exact modes: joints that
  // trade roles) are fitted too; each is a candidate alternative the design may have missed.
  bool pole_equivalent_starts = true;
  // Ceres' initial trust region radius for starts that have the identified poles: the given
  // starts marked `matches_poles` (Route 1's sets) and the primary start when
  // `primary_matches_poles` (set by the caller). They sit in the records' basin already, where
  // the cautious first steps of UpdateOptions::initial_trust_region_radius, meant for starts of
  // unknown quality, slow Gauss-Newton down (the reference crane: 5 -> 3 iterations, the same
  // cost within 1e-7) or stop it early on a flat valley's slope (tests/updating/
  // global_search_test.cc). 0: the options' own radius for every start.
  double matched_trust_region_radius = 1e3;
  bool primary_matches_poles = false;

  bool IsValid(std::string* why) const;
};

// A start: values of tuned shared parameters (others take the primary start's values).
struct SearchStart {
  std::string label;  // "scenario", "route1 set 2", "design 5", ...
  std::map<std::string, double> values;
  bool matches_poles = false;  // has the identified poles (GlobalSearchOptions)
};

// One distinct end point of the local fits.
struct SearchMinimum {
  UpdateResult fit;
  std::vector<std::string> starts;  // labels of the starts that ended here
  double cost = 0;                  // fit.final_cost (1/2 sum of squared weighted residuals)
  double f_statistic = 0;           // against the best; 0 for the best itself
  double p_value = 1;               // of the F-test; 1 for the best
  bool alternative = false;         // statistically indistinguishable from the best
  // Shared parameters outside the best's value +- 3 of the best's standard deviations (and
  // the clustering tolerance): what the records leave open if this is an alternative.
  std::vector<std::string> differs_in;
};

struct GlobalSearchResult {
  UpdateResult best;                   // the local fit at the lowest cost, with the marks below
  std::vector<SearchMinimum> minima;   // distinct end points by ascending cost; [0] is the best
  bool non_unique = false;             // at least one alternative to the best
  std::vector<std::string> differing;  // parameters in which the alternatives differ from it
  int starts = 0;                      // given + design
  int screened = 0;                    // design points fitted on the windows
  int pole_equivalent = 0;             // sets with the best end's poles (eq. 7)
  int aliased = 0;         // sets with its modes above the records' Nyquist moved to their aliases
  int full_fits = 0;       // whole-record local fits
  int residual_count = 0;  // samples x channels over the tests
  double wall_time_s = 0;
  double screen_time_s = 0;        // of the given starts' and design points' batch
  std::vector<std::string> notes;  // what the search did, in words
  // Starts the whole records judged: fitted to a converged end, or starting above the promising
  // cost (3 times the best). A Route-1 rival among them is settled by the F-test on the minima,
  // not by its initial-state mismatch.
  std::vector<std::string> judged_starts;
};

// The shared model parameters of `options` (every model parameter if it names none) with their
// start and bounds resolved as UpdateModel resolves them.
std::vector<ParameterSetting> ResolveParameterSettings(const model::MechanicalModel& model,
                                                       const UpdateOptions& options);

// The search. `starts` lists the given starts besides the options' own (which is always the
// first, labelled `primary_label`); bounds are the options' (resolved at the primary start) for
// every start. Weights: channels without a given noise level get the one the primary start's
// fit estimates, so that every fit's cost is in the same units. `progress`, if set, hears one
// line per stage. `best` gets the alternatives' differing parameters marked undetermined, a
// warning, and a message naming the search.
GlobalSearchResult SearchGlobally(const model::MechanicalModel& model,
                                  const std::vector<TestRecord>& tests,
                                  const UpdateOptions& options, const std::string& primary_label,
                                  const std::vector<SearchStart>& starts,
                                  const GlobalSearchOptions& search,
                                  const std::function<void(const std::string&)>& progress = {});

// The F-test's upper quantile F(1 - alpha; d1, d2) and survival P(F > f) (Boost.Math).
double FQuantile(double alpha, double d1, double d2);
double FSurvival(double f, double d1, double d2);

}  // namespace mbid::updating
