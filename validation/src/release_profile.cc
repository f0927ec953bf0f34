#include "mbid/validation/release_profile.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <optional>

#include "mbid/identification/release.h"
#include "mbid/updating/credibility.h"

namespace mbid::validation {
namespace {

// A local fit of `tests` from `start` (shared parameters at its values, the same weights).
updating::UpdateResult FitFrom(const model::MechanicalModel& model,
                               const std::vector<updating::TestRecord>& tests,
                               const updating::UpdateOptions& base,
                               const updating::UpdateResult& start) {
  std::unique_ptr<model::MechanicalModel> clone = model.Clone();
  updating::ApplyEstimates(start, *clone);
  updating::UpdateOptions options = base;
  options.quiet = true;
  options.continuation_fractions.clear();
  options.refit_after_noise_estimate = false;
  options.parameters.clear();
  for (const updating::ParameterEstimate& p : start.parameters) {
    if (!p.test.empty()) continue;  // nuisance parameters start where the tests say
    options.parameters.push_back(
        {p.name, std::clamp(p.value, p.lower, p.upper), p.lower, p.upper, p.log_scale});
  }
  return updating::UpdateModel(*clone, tests, options);
}

// The fit at the placed release, with the judgments made of `judged` from outside its fit kept:
// parameters the global search or Route 1 left undetermined (alternative minima, ambiguous
// sets: ParameterEstimate::rival_differs) stay so, and no warning is lost. What the fit judges
// itself (its std, its credibility from the residual) is the placed fit's: a record cut half a
// sample off leaves a structured residual that the placed fit no longer has.
updating::UpdateResult Merge(const updating::UpdateResult& judged,
                             const updating::UpdateResult& placed) {
  updating::UpdateResult merged = placed;
  for (updating::ParameterEstimate& p : merged.parameters) {
    for (const updating::ParameterEstimate& q : judged.parameters) {
      if (q.name != p.name || !q.rival_differs) continue;
      p.determined = false;
      p.rival_differs = true;
      p.why_undetermined = q.why_undetermined;
      if (std::find(merged.undetermined.begin(), merged.undetermined.end(), p.name) ==
          merged.undetermined.end()) {
        merged.undetermined.push_back(p.name);
      }
    }
  }
  // Credibility is the fit's own (credibility.cc, judged from its residual): the placed fit's.
  // The judged fit's own judgments of its estimate (output_error_fit.cc: a parameter at a
  // bound, undetermined by the rank, two correlated) are the misplaced fit's and give way to the
  // placed fit's; the search's (alternative minima, non-unique) stay. A stale "the records leave
  // undetermined: d_eta" beside a placed d_eta reported determined said the opposite.
  merged.warnings.clear();
  for (const std::string& line : judged.warnings) {
    const bool own = line.rfind("the records leave undetermined: ", 0) == 0 ||
                     line.find(" ends at a bound (") != std::string::npos ||
                     line.find(" are correlated ") != std::string::npos;
    if (!own) merged.warnings.push_back(line);
  }
  for (const std::string& line : placed.warnings) {
    if (std::find(merged.warnings.begin(), merged.warnings.end(), line) == merged.warnings.end()) {
      merged.warnings.push_back(line);
    }
  }
  // The path from the start is the global search's (the convergence figure).
  merged.initial_cost = judged.initial_cost;
  merged.iterations = judged.iterations;
  merged.history = judged.history;
  return merged;
}

bool Usable(const updating::UpdateResult& fit) {
  return fit.termination != updating::UpdateResult::Termination::kFailure &&
         std::isfinite(fit.final_cost);
}

}  // namespace

Measurement MoveRelease(const Measurement& record, double delta_s) {
  // The record's times are from the release: a release delta_s later is a cut at delta_s.
  return identification::CutAtRelease(record, delta_s, record.source);
}

Measurement AsFitted(const Measurement& cut, const updating::TestFit& fit) {
  return fit.release_shift_s == 0 ? cut : MoveRelease(cut, fit.release_shift_s);
}

void WidenForReleases(const std::map<std::string, double>& added_variance,
                      const updating::UpdateOptions& options, updating::UpdateResult* best) {
  for (updating::ParameterEstimate& p : best->parameters) {
    const auto added = added_variance.find(p.name);
    if (added == added_variance.end() || !std::isfinite(p.std)) continue;
    p.std = std::sqrt(p.std * p.std + added->second);
    if (p.value != 0) p.relative_std = p.std / std::abs(p.value);
    updating::SetInterval(p, best->std_inflation);  // from the widened std
    // A parameter the release's uncertainty moves too far is no longer determined by the records.
    if (p.determined && updating::MarkIfSpreadUndetermined(p, best->std_inflation,
                                                           options.undetermined_relative_std)) {
      p.why_undetermined += " with the release's uncertainty";
      best->undetermined.push_back(p.name);
    }
  }
}

ReleasePlacement FindReleasePlacement(const model::MechanicalModel& model,
                                      const std::vector<updating::TestRecord>& tests,
                                      const updating::UpdateOptions& options,
                                      const updating::UpdateResult& from) {
  ReleasePlacement placement;
  placement.from_cost = from.final_cost;
  for (const updating::ParameterEstimate& p : from.parameters) placement.from[p.name] = p.value;
  placement.records = tests;
  placement.fit = from;
  std::vector<updating::TestRecord>* records = &placement.records;
  updating::UpdateResult* best = &placement.fit;
  std::vector<size_t>& detected = placement.detected;
  for (size_t t = 0; t < records->size(); ++t) {
    if ((*records)[t].release_detected) detected.push_back(t);
  }
  if (detected.empty() || best->termination == updating::UpdateResult::Termination::kFailure) {
    detected.clear();
    return placement;
  }
  // The weights the best fit used, kept for every fit of the profile: costs must compare.
  for (size_t t = 0; t < records->size() && t < best->tests.size(); ++t) {
    const updating::TestFit& fit = best->tests[t];
    for (size_t c = 0; c < fit.channels.size(); ++c) {
      (*records)[t].noise_std[fit.channels[c]] = fit.noise_std[static_cast<Eigen::Index>(c)];
    }
  }
  std::vector<Measurement> as_detected;
  for (size_t t : detected) as_detected.push_back((*records)[t].record);
  std::vector<double>& shift = placement.shift_s;
  std::vector<double>& sigma = placement.std_s;
  std::vector<bool>& placed = placement.placed;
  shift.assign(detected.size(), 0.0);
  sigma.assign(detected.size(), NAN);
  placed.assign(detected.size(), false);
  // Per test and shared parameter, how far the parameter moves per second of the test's release.
  std::vector<std::map<std::string, double>> release_slope(detected.size());
  // Each sweep's move of each release, the last sweep's kept.
  std::vector<double> last_move(detected.size(), 0.0), previous_move(detected.size(), 0.0);
  // One test's release is placed with the others where they are; further sweeps place each
  // again with the others placed, until no release moves by a tenth of its std (two noise-free
  // 100 Hz records, one cut 0.4 samples late: both placed to 0.0024 samples, errors shrinking by
  // 4 per sweep: 0.19, 0.04, 0.01 samples after three sweeps, 4 of their std still).
  const int sweeps = detected.size() > 1 ? 8 : 1;
  for (int sweep = 0; sweep < sweeps; ++sweep) {
    double largest_move = 0;  // in the release's std
    for (size_t i = 0; i < detected.size(); ++i) {
      const size_t t = detected[i];
      const double half = 0.5 * as_detected[i].sample_interval_s;
      // The fit at the current centre; each local fit starts from it (a release found far off
      // moves the parameters far from the fit at the detected instant).
      updating::UpdateResult at_centre = *best, before, after, trial;
      const auto cost_at = [&](double at, updating::UpdateResult* fit) {
        std::vector<updating::TestRecord> moved = *records;
        moved[t].record = MoveRelease(as_detected[i], at);
        *fit = FitFrom(model, moved, options, Usable(at_centre) ? at_centre : *best);
        return Usable(*fit) ? fit->final_cost : std::numeric_limits<double>::quiet_NaN();
      };
      // The parabola's half-width: half a sample first, then twice the instant's std, where the
      // cost is the parabola. A 19 Hz mode in a strong accelerometer channel pins a 250 Hz
      // record's release to 0.75 us; the parabola through +-2 ms put it 8.6 std off, and a
      // parameter 5 of its std off was reported determined.
      const auto scale = [&](double std_s) { return std::clamp(2 * std_s, 1e-4 * half, half); };
      double h = std::isfinite(sigma[i]) ? scale(sigma[i]) : half;
      double centre = shift[i];
      double c0 = cost_at(centre, &at_centre);
      bool ok = std::isfinite(c0);
      double h_beside = h;  // where `before` and `after` were fitted: centre -+ h_beside
      // Newton steps on the profile, each at most two samples (a release detected several
      // samples off, a noisy onset at 10 kHz, is followed all the way), each taken only where it
      // lowers the cost, until a step at the instant's own scale is a tenth of its std.
      bool scanned = false;
      for (int round = 0; ok && round < 12; ++round) {
        const double cm = cost_at(centre - h, &before), cp = cost_at(centre + h, &after);
        h_beside = h;
        const double curvature = (cm - 2 * c0 + cp) / (h * h);
        if (!(std::isfinite(curvature) && curvature > 0)) {
          // No parabola here: the instant may be far off (a load drop's release placed by two
          // of its four modes, 5.5 samples early, where the cost bends the other way). Once,
          // the cost 1, 2, 4 and 8 samples either way; from the least of them, again.
          ok = false;
          if (scanned) break;
          scanned = true;
          double least = std::min({c0, std::isfinite(cm) ? cm : c0, std::isfinite(cp) ? cp : c0});
          double at = centre;
          for (const int k : {-1, 1, -2, 2, -4, 4, -8, 8}) {
            const double c = cost_at(centre + 2 * k * half, &trial);
            if (c < least) {
              least = c;
              at = centre + 2 * k * half;
              at_centre = trial;
            }
          }
          if (at == centre) break;
          centre = at;
          c0 = least;
          h = half;
          ok = true;
          continue;
        }
        sigma[i] = 1 / std::sqrt(curvature);  // cost = chi^2 / 2: one std raises it by 1/2
        const bool local = scale(sigma[i]) >= h / 1.5;  // measured at the instant's own scale
        double step = std::clamp(-(cp - cm) / (2 * h) / curvature, -4 * half, 4 * half);
        if (local && std::abs(step) < 0.1 * sigma[i]) break;
        double c_new = cost_at(centre + step, &trial);
        if (!(c_new < c0)) {
          // Not the parabola there: the lower of the two costs beside it, or none.
          step = std::min(cm, cp) < c0 ? (cm < cp ? -h : h) : 0.0;
          c_new = std::min(cm, cp);
          trial = cm < cp ? before : after;
        }
        if (step == 0 && local) break;
        if (step != 0) {
          centre += step;
          c0 = c_new;
          at_centre = trial;
        }
        h = scale(sigma[i]);
      }
      placed[i] = ok;
      if (!ok) {
        (*records)[t].record = MoveRelease(as_detected[i], shift[i]);
        continue;
      }
      last_move[i] = centre - shift[i];
      largest_move = std::max(largest_move, std::abs(last_move[i]) / sigma[i]);
      shift[i] = centre;
      (*records)[t].record = MoveRelease(as_detected[i], centre);
      *best = Merge(*best, at_centre);
      // The slope between the two fits beside the placed instant.
      release_slope[i].clear();
      for (const updating::ParameterEstimate& p : at_centre.parameters) {
        if (!p.test.empty()) continue;
        double low = NAN, high = NAN;
        for (const auto& q : before.parameters) {
          if (q.name == p.name) low = q.value;
        }
        for (const auto& q : after.parameters) {
          if (q.name == p.name) high = q.value;
        }
        const double slope = (high - low) / (2 * h_beside);
        if (std::isfinite(slope)) release_slope[i][p.name] = slope;
      }
    }
    if (!(largest_move >= 0.1)) break;
    // Placing one release with the others held converges geometrically (each sweep's moves a
    // fixed fraction of the last's, the releases coupled through the shared parameters): after
    // two such sweeps every release goes to the sequence's limit (Aitken), which the next sweep
    // checks. The example above: from 0.01 to 0.0001 samples, three sweeps fewer.
    if (sweep >= 1 && sweep + 2 < sweeps) {
      std::vector<double> ratio(detected.size(), NAN);
      bool geometric = true;
      for (size_t i = 0; i < detected.size() && geometric; ++i) {
        if (!placed[i] || last_move[i] == 0) continue;
        ratio[i] = last_move[i] / previous_move[i];
        geometric = ratio[i] > 0 && ratio[i] < 0.9;
      }
      if (geometric) {
        for (size_t i = 0; i < detected.size(); ++i) {
          if (!std::isfinite(ratio[i])) continue;
          shift[i] += last_move[i] * ratio[i] / (1 - ratio[i]);
          (*records)[detected[i]].record = MoveRelease(as_detected[i], shift[i]);
        }
      }
    }
    previous_move = last_move;
    if (sweep > 0 && sweep + 1 == sweeps) {
      // Still moving: what the sweeps have left is part of each release's uncertainty.
      for (size_t i = 0; i < detected.size(); ++i) sigma[i] = std::hypot(sigma[i], last_move[i]);
    }
  }
  // What each release's uncertainty moves each shared parameter by: its slope times the std.
  for (size_t i = 0; i < detected.size(); ++i) {
    if (!placed[i]) continue;
    for (const auto& [name, slope] : release_slope[i]) {
      placement.added_variance[name] += slope * sigma[i] * slope * sigma[i];
    }
  }
  return placement;
}

bool ReleasePlacement::From(const updating::UpdateResult& other) const {
  if (!(other.final_cost == from_cost) || other.parameters.size() != from.size()) return false;
  for (const updating::ParameterEstimate& p : other.parameters) {
    const auto value = from.find(p.name);
    if (value == from.end() || !(value->second == p.value)) return false;
  }
  return true;
}

std::vector<std::string> TakeReleasePlacement(const ReleasePlacement& placement,
                                              std::vector<updating::TestRecord>* records,
                                              const updating::UpdateOptions& options,
                                              updating::UpdateResult* best) {
  std::vector<std::string> lines;
  const std::vector<size_t>& detected = placement.detected;
  if (detected.empty()) return lines;
  const std::vector<double>& shift = placement.shift_s;
  const std::vector<double>& sigma = placement.std_s;
  const std::vector<bool>& placed = placement.placed;
  *records = placement.records;
  if (std::find(placed.begin(), placed.end(), true) != placed.end()) {
    *best = Merge(*best, placement.fit);
  }
  WidenForReleases(placement.added_variance, options, best);
  for (size_t i = 0; i < detected.size(); ++i) {
    const std::string& name = (*records)[detected[i]].name;
    if (detected[i] < best->tests.size() && placed[i]) {
      best->tests[detected[i]].release_shift_s = shift[i];
      best->tests[detected[i]].release_shift_std_s = sigma[i];
    }
    if (!placed[i]) {
      lines.push_back(fmt::format(
          "{}: the fit does not place the release (its cost has no least point near the "
          "detected instant); kept as detected",
          name));
      continue;
    }
    lines.push_back(fmt::format(
        "{}: the fit places the release {:.3g} ms {} the detected instant (+- {:.2g} ms, {:.2g} "
        "samples); the standard deviations include what that uncertainty moves",
        name, 1e3 * std::abs(shift[i]), shift[i] < 0 ? "before" : "after", 1e3 * sigma[i],
        sigma[i] / placement.records[detected[i]].record.sample_interval_s));
  }
  for (const std::string& line : lines) best->warnings.push_back(line);
  return lines;
}

std::vector<std::string> PlaceDetectedReleases(const model::MechanicalModel& model,
                                               std::vector<updating::TestRecord>* records,
                                               const updating::UpdateOptions& options,
                                               updating::UpdateResult* best) {
  return TakeReleasePlacement(FindReleasePlacement(model, *records, options, *best), records,
                              options, best);
}

ReleasePlacer PlaceReleasesEarly(const model::MechanicalModel& model,
                                 updating::GlobalSearchOptions* search) {
  auto kept = std::make_shared<std::optional<ReleasePlacement>>();
  search->explains_records = [kept, &model](const std::vector<updating::TestRecord>& tests,
                                            const updating::UpdateOptions& options,
                                            const updating::UpdateResult& fit) {
    *kept = FindReleasePlacement(model, tests, options, fit);
    return (*kept)->fit.explains_records;
  };
  return
      [kept](const model::MechanicalModel& placed_model, std::vector<updating::TestRecord>* records,
             const updating::UpdateOptions& options, updating::UpdateResult* best) {
        if (kept->has_value() && (*kept)->From(*best)) {
          return TakeReleasePlacement(**kept, records, options, best);
        }
        return PlaceDetectedReleases(placed_model, records, options, best);
      };
}

}  // namespace mbid::validation
