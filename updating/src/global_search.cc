#include "mbid/updating/global_search.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <set>
#include <thread>

#include "fit_unknowns.h"
#include "global_search_internal.h"
#include "mbid/common/error.h"
#include "output_error_fit.h"

namespace mbid::updating {
using internal::Differences;
using internal::PoleEquivalentStarts;
using internal::SpaceFillingDesign;
using internal::StartOptions;
using internal::Window;

namespace {

// A start (or screened end) is worth a whole-record fit when its cost is within this factor of
// the best known: alternatives end within a few percent of the best cost.
constexpr double kPromisingCostRatio = 3.0;

// Runs jobs(0..count-1) on up to `threads` threads; each job writes only its own slot, so the
// outcome does not depend on the thread count.
void RunParallel(int count, int threads, const std::function<void(int)>& job) {
  std::atomic<int> next{0};
  auto worker = [&] {
    for (int i = next++; i < count; i = next++) job(i);
  };
  const int workers = std::max(1, std::min(threads, count));
  std::vector<std::thread> pool;
  for (int w = 1; w < workers; ++w) pool.emplace_back(worker);
  worker();
  for (std::thread& thread : pool) thread.join();
}

bool Converged(const UpdateResult& result) {
  return result.termination == UpdateResult::Termination::kConverged;
}

}  // namespace

bool GlobalSearchOptions::IsValid(std::string* why) const {
  auto fail = [why](const std::string& reason) {
    if (why != nullptr) *why = reason;
    return false;
  };
  if (design_starts < 0) return fail("design_starts must be >= 0");
  if (!(screen_fraction > 0 && screen_fraction <= 1)) return fail("screen_fraction in (0, 1]");
  if (screen_iterations < 1) return fail("screen_iterations must be >= 1");
  if (!(screen_relative_tolerance > 0 && screen_relative_tolerance < 1)) {
    return fail("screen_relative_tolerance in (0, 1)");
  }
  if (full_fits < 0) return fail("full_fits must be >= 0");
  if (!(cluster_tolerance > 0 && cluster_tolerance < 1)) {
    return fail("cluster_tolerance in (0, 1)");
  }
  if (!(significance > 0 && significance < 1)) return fail("significance in (0, 1)");
  if (threads < 1) return fail("threads must be >= 1");
  if (!(matched_trust_region_radius >= 0) || !std::isfinite(matched_trust_region_radius)) {
    return fail("matched_trust_region_radius must be >= 0 and finite");
  }
  return true;
}

GlobalSearchResult SearchGlobally(const model::MechanicalModel& model,
                                  const std::vector<TestRecord>& tests,
                                  const UpdateOptions& options, const std::string& primary_label,
                                  const std::vector<SearchStart>& starts,
                                  const GlobalSearchOptions& search,
                                  const std::function<void(const std::string&)>& progress) {
  const auto start_time = std::chrono::steady_clock::now();
  std::string why;
  if (!search.IsValid(&why)) {
    throw InputError("updating", "global_search", why, "valid global search options");
  }
  auto say = [&progress](const std::string& line) {
    if (progress) progress(line);
  };
  GlobalSearchResult result;
  for (const TestRecord& test : tests) {
    result.residual_count += test.record.samples() * test.record.channel_count();
  }
  const std::vector<ParameterSetting> settings = ResolveParameterSettings(model, options);

  // Options for a start: the matched radius where it has the identified poles.
  const auto with_radius = [&search](UpdateOptions base, bool matches_poles) {
    if (matches_poles && search.matched_trust_region_radius > 0) {
      base.initial_trust_region_radius = search.matched_trust_region_radius;
    }
    return base;
  };
  // The primary start: the options' own values (or the scenario's), fitted first and alone.
  UpdateOptions primary =
      with_radius(StartOptions(options, settings, {}), search.primary_matches_poles);
  if (!search.enabled) {
    result.best = UpdateModel(model, tests, primary);
    SearchMinimum only;
    only.fit = result.best;
    only.starts = {primary_label};
    only.cost = result.best.final_cost;
    result.minima.push_back(only);
    result.starts = result.full_fits = 1;
    result.wall_time_s = result.best.wall_time_s;
    return result;
  }
  UpdateOptions local = options;
  local.quiet = true;
  local.threads = 1;
  primary.quiet = true;
  // The user's own thread count: the sensitivity groups change CVODES' error control, so a count
  // tied to the search's would change the bits with it.
  primary.threads = options.threads;
  std::vector<TestRecord> weighted = tests;
  const bool all_given = internal::EveryNoiseGiven(tests);

  struct Run {
    std::string label;
    UpdateResult fit;
    bool failed = false;
  };
  std::vector<Run> full;
  auto fit_full = [&](const std::string& label, const std::map<std::string, double>& values,
                      const UpdateOptions& base) {
    Run run{label, {}, false};
    try {
      run.fit = UpdateModel(model, weighted, StartOptions(base, settings, values));
    } catch (const std::exception& e) {
      run.failed = true;
      run.fit.message = e.what();
    }
    return run;
  };

  // The design: space-filling points in Ceres' coordinates over the bounds, each screened (a
  // short fit on the first part of each record).
  const auto make_design = [&](int count) {
    std::vector<std::map<std::string, double>> design;
    for (const std::vector<double>& point :
         SpaceFillingDesign(count, static_cast<int>(settings.size()), search.seed)) {
      std::map<std::string, double> values;
      for (size_t k = 0; k < settings.size(); ++k) {
        const ParameterSetting& s = settings[k];
        // Uniform in Ceres' coordinates over the bounds.
        values[s.name] =
            s.log_scale
                ? std::exp(std::log(s.lower) + point[k] * (std::log(s.upper) - std::log(s.lower)))
                : s.lower + point[k] * (s.upper - s.lower);
      }
      design.push_back(values);
    }
    return design;
  };
  // The records' first parts, once the weights are known.
  std::vector<TestRecord> windows;
  UpdateOptions screen = local;
  screen.max_iterations = search.screen_iterations;
  screen.continuation_fractions.clear();
  internal::LoosenForScreening(search.screen_relative_tolerance, screen);
  // From space-filling points Ceres rejects about a quarter of the trial points, and at the
  // screens' tolerance a sensitivity run costs ~10 plain ones: speculating does not pay there
  // (docs/performance.md, session 19).
  screen.speculative_jacobians = false;
  struct Screened {
    std::vector<std::map<std::string, double>> design;
    std::vector<Run> batch;
  };
  const auto screen_one = [&](const std::map<std::string, double>& values, size_t d) {
    Run run{fmt::format("design {}", d + 1), {}, false};
    try {
      run.fit = UpdateModel(model, windows, StartOptions(screen, settings, values));
    } catch (const std::exception& e) {
      run.failed = true;
    }
    return run;
  };

  // The primary start first. Where the records give no noise level, its fit estimates one, and
  // every other fit is weighed by it so that all costs are in the same units; where the given
  // starts may settle the search (complete_starts), its fit decides whether the design runs.
  // Otherwise nothing of the design depends on it: it is fitted in the design's batch, which
  // keeps every thread busy while it runs (the same fits, hence the same result).
  const auto batch_start = std::chrono::steady_clock::now();
  const bool design_with_primary = all_given && !search.complete_starts && search.design_starts > 0;
  say(fmt::format("global search: fit from {}{}{}", primary_label,
                  all_given ? "" : " to estimate the noise",
                  design_with_primary
                      ? fmt::format(" beside {} design points on the first {:.0f}% of each record",
                                    search.design_starts, 100 * search.screen_fraction)
                      : ""));
  Screened early;
  if (design_with_primary) {
    windows = Window(weighted, search.screen_fraction);
    early.design = make_design(search.design_starts);
    early.batch.resize(early.design.size());
    Run primary_run;
    RunParallel(static_cast<int>(early.design.size()) + 1, search.threads, [&](int i) {
      if (i == 0) {
        primary_run = fit_full(primary_label, {}, primary);
      } else {
        const size_t d = static_cast<size_t>(i - 1);
        early.batch[d] = screen_one(early.design[d], d);
      }
    });
    full.push_back(primary_run);
  } else {
    full.push_back(fit_full(primary_label, {}, primary));
  }
  if (!all_given) {
    internal::WeighAs(full.front().fit, weighted);
    if (full.front().failed) {
      // The search cannot weigh its fits; the primary fit's failure is the answer.
      result.best = full.front().fit;
      result.starts = result.full_fits = 1;
      return result;
    }
  }

  // Only starts near the best known cost can end as alternatives: one iteration gives a start's
  // cost, and those above kPromisingCostRatio times the best are left out (measured on the
  // crane: other Route-1 sets and pole-equivalent sets whose shapes miss the record start
  // thousands of times higher and end at far minima). Without a converged fit, all are fitted.
  auto fit_promising = [&](const std::vector<SearchStart>& candidates, const std::string& what) {
    double best_cost = std::numeric_limits<double>::infinity();
    for (const Run& run : full) {
      if (!run.failed && Converged(run.fit)) best_cost = std::min(best_cost, run.fit.final_cost);
    }
    UpdateOptions probe = local;
    probe.max_iterations = 1;
    probe.refit_after_noise_estimate = false;
    // A start's cost alone: without continuation it is one evaluation without sensitivities (a
    // sixth of a one-iteration fit); with it, the first window's, which a fit reports.
    std::vector<double> start_costs(candidates.size(), std::numeric_limits<double>::quiet_NaN());
    if (std::isfinite(best_cost)) {
      RunParallel(static_cast<int>(candidates.size()), search.threads, [&](int i) {
        const SearchStart& start = candidates[static_cast<size_t>(i)];
        const UpdateOptions at_start = StartOptions(probe, settings, start.values);
        try {
          start_costs[static_cast<size_t>(i)] =
              probe.continuation_fractions.empty()
                  ? internal::CalcStartCostUpTo(model, weighted, at_start,
                                                kPromisingCostRatio * best_cost)
                  : UpdateModel(model, weighted, at_start).initial_cost;
        } catch (const std::exception&) {
          // A start whose simulation fails is not promising.
        }
      });
    }
    std::vector<SearchStart> promising;
    for (size_t i = 0; i < candidates.size(); ++i) {
      if (!std::isfinite(best_cost) || start_costs[i] <= kPromisingCostRatio * best_cost) {
        promising.push_back(candidates[i]);
      } else {
        result.judged_starts.push_back(candidates[i].label);
      }
    }
    std::vector<Run> fitted(promising.size());
    RunParallel(static_cast<int>(promising.size()), search.threads, [&](int i) {
      const SearchStart& start = promising[static_cast<size_t>(i)];
      fitted[static_cast<size_t>(i)] =
          fit_full(start.label, start.values, with_radius(local, start.matches_poles));
    });
    for (const Run& run : fitted) {
      if (!run.failed && Converged(run.fit)) result.judged_starts.push_back(run.label);
    }
    full.insert(full.end(), fitted.begin(), fitted.end());
    if (promising.size() < candidates.size()) {
      result.notes.push_back(fmt::format(
          "{} of {} {} start above {} times the best cost: not fitted",
          candidates.size() - promising.size(), candidates.size(), what, kPromisingCostRatio));
    }
  };

  // The other given starts (Route 1's other sets) that start near the primary's cost.
  if (!starts.empty()) {
    say(fmt::format("global search: {} further given start(s) (Route 1's other sets)",
                    starts.size()));
    fit_promising(starts, "further given start(s)");
  }

  // The design, unless the given starts settle the question: they hold every parameter set
  // that matches the identified poles (complete_starts) and the best of them explains the
  // records to their noise, so that no other minimum can fit better and an equally good one
  // would be among them.
  bool settled = false, settled_by_caller = false;
  if (search.complete_starts) {
    const Run* least = nullptr;
    for (const Run& run : full) {
      if (run.failed || !Converged(run.fit)) continue;
      settled = settled || run.fit.explains_records;
      if (least == nullptr || run.fit.final_cost < least->fit.final_cost) least = &run;
    }
    if (!settled && least != nullptr && search.explains_records) {
      settled = settled_by_caller = search.explains_records(tests, options, least->fit);
    }
  }
  const int design_count = settled ? 0 : search.design_starts;
  if (settled) {
    result.notes.push_back(fmt::format(
        "no space-filling design: the given starts hold every set that matches the identified "
        "poles, and the best of them fits the records to their noise{}",
        settled_by_caller ? " (once its releases are placed)" : ""));
  }
  Screened screened = std::move(early);
  if (!design_with_primary) {
    windows = Window(weighted, search.screen_fraction);
    screened.design = make_design(design_count);
    if (!screened.design.empty()) {
      say(fmt::format("global search: {} design points on the first {:.0f}% of each record",
                      screened.design.size(), 100 * search.screen_fraction));
    }
    screened.batch.resize(screened.design.size());
    RunParallel(static_cast<int>(screened.batch.size()), search.threads, [&](int i) {
      const size_t d = static_cast<size_t>(i);
      screened.batch[d] = screen_one(screened.design[d], d);
    });
  }
  const std::vector<std::map<std::string, double>>& design = screened.design;
  const std::vector<Run>& batch = screened.batch;
  result.starts = static_cast<int>(1 + starts.size() + design.size());
  result.screen_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - batch_start).count();
  result.screened = static_cast<int>(design.size());

  // The best distinct screened ends (a failed window fit has nothing to offer), minus those
  // already reached by a whole-record fit.
  std::vector<size_t> order;
  for (size_t i = 0; i < batch.size(); ++i) {
    if (!batch[i].failed && batch[i].fit.termination != UpdateResult::Termination::kFailure &&
        std::isfinite(batch[i].fit.final_cost)) {
      order.push_back(i);
    }
  }
  std::stable_sort(order.begin(), order.end(), [&batch](size_t a, size_t b) {
    return batch[a].fit.final_cost < batch[b].fit.final_cost;
  });
  std::vector<size_t> chosen;
  for (size_t i : order) {
    if (static_cast<int>(chosen.size()) >= search.full_fits) break;
    // Ends far above the best screened cost lead to far minima (measured on the crane's load
    // drop: window costs 6 times the best end 6 times above the best whole-record cost).
    if (batch[i].fit.final_cost > kPromisingCostRatio * batch[order.front()].fit.final_cost) {
      break;
    }
    bool known = false;
    for (size_t j : chosen) {
      known = known || Differences(batch[i].fit, batch[j].fit, search.cluster_tolerance).empty();
    }
    if (!known) chosen.push_back(i);
  }
  if (!chosen.empty()) {
    say(fmt::format("global search: {} screened end(s) fitted on the whole records",
                    chosen.size()));
  }
  std::vector<Run> refits(chosen.size());
  RunParallel(static_cast<int>(chosen.size()), search.threads, [&](int i) {
    const Run& end = batch[chosen[static_cast<size_t>(i)]];
    std::map<std::string, double> values;
    for (const ParameterEstimate& p : end.fit.parameters) {
      if (p.test.empty()) values[p.name] = p.value;
    }
    refits[static_cast<size_t>(i)] = fit_full(end.label, values, local);
  });
  full.insert(full.end(), refits.begin(), refits.end());

  // The sets with the best end's own poles (eq. 7 on the tuned model's exact modes): joints
  // trading roles give the same frequencies and dampings and differ only in what the record's
  // mode shapes show, so a poorly excited mode leaves such a set as good a fit. The design
  // finds them by chance; eq. 7 lists them.
  const auto best_so_far = [&full]() -> const Run* {
    const Run* provisional = nullptr;
    for (const Run& run : full) {
      if (run.failed || !Converged(run.fit)) continue;
      if (provisional == nullptr || run.fit.final_cost < provisional->fit.final_cost) {
        provisional = &run;
      }
    }
    return provisional;
  };
  if (search.pole_equivalent_starts && !search.complete_starts) {
    const Run* provisional = best_so_far();
    std::vector<SearchStart> equivalent;
    if (provisional != nullptr) {
      equivalent = PoleEquivalentStarts(model, provisional->fit, search.seed);
    }
    if (!equivalent.empty()) {
      say(
          fmt::format("global search: {} set(s) with the best end's poles (eq. 7) fitted on the "
                      "whole records",
                      equivalent.size()));
    }
    fit_promising(equivalent, "set(s) with the best end's poles");
    result.starts += static_cast<int>(equivalent.size());
    result.pole_equivalent = static_cast<int>(equivalent.size());
  }
  // A mode of the best end at or above the records' Nyquist frequency shows in them only as its
  // alias below, which a joint set with that mode there shows as well (and a logger's
  // anti-alias filter records nothing above). A trial's stiff mast pin, 46.7 Hz sampled at
  // 100 Hz, was tuned to 53.3 Hz, 30 % too stiff and 38 of its standard deviations off,
  // "passed" as unique: Route 1 had no such mode and the design was skipped; the fit from the
  // alias ends lower. These sets are fitted whatever settled the search.
  double nyquist_hz = std::numeric_limits<double>::infinity();
  for (const TestRecord& test : tests) {
    nyquist_hz = std::min(nyquist_hz, 0.5 / test.record.sample_interval_s);
  }
  if (const Run* provisional = best_so_far(); provisional != nullptr) {
    std::vector<std::string> moved;
    const std::vector<SearchStart> aliased =
        internal::AliasStarts(model, provisional->fit, search.seed, nyquist_hz, &moved);
    if (!aliased.empty()) {
      say(
          fmt::format("global search: {} set(s) with the best end's modes above Nyquist moved to "
                      "their aliases ({}) fitted on the whole records",
                      aliased.size(), fmt::join(moved, ", ")));
      fit_promising(aliased, "set(s) with the best end's aliased modes");
      result.starts += static_cast<int>(aliased.size());
      result.aliased = static_cast<int>(aliased.size());
      result.notes.push_back(fmt::format(
          "a mode of the best end lies above the records' Nyquist frequency {:.4g} Hz ({}): the "
          "joint sets with it at its alias were fitted too",
          nyquist_hz, fmt::join(moved, ", ")));
    }
  }
  // No whole-record fit converged within its iterations: in a flat valley (two springs in series
  // that one sensor sees as one) Levenberg-Marquardt creeps. The least-cost end goes on once for
  // three times the iterations, from where it stopped (a trial's series springs: exit 3 after
  // 50 iterations in 20 of 20 records; converged in 178, every parameter rightly undetermined).
  if (best_so_far() == nullptr) {
    const Run* least = nullptr;
    for (const Run& run : full) {
      if (run.failed || run.fit.termination != UpdateResult::Termination::kNoConvergence) continue;
      if (least == nullptr || run.fit.final_cost < least->fit.final_cost) least = &run;
    }
    if (least != nullptr) {
      std::map<std::string, double> end;
      for (const ParameterEstimate& p : least->fit.parameters) {
        if (p.test.empty()) end[p.name] = p.value;
      }
      UpdateOptions longer = local;
      longer.max_iterations = 3 * local.max_iterations;
      say(
          fmt::format("global search: no fit converged in {} iterations; the least-cost end "
                      "({}) goes on for up to {}",
                      local.max_iterations, least->label, longer.max_iterations));
      const std::string label = least->label;
      full.push_back(fit_full(label, end, longer));
      result.notes.push_back(fmt::format(
          "no fit converged in {} iterations; the least-cost end ({}) went on for up to {}: {}",
          local.max_iterations, label, longer.max_iterations, full.back().fit.termination_name()));
    }
  }
  result.full_fits = static_cast<int>(full.size());

  // Distinct minima among the converged whole-record fits, by ascending cost (ties: start
  // order, so the given starts win).
  std::vector<size_t> converged;
  for (size_t i = 0; i < full.size(); ++i) {
    if (!full[i].failed && Converged(full[i].fit)) converged.push_back(i);
  }
  std::stable_sort(converged.begin(), converged.end(), [&full](size_t a, size_t b) {
    return full[a].fit.final_cost < full[b].fit.final_cost;
  });
  for (size_t i : converged) {
    bool merged = false;
    for (SearchMinimum& minimum : result.minima) {
      if (Differences(minimum.fit, full[i].fit, search.cluster_tolerance).empty()) {
        minimum.starts.push_back(full[i].label);
        merged = true;
        break;
      }
    }
    if (!merged) {
      SearchMinimum minimum;
      minimum.fit = full[i].fit;
      minimum.starts = {full[i].label};
      minimum.cost = full[i].fit.final_cost;
      result.minima.push_back(minimum);
    }
  }
  if (result.minima.empty()) {
    // Nothing converged: the primary start's fit carries the failure.
    result.best = full.front().fit;
    if (full.front().failed) result.best.termination = UpdateResult::Termination::kFailure;
    result.notes.push_back("no local fit converged");
  } else {
    const SearchMinimum& best = result.minima.front();
    const double k = static_cast<double>(best.fit.parameters.size());
    const double dof = std::max(1.0, result.residual_count - k);
    const double scale = std::max(2 * best.cost / dof, 1e-300);
    for (size_t m = 1; m < result.minima.size(); ++m) {
      SearchMinimum& minimum = result.minima[m];
      minimum.f_statistic = 2 * (minimum.cost - best.cost) / k / scale;
      minimum.p_value = FSurvival(minimum.f_statistic, k, dof);
      minimum.alternative = minimum.p_value > search.significance;
      minimum.differs_in = Differences(best.fit, minimum.fit, search.cluster_tolerance, false);
    }
    result.best = best.fit;
    std::set<std::string> differing;
    int alternatives = 0;
    for (const SearchMinimum& minimum : result.minima) {
      if (!minimum.alternative) continue;
      ++alternatives;
      differing.insert(minimum.differs_in.begin(), minimum.differs_in.end());
    }
    result.non_unique = alternatives > 0;
    for (const ParameterEstimate& p : result.best.parameters) {
      if (differing.count(p.name) > 0) result.differing.push_back(p.name);
    }
    for (ParameterEstimate& p : result.best.parameters) {
      if (differing.count(p.name) == 0) continue;
      p.determined = false;
      p.rival_differs = true;
      p.why_undetermined = "the alternative minima differ in it";
      if (std::find(result.best.undetermined.begin(), result.best.undetermined.end(), p.name) ==
          result.best.undetermined.end()) {
        result.best.undetermined.push_back(p.name);
      }
    }
    if (result.non_unique) {
      // Minima that differ only by a mode above Nyquist and its alias: which one the test had,
      // the samples cannot say; a logger's anti-alias filter can.
      std::string alias_note;
      if (result.aliased > 0 &&
          internal::FrequenciesAbove(model, result.best, nyquist_hz).empty()) {
        bool all_above = true;
        std::vector<std::string> above;
        for (const SearchMinimum& minimum : result.minima) {
          if (!minimum.alternative) continue;
          const std::vector<double> f = internal::FrequenciesAbove(model, minimum.fit, nyquist_hz);
          all_above = all_above && !f.empty();
          for (double hz : f) above.push_back(fmt::format("{:.4g} Hz", hz));
        }
        if (all_above) {
          alias_note = fmt::format(
              ". The alternatives put a mode above the records' Nyquist frequency {:.4g} Hz ({}), "
              "where the samples show only its alias, a mode of the best's: a record taken "
              "through an anti-alias filter (most loggers) has no mode above Nyquist, and with "
              "one the best's values stand; without, sample faster to tell them apart",
              nyquist_hz, fmt::join(above, ", "));
        }
      }
      result.best.warnings.push_back(fmt::format(
          "non-unique: {} other minimum(s) fit the records as well as the best (F-test at {}); "
          "they differ in {}{}",
          alternatives, search.significance, fmt::join(result.differing, ", "), alias_note));
    }
    result.notes.push_back(fmt::format(
        "global search: {} starts ({} given, {} design, {} with the best end's poles{}), {} "
        "whole-record fits, {} distinct minima, {} alternative(s)",
        result.starts, result.starts - result.screened - result.pole_equivalent - result.aliased,
        result.screened, result.pole_equivalent,
        result.aliased > 0 ? fmt::format(", {} with its aliased modes", result.aliased) : "",
        result.full_fits, result.minima.size(), alternatives));
    if (best.starts.front() != primary_label) {
      result.notes.push_back(fmt::format("the best minimum was reached from {}, not from {}",
                                         fmt::join(best.starts, ", "), primary_label));
    }
  }
  if (!result.notes.empty())
    result.best.message += fmt::format("; {}", fmt::join(result.notes, "; "));
  result.wall_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_time).count();
  return result;
}

}  // namespace mbid::updating
