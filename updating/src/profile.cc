// Profile-likelihood intervals (profile.h): per shared parameter and side, a root search of
// constrained fits for the cost's rise to the threshold.
#include "mbid/updating/profile.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <memory>
#include <thread>

#include "fit_unknowns.h"
#include "mbid/common/error.h"
#include "mbid/updating/global_search.h"

namespace mbid::updating {
namespace {

using internal::FormatValue;
using internal::StartNuisanceAt;
using internal::ToInternal;
using internal::ToValue;

// One side's search, in Ceres' coordinate x (log p on the log scale) as the distance s >= 0
// from the estimate.
struct Side {
  size_t parameter = 0;  // index into best.parameters
  double direction = 1;  // +1: towards the upper bound
  double reach = 0;      // distance to the bound
  double end = 0;        // distance of the interval's end
  bool open = false;
  bool at_bound = false;  // open because the bound was reached (else the fits ran out)
  bool better = false;
  double better_distance = 0;
  std::vector<double> distances, rises;
  int fits = 0;
  std::string failure;
};

class Profiler {
 public:
  Profiler(const model::MechanicalModel& model, const std::vector<TestRecord>& tests,
           const UpdateOptions& options, const ProfileOptions& profile, const UpdateResult& best)
      : model_(model), options_(options), profile_(profile), best_(best) {
    settings_ = ResolveParameterSettings(model, options);
    weighted_ = tests;
    internal::WeighAs(best, weighted_);
    threshold_ = profile.sigmas * profile.sigmas * best.std_inflation * best.std_inflation;
  }

  double threshold() const { return threshold_; }

  // 2 (cost - best cost) with parameter `k` held at `value`, the rest re-fitted from `start`
  // moved by Predict; `start` then holds the fitted values. Returns false (and says why) when
  // the fit failed.
  bool RiseAt(size_t k, double value, UpdateResult& start, double* rise, std::string* why) const {
    const ParameterEstimate& held = best_.parameters[k];
    Predict(k, value, start);
    std::unique_ptr<model::MechanicalModel> clone = model_.Clone();
    ApplyEstimates(start, *clone);
    clone->SetParameter(held.name, value);
    UpdateOptions options = options_;
    options.quiet = true;
    options.threads = 1;
    options.continuation_fractions.clear();
    options.refit_after_noise_estimate = false;
    options.max_iterations = profile_.max_iterations;
    options.parameters.clear();
    for (const ParameterSetting& setting : settings_) {
      if (setting.name == held.name) continue;
      ParameterSetting moved = setting;
      for (const ParameterEstimate& p : start.parameters) {
        if (p.name == setting.name)
          moved.initial = std::clamp(p.value, setting.lower, setting.upper);
      }
      options.parameters.push_back(moved);
    }
    if (options.parameters.empty()) {
      // Nothing else to re-fit (an empty list would mean every model parameter): the held one
      // itself in a box of roundoff width, so that the fit only evaluates the cost there.
      const double width = 1e-9 * (held.log_scale ? value : std::max(std::abs(value), 1e-6));
      options.parameters.push_back(
          {held.name, value, value - width, value + width, held.log_scale});
    }
    std::vector<TestRecord> tests = weighted_;
    StartNuisanceAt(start, tests);
    try {
      UpdateResult fit = UpdateModel(*clone, tests, options);
      if (fit.termination == UpdateResult::Termination::kFailure) {
        *why = fit.message;
        return false;
      }
      *rise = 2 * (fit.final_cost - best_.final_cost);
      for (ParameterEstimate& p : start.parameters) {
        for (const ParameterEstimate& fitted : fit.parameters) {
          if (fitted.name == p.name && p.name != held.name) p.value = fitted.value;
        }
      }
      return true;
    } catch (const std::exception& e) {
      *why = e.what();
      return false;
    }
  }

  // Moves the other unknowns of `start` (whose k-th holds the previous value) along the
  // estimate's covariance to where they are best for the k-th at `value`: the exact profile
  // of a quadratic cost, so the constrained fit starts close to its end.
  void Predict(size_t k, double value, UpdateResult& start) const {
    const Eigen::MatrixXd& covariance = best_.covariance;
    const auto n = static_cast<Eigen::Index>(best_.parameters.size());
    const auto kk = static_cast<Eigen::Index>(k);
    if (covariance.rows() != n || covariance.cols() != n ||
        start.parameters.size() != best_.parameters.size() || !(covariance(kk, kk) > 0) ||
        !covariance.allFinite()) {
      return;
    }
    ParameterEstimate& held = start.parameters[k];
    const double step = ToInternal(held, value) - ToInternal(held, held.value);
    for (Eigen::Index o = 0; o < n; ++o) {
      if (o == kk) continue;
      ParameterEstimate& other = start.parameters[static_cast<size_t>(o)];
      const double x =
          ToInternal(other, other.value) + covariance(o, kk) / covariance(kk, kk) * step;
      other.value = std::clamp(ToValue(other, x), other.lower, other.upper);
    }
    held.value = value;
  }

  void Search(Side& side) const {
    const ParameterEstimate& p = best_.parameters[side.parameter];
    const double x0 = ToInternal(p, p.value);
    side.reach = std::max(
        0.0, side.direction > 0 ? ToInternal(p, p.upper) - x0 : x0 - ToInternal(p, p.lower));
    // The Fisher prediction of the end; a tenth of the span where there is none.
    const double fisher = p.log_scale ? p.relative_std : p.std;
    double s = std::isfinite(fisher) && fisher > 0
                   ? profile_.sigmas * fisher * best_.std_inflation
                   : 0.1 * (ToInternal(p, p.upper) - ToInternal(p, p.lower));
    s = std::min(s, side.reach);
    const double target = std::sqrt(threshold_);
    // The bracket in sqrt(rise), which is linear in s where the cost is quadratic.
    double below_s = 0, below_root = 0;
    double above_s = -1, above_root = 0;
    const auto bracketed_end = [&] {
      return below_s + (above_s - below_s) * (target - below_root) / (above_root - below_root);
    };
    UpdateResult start;  // the values only: the held one's last, the others' fitted there
    start.parameters = best_.parameters;
    side.open = true;
    side.end = side.reach;
    while (side.fits < profile_.max_fits_per_side && s > 0) {
      double rise = 0;
      std::string why;
      ++side.fits;
      if (!RiseAt(side.parameter, ToValue(p, x0 + side.direction * s), start, &rise, &why)) {
        side.failure = fmt::format("at {} = {}: {}", p.name,
                                   FormatValue(ToValue(p, x0 + side.direction * s)), why);
        side.end = below_s;
        return;
      }
      side.distances.push_back(s);
      side.rises.push_back(rise);
      if (rise < -0.1 * threshold_) {
        side.better = true;
        side.better_distance = s;
        side.end = below_s;
        return;
      }
      const double root = std::sqrt(std::max(rise, 0.0));
      if (std::abs(root - target) <= profile_.tolerance * target) {
        // Through the origin in sqrt(rise), exact for a quadratic cost: takes the end from
        // within the tolerance to the cost's own curvature there.
        side.open = false;
        side.end = std::min(s * target / root, side.reach);
        return;
      }
      if (root > target) {
        above_s = s;
        above_root = root;
      } else {
        below_s = s;
        below_root = root;
      }
      if (above_s < 0) {
        if (s >= side.reach) {
          side.at_bound = true;  // open: the bound reached below the threshold
          return;
        }
        const double grow = std::clamp(target / std::max(root, 1e-3 * target), 1.25, 4.0);
        s = std::min(side.reach, s * grow);
      } else {
        s = bracketed_end();
      }
    }
    if (above_s >= 0) {
      side.open = false;
      side.end = bracketed_end();
    } else {
      side.end = below_s;  // the search stopped below the threshold: open as far as it went
    }
  }

 private:
  const model::MechanicalModel& model_;
  const UpdateOptions& options_;
  const ProfileOptions& profile_;
  const UpdateResult& best_;
  std::vector<ParameterSetting> settings_;
  std::vector<TestRecord> weighted_;
  double threshold_ = 4;
};

// An earlier reason is kept, the profile's added to it, unless `overrides` (a better minimum
// explains more than any other).
void MarkUndetermined(ParameterEstimate& p, const std::string& why, UpdateResult& result,
                      bool overrides = false) {
  if (p.determined || p.why_undetermined.empty() || overrides) {
    p.why_undetermined = why;
  } else {
    p.why_undetermined += "; " + why;
  }
  p.determined = false;
  if (std::find(result.undetermined.begin(), result.undetermined.end(), p.name) ==
      result.undetermined.end()) {
    result.undetermined.push_back(p.name);
  }
}

}  // namespace

bool ProfileOptions::IsValid(std::string* why) const {
  auto fail = [why](const std::string& reason) {
    if (why != nullptr) *why = reason;
    return false;
  };
  if (!(sigmas > 0 && sigmas <= 10)) return fail("sigmas: expected a value in (0, 10]");
  if (max_fits_per_side < 1) return fail("max_fits_per_side: expected >= 1");
  if (max_iterations < 1) return fail("max_iterations: expected >= 1");
  if (!(tolerance > 0 && tolerance < 1)) return fail("tolerance: expected a value in (0, 1)");
  if (threads < 1) return fail("threads: expected >= 1");
  return true;
}

void ProfileLikelihood(const model::MechanicalModel& model, const std::vector<TestRecord>& tests,
                       const UpdateOptions& options, const ProfileOptions& profile,
                       UpdateResult& best,
                       const std::function<void(const std::string&)>& progress) {
  std::string why;
  if (!profile.IsValid(&why)) {
    throw InputError("updating", "profile", why, "valid profile options");
  }
  if (best.termination == UpdateResult::Termination::kFailure) return;
  const Profiler profiler(model, tests, options, profile, best);
  std::vector<Side> sides;
  for (size_t k = 0; k < best.parameters.size(); ++k) {
    if (!best.parameters[k].test.empty()) continue;
    if (!profile.parameters.empty() &&
        std::find(profile.parameters.begin(), profile.parameters.end(), best.parameters[k].name) ==
            profile.parameters.end()) {
      continue;
    }
    for (double direction : {-1.0, 1.0}) {
      Side side;
      side.parameter = k;
      side.direction = direction;
      sides.push_back(side);
    }
  }
  if (progress) {
    progress(fmt::format("profile likelihood: {} parameters, {} sides on {} thread(s)",
                         sides.size() / 2, sides.size(), profile.threads));
  }
  // Each side writes only its own entry and runs single-threaded fits: same bits for any
  // number of workers.
  std::atomic<size_t> next{0};
  auto work = [&] {
    for (size_t i = next++; i < sides.size(); i = next++) profiler.Search(sides[i]);
  };
  std::vector<std::thread> workers;
  const size_t extra = std::min<size_t>(static_cast<size_t>(profile.threads), sides.size());
  for (size_t w = 1; w < extra; ++w) workers.emplace_back(work);
  work();
  for (std::thread& worker : workers) worker.join();

  for (size_t i = 0; i + 1 < sides.size(); i += 2) {
    const Side& low = sides[i];
    const Side& high = sides[i + 1];
    ParameterEstimate& p = best.parameters[low.parameter];
    ParameterProfile& out = p.profile;
    const double x0 = ToInternal(p, p.value);
    out = ParameterProfile();
    out.computed = true;
    out.threshold = profiler.threshold();
    out.lower = ToValue(p, x0 - low.end);
    out.upper = ToValue(p, x0 + high.end);
    out.lower_open = low.open;
    out.upper_open = high.open;
    out.fits = low.fits + high.fits;
    for (size_t j = low.distances.size(); j-- > 0;) {
      out.values.push_back(ToValue(p, x0 - low.distances[j]));
      out.cost_rises.push_back(low.rises[j]);
    }
    out.values.push_back(p.value);
    out.cost_rises.push_back(0);
    for (size_t j = 0; j < high.distances.size(); ++j) {
      out.values.push_back(ToValue(p, x0 + high.distances[j]));
      out.cost_rises.push_back(high.rises[j]);
    }
    std::vector<size_t> order(out.values.size());
    for (size_t j = 0; j < order.size(); ++j) order[j] = j;
    std::sort(order.begin(), order.end(),
              [&out](size_t a, size_t b) { return out.values[a] < out.values[b]; });
    std::vector<double> values, rises;
    for (size_t j : order) {
      values.push_back(out.values[j]);
      rises.push_back(out.cost_rises[j]);
    }
    out.values = values;
    out.cost_rises = rises;
    for (const Side* side : {&low, &high}) {
      if (!side->failure.empty()) {
        out.failure = side->failure;
        best.warnings.push_back("profile likelihood: a constrained fit failed " + side->failure);
      }
      if (side->better) {
        out.better_minimum = true;
        out.better_value = ToValue(p, x0 + side->direction * side->better_distance);
      }
    }

    if (out.better_minimum) {
      MarkUndetermined(p,
                       fmt::format("its profile fits the records better at {} than at the "
                                   "estimate: the estimate is not the best minimum",
                                   FormatValue(out.better_value)),
                       best, true);
      best.warnings.push_back(fmt::format(
          "profile likelihood: {} = {} fits better than the estimate {}; the fit ended in a "
          "local minimum",
          p.name, FormatValue(out.better_value), FormatValue(p.value)));
    } else if (out.lower_open || out.upper_open) {
      std::vector<std::string> ends;
      for (const Side* side : {&low, &high}) {
        if (!side->open) continue;
        const std::string end = side == &low ? "below" : "above";
        const double rise = side->rises.empty() ? 0.0 : side->rises.back();
        const std::string value = FormatValue(side == &low ? out.lower : out.upper);
        if (!side->failure.empty()) {
          ends.push_back(end + ", where a constrained fit failed");
        } else if (side->fits == 0) {
          // "rises by 0 of 6.84 within 0 fits" said nothing: no step was possible there.
          ends.push_back(
              fmt::format("{}: the estimate is at its bound {} (no profile point beyond it; wider "
                          "updating.bounds let the records decide)",
                          end, value));
        } else if (side->at_bound) {
          ends.push_back(fmt::format("{}: 2 x cost rises by {:.3g} of {:.3g} up to the bound {}",
                                     end, rise, out.threshold, value));
        } else {
          ends.push_back(
              fmt::format("{}: 2 x cost rises by {:.3g} of {:.3g} within {} fits, "
                          "up to {}",
                          end, rise, out.threshold, side->fits, value));
        }
      }
      MarkUndetermined(p,
                       fmt::format("profile-likelihood interval open {}: the records do not "
                                   "bound it",
                                   fmt::join(ends, "; ")),
                       best);
    } else {
      const double half_width =
          p.log_scale ? std::log(out.upper / out.lower) / 2
                      : (out.upper - out.lower) / 2 / std::max(std::abs(p.value), 1e-6);
      const double equivalent = half_width / profile.sigmas;
      if (equivalent > options.undetermined_relative_std) {
        MarkUndetermined(p,
                         fmt::format("profile-likelihood interval [{}, {}] as wide as a relative "
                                     "std of {:.3g}, above {}",
                                     FormatValue(out.lower), FormatValue(out.upper), equivalent,
                                     options.undetermined_relative_std),
                         best);
      }
    }
  }
  int fits = 0;
  for (const Side& side : sides) fits += side.fits;
  if (progress) progress(fmt::format("profile likelihood: {} constrained fits", fits));
}

std::vector<std::string> DescribeProfiles(const UpdateResult& result) {
  std::vector<std::string> lines;
  for (const ParameterEstimate& p : result.parameters) {
    const ParameterProfile& profile = p.profile;
    if (!profile.computed) continue;
    // 6 digits: a well-determined parameter's interval is narrower than 4 show.
    std::string line = fmt::format(
        "{}: profile {}{:.6g}, {:.6g}{} {} (Fisher [{:.6g}, {:.6g}]), {} fits", p.name,
        profile.lower_open ? "(" : "[", profile.lower, profile.upper,
        profile.upper_open ? ")" : "]", p.units, p.interval_lower, p.interval_upper, profile.fits);
    if (profile.lower_open && profile.upper_open) {
      line += "; open on both sides";
    } else if (profile.lower_open || profile.upper_open) {
      line += profile.lower_open ? "; open below" : "; open above";
    }
    if (profile.better_minimum) {
      line += fmt::format("; fits better at {}", FormatValue(profile.better_value));
    }
    if (!profile.failure.empty()) line += "; a fit failed " + profile.failure;
    lines.push_back(line);
  }
  return lines;
}

}  // namespace mbid::updating
