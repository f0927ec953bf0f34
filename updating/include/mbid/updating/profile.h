#pragma once

#include <functional>
#include <string>
#include <vector>

#include "mbid/model/mechanical_model.h"
#include "mbid/updating/output_error.h"

namespace mbid::updating {

// Profile-likelihood intervals of the tuned shared parameters. The Fisher standard deviations
// read the cost's curvature at the estimate; where the cost is curved differently farther out
// (a damping whose cost flattens, a parameter trading with another, a second valley) they can
// look small while the records allow far more. The profile holds one parameter at a time at
// values on each side, re-fits all the others (shared and nuisance, with the estimate's weights)
// and finds where 2 (cost - best cost) reaches sigmas^2 std_inflation^2: the Fisher interval's
// own level, so both agree where the cost is quadratic. Each side is a root search of a few
// constrained fits, warm-started from the side's previous point.
struct ProfileOptions {
  bool enabled = false;  // the scenario's `updating.profile.enabled`: off by default (cost)
  double sigmas = 2;     // the interval's half-width in Fisher terms (2: about 95%)
  int max_fits_per_side = 6;
  int max_iterations = 20;  // of each constrained fit
  // 2 (cost - best) is accepted as the threshold within this relative error of its square root
  // (about the same relative error of the interval's half-width).
  double tolerance = 0.05;
  int threads = 1;  // sides in parallel; each fit single-threaded, so the bits do not depend on it
  // The shared parameters to profile; empty: every one.
  std::vector<std::string> parameters;

  bool IsValid(std::string* why) const;
};

// Fills `best.parameters[k].profile` for every shared parameter of `best`, the fit of `model`
// (left unchanged) to `tests` with `options` (bounds resolved as UpdateModel resolves them on
// `model`). Weights: the noise levels `best` used. A parameter is then marked undetermined, with
// the reason, when its interval is open (the records do not bound it before the parameter's
// bound), when it is wider than the Fisher test allows (options.undetermined_relative_std as a
// relative half-width over `sigmas`), or when a profile point fitted better than `best` (then
// also a warning: the estimate is not the best minimum). `progress`, if set, hears one line.
void ProfileLikelihood(const model::MechanicalModel& model, const std::vector<TestRecord>& tests,
                       const UpdateOptions& options, const ProfileOptions& profile,
                       UpdateResult& best,
                       const std::function<void(const std::string&)>& progress = {});

// One line per profiled parameter: "c_alpha: profile [4.1e+07, 5.6e+07] N*m/rad (Fisher [...]),
// 4 fits", with "open below/above" or a better minimum said; empty when none was profiled.
std::vector<std::string> DescribeProfiles(const UpdateResult& result);

}  // namespace mbid::updating
