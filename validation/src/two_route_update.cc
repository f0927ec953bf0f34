#include "mbid/validation/two_route_update.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <vector>

#include "mbid/updating/credibility.h"
#include "mbid/updating/profile.h"
#include "mbid/validation/release_profile.h"

namespace mbid::validation {

std::vector<size_t> SelectMainModes(const identification::ModalResult& identified, size_t count) {
  // Energy of mode k over the analysed record, sum over channels of
  // A^2 (1 - e^{-2 decay T}) / (4 decay), each channel in units of its residual noise variance so
  // that no channel dominates by its unit; noiseless channels count unweighted.
  const double record_s = (identified.samples - 1) * identified.sample_interval_s;
  std::vector<double> energy(identified.modes.size(), 0.0);
  for (size_t k = 0; k < identified.modes.size(); ++k) {
    const auto& mode = identified.modes[k];
    const double decay = mode.decay_rate_per_s;
    const double duration = std::abs(decay) * record_s < 1e-12
                                ? record_s / 2
                                : -std::expm1(-2 * decay * record_s) / (4 * decay);
    for (Eigen::Index c = 0; c < mode.amplitude.size(); ++c) {
      const double noise = c < identified.noise_std.size() && identified.noise_std[c] > 0
                               ? identified.noise_std[c]
                               : 1.0;
      energy[k] += mode.amplitude[c] * mode.amplitude[c] * duration / (noise * noise);
    }
  }
  // A combination tone is no mode of the structure: eq. 7 must not take it as one.
  std::vector<size_t> order;
  for (size_t k = 0; k < identified.modes.size(); ++k) {
    if (identified.modes[k].combination.empty()) order.push_back(k);
  }
  std::stable_sort(order.begin(), order.end(),
                   [&energy](size_t a, size_t b) { return energy[a] > energy[b]; });
  order.resize(std::min(count, order.size()));
  std::sort(order.begin(), order.end());  // ascending frequency, as identified
  return order;
}

std::shared_ptr<const updating::CharacteristicResult> SolveAlgebraicRoute(
    const model::MechanicalModel& model, const identification::ModalResult& identified,
    const Measurement& record, const simulation::Excitation& excitation,
    const updating::UpdatingSettings& settings, std::string* note) {
  if (!settings.algebraic_start) {
    *note = "algebraic_start is off";
    return nullptr;
  }
  const size_t n = static_cast<size_t>(model.coordinate_count());
  const std::string free = updating::FindFreeCoordinate(model);
  if (!free.empty()) {
    *note =
        fmt::format("coordinate '{}' has no spring (eq. 7 needs one on every coordinate)", free);
    return nullptr;
  }
  std::vector<size_t> main = SelectMainModes(identified, n);
  if (main.size() < n) {
    *note =
        fmt::format("{} identified modes{} for {} coordinates", main.size(),
                    main.size() < identified.modes.size() ? " (besides combination tones)" : "", n);
    return nullptr;
  }
  if (identified.modes.size() > n) {
    std::vector<std::string> left_out;
    for (size_t k = 0; k < identified.modes.size(); ++k) {
      if (std::find(main.begin(), main.end(), k) == main.end()) {
        left_out.push_back(fmt::format("{:.3f} Hz", identified.modes[k].frequency_hz));
      }
    }
    *note = fmt::format("eq. 7 on the {} main modes (largest energy in the record); left out: {}",
                        n, fmt::join(left_out, ", "));
  }
  std::vector<std::complex<double>> lambda;
  for (size_t k : main) lambda.push_back(identified.modes[k].lambda);
  updating::CharacteristicResult solved = updating::SolveCharacteristicEquation(
      updating::MakeCharacteristicProblem(model, lambda, record, excitation), settings.algebraic);
  // Poles of modes that explain the record (every channel at min_correlation) are the record's,
  // whatever else made the identification doubt itself (a load drop's nonlinear start at 10 kHz,
  // whose design then cost 55-74 s for the same minimum); poles that do not (a noise peak,
  // K = 0.17) may be noise.
  solved.poles_reliable =
      identified.reliable || (identified.correlation.size() > 0 &&
                              identified.correlation.minCoeff() >= identified.min_correlation);
  return std::make_shared<const updating::CharacteristicResult>(std::move(solved));
}

std::vector<updating::SearchStart> StartFromAlgebraicRoute(
    const updating::CharacteristicResult* algebraic, updating::UpdatingSettings* settings,
    std::string* start, std::string* note) {
  *start = "scenario";
  bool from_route1 = false;
  if (algebraic != nullptr) {
    std::string why;
    from_route1 = updating::ApplyAlgebraicStart(*algebraic, settings->options, &why);
    if (from_route1) *start = "route1";
    settings->global_search.primary_matches_poles = from_route1;
    if (!why.empty()) *note = note->empty() ? why : *note + "; " + why;
  }
  // Route 1 ran on as many poles as coordinates (SolveAlgebraicRoute) and solved: its sets are
  // every joint set with these poles. From an unreliable identification's poles they are not
  // (a trial's pendulum in noise twice its swing: a 20.2 Hz noise peak for its 1.1 Hz mode, the
  // design skipped, c 400 times the truth reported determined).
  settings->global_search.complete_starts =
      algebraic != nullptr &&
      algebraic->status == updating::CharacteristicResult::Status::kSolved &&
      algebraic->poles_reliable;
  if (algebraic == nullptr) return {};
  return updating::MakeAlgebraicStarts(*algebraic, from_route1);
}

namespace {

// A shared parameter that ends at its bound may be where a fit from a start far off stopped, not
// where the records put it: the fit in a valley of the others that the bound cut off (a trial's
// arm on a sprung base, one channel: c_bounce at its upper bound, c_shoulder and c_elbow
// "determined" 9 of their standard deviations off; with c_bounce held at the truth the cost was
// 9.6 lower). Each such parameter is profiled (held at values inside, the others re-fitted); a
// point that fits better shows the estimate is no minimum of the records, and then no shared
// parameter is determined by it.
void CheckParametersAtABound(const model::MechanicalModel& model,
                             const std::vector<updating::TestRecord>& records,
                             const updating::UpdatingSettings& settings,
                             updating::UpdateResult& best,
                             const std::function<void(const std::string&)>& say) {
  updating::ProfileOptions profile = settings.profile;
  for (const updating::ParameterEstimate& p : best.parameters) {
    if (p.test.empty() && p.at_bound) profile.parameters.push_back(p.name);
  }
  if (profile.parameters.empty()) return;
  profile.enabled = true;
  updating::ProfileLikelihood(model, records, settings.options, profile, best, say);
  std::vector<std::string> better;
  for (const updating::ParameterEstimate& p : best.parameters) {
    if (p.profile.computed && p.profile.better_minimum) {
      better.push_back(fmt::format("{} = {:.4g}", p.name, p.profile.better_value));
    }
  }
  if (better.empty()) return;
  const std::string why = fmt::format(
      "the fit ended at a bound in a local minimum: held at {} the others fit the records "
      "better",
      fmt::join(better, ", "));
  for (updating::ParameterEstimate& p : best.parameters) {
    if (!p.test.empty() || !p.determined) continue;
    p.determined = false;
    p.why_undetermined = why;
    best.undetermined.push_back(p.name);
  }
}

}  // namespace

updating::GlobalSearchResult TuneModel(const model::MechanicalModel& model,
                                       const std::vector<updating::TestRecord>& records,
                                       updating::UpdatingSettings settings,
                                       const updating::CharacteristicResult* algebraic,
                                       std::string* start, std::string* note,
                                       const std::function<void(const std::string&)>& say) {
  const std::vector<updating::SearchStart> starts =
      StartFromAlgebraicRoute(algebraic, &settings, start, note);
  const bool detected =
      std::any_of(records.begin(), records.end(),
                  [](const updating::TestRecord& r) { return r.release_detected; });
  // A release found in a record is placed by the fit too (release_profile.h). Before that, its
  // fit leaves a misfit of a fraction of a sample that would call for the search's design; so
  // the search asks whether the placed fit explains the records, and that placement is kept.
  const ReleasePlacer place =
      detected ? PlaceReleasesEarly(model, &settings.global_search) : ReleasePlacer();
  updating::GlobalSearchResult search = updating::SearchGlobally(
      model, records, settings.options, *start, starts, settings.global_search, say);
  if (algebraic != nullptr) {
    updating::MarkAlgebraicAmbiguity(*algebraic, search.best, 0.1, search.judged_starts);
  }
  // Records cut elsewhere are fitted as they are, without a copy.
  std::vector<updating::TestRecord> placed;
  if (detected) {
    placed = records;
    place(model, &placed, settings.options, &search.best);
  }
  if (search.best.termination != updating::UpdateResult::Termination::kFailure) {
    updating::MarkUnseenParameters(model, records, search.best);
    updating::WidenToTheIntervalEnds(model, placed.empty() ? records : placed, settings.options,
                                     search.best);
  }
  if (settings.profile.enabled) {
    updating::ProfileLikelihood(model, placed.empty() ? records : placed, settings.options,
                                settings.profile, search.best, say);
  } else if (search.best.termination == updating::UpdateResult::Termination::kConverged) {
    CheckParametersAtABound(model, placed.empty() ? records : placed, settings, search.best, say);
  }
  return search;
}

void MarkUnmeasuredSamples(const records::ImportReport& import,
                           const identification::ModalResult& identified,
                           updating::TestRecord& record) {
  // Only the record's start is ever cut (the release, a clipped start).
  Measurement& measured = record.record;
  const Eigen::Index kept = measured.samples();
  const Eigen::Index cut = static_cast<Eigen::Index>(import.samples) - kept;
  const double tau = measured.sample_interval_s;
  const bool same_rate = std::abs(identified.sample_interval_s - tau) <= 1e-9 * tau;
  for (const int row : import.filled_rows) {
    const Eigen::Index j = row - cut;
    if (cut < 0 || j < 0 || j >= kept) continue;
    record.unmeasured_samples.push_back(j);
    const double at =
        (measured.start_time_s + static_cast<double>(j) * tau - identified.start_time_s) / tau;
    const Eigen::Index k = std::llround(at);
    if (!same_rate || std::abs(at - static_cast<double>(k)) > 1e-6 || k < 0 ||
        k >= identified.reconstruction.rows()) {
      continue;
    }
    for (Eigen::Index c = 0; c < measured.values.cols(); ++c) {
      const auto found = std::find(identified.channels.begin(), identified.channels.end(),
                                   measured.channels[static_cast<size_t>(c)]);
      const Eigen::Index i = found - identified.channels.begin();
      if (found != identified.channels.end() && i < identified.reconstruction.cols()) {
        measured.values(j, c) = identified.reconstruction(k, i);
      }
    }
  }
}

void WeighByIdentifiedNoise(const identification::ModalResult& identified,
                            updating::TestRecord& record) {
  for (size_t c = 0; c < identified.channels.size(); ++c) {
    const double noise = identified.noise_std[static_cast<Eigen::Index>(c)];
    if (noise > 0) record.noise_std.emplace(identified.channels[c], noise);
  }
}

}  // namespace mbid::validation
