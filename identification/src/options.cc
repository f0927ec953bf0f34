#include "mbid/identification/options.h"

#include <fmt/format.h>

#include <cmath>

#include "internal.h"
#include "mbid/common/error.h"
#include "methods/method.h"

namespace mbid::identification {
namespace {

// Keeps the first violated option: its field name, the problem and what was expected.
class Checker {
 public:
  const std::optional<OptionProblem>& problem() const { return problem_; }

  void Require(bool condition, const char* field, double value, const char* expected) {
    if (problem_ || condition) return;
    problem_ = OptionProblem{field, fmt::format("{} is out of range", value), expected};
  }

 private:
  std::optional<OptionProblem> problem_;
};

}  // namespace

std::optional<OptionProblem> FindOptionProblem(const IdentificationOptions& o) {
  Checker c;
  const double inf = std::numeric_limits<double>::infinity();
  c.Require(!std::isnan(o.window_start_s) && o.window_start_s < inf, "window_start_s",
            o.window_start_s, "a number below +inf (-inf: from the first sample)");
  c.Require(!std::isnan(o.window_end_s) && o.window_end_s > o.window_start_s, "window_end_s",
            o.window_end_s, "a number above window_start_s (+inf: to the last sample)");
  c.Require(o.decimation >= 0, "decimation", o.decimation, "0 (automatic) or an integer >= 1");
  c.Require(std::isfinite(o.release_time_s), "release_time_s", o.release_time_s,
            "a finite time in s");
  c.Require(std::isfinite(o.min_correlation) && o.min_correlation >= 0 && o.min_correlation <= 1,
            "min_correlation", o.min_correlation, "a correlation in [0, 1]");
  c.Require(std::isfinite(o.min_frequency_hz) && o.min_frequency_hz >= 0, "min_frequency_hz",
            o.min_frequency_hz, "a finite number >= 0");
  c.Require(std::isfinite(o.max_frequency_hz) &&
                (o.max_frequency_hz == 0 || o.max_frequency_hz > o.min_frequency_hz),
            "max_frequency_hz", o.max_frequency_hz,
            "0 (the Nyquist frequency) or a finite number above min_frequency_hz");
  c.Require(std::isfinite(o.min_damping_ratio) && o.min_damping_ratio > -1, "min_damping_ratio",
            o.min_damping_ratio, "a number in (-1, max_damping_ratio)");
  c.Require(o.max_damping_ratio > o.min_damping_ratio && o.max_damping_ratio <= 1,
            "max_damping_ratio", o.max_damping_ratio, "a number in (min_damping_ratio, 1]");
  c.Require(o.max_decay_rate_per_s > 0, "max_decay_rate_per_s", o.max_decay_rate_per_s,
            "a positive number (+inf: no limit)");
  c.Require(o.max_modes >= 1, "max_modes", o.max_modes, "an integer >= 1");
  c.Require(o.significance_false_alarm > 0 && o.significance_false_alarm < 1,
            "significance_false_alarm", o.significance_false_alarm, "a probability in (0, 1)");
  c.Require(std::isfinite(o.min_significance) && o.min_significance >= 0, "min_significance",
            o.min_significance, "a finite number >= 0 (0: from significance_false_alarm)");
  c.Require(o.stabilization_max_order >= 0, "stabilization_max_order", o.stabilization_max_order,
            "0 (automatic) or a positive integer");
  c.Require(o.spectrum.zero_padding_factor >= 1 && o.spectrum.zero_padding_factor <= 64,
            "spectrum.zero_padding_factor", o.spectrum.zero_padding_factor,
            "an integer in [1, 64]");
  c.Require(std::isfinite(o.spectrum.min_peak_prominence) && o.spectrum.min_peak_prominence >= 0 &&
                o.spectrum.min_peak_prominence <= 1,
            "spectrum.min_peak_prominence", o.spectrum.min_peak_prominence, "a fraction in [0, 1]");
  c.Require(o.prony.order >= 1, "prony.order", o.prony.order, "an integer >= 1");
  c.Require(std::isfinite(o.prony.rank_tolerance) && o.prony.rank_tolerance > 0 &&
                o.prony.rank_tolerance < 1,
            "prony.rank_tolerance", o.prony.rank_tolerance, "a fraction in (0, 1)");
  c.Require(std::isfinite(o.prony.noise_floor_factor) && o.prony.noise_floor_factor >= 0,
            "prony.noise_floor_factor", o.prony.noise_floor_factor,
            "a factor >= 0 (0: no noise rule)");
  c.Require(o.hankel.max_columns >= 8, "hankel.max_columns", o.hankel.max_columns,
            "an integer >= 8");
  c.Require(std::isfinite(o.hankel.noise_floor_factor) && o.hankel.noise_floor_factor >= 1,
            "hankel.noise_floor_factor", o.hankel.noise_floor_factor, "a finite number >= 1");
  c.Require(o.hankel.min_relative_singular_value > 0 && o.hankel.min_relative_singular_value < 1,
            "hankel.min_relative_singular_value", o.hankel.min_relative_singular_value,
            "a fraction in (0, 1)");
  c.Require(o.hankel.extra_orders >= 0, "extra_orders", o.hankel.extra_orders, "an integer >= 0");
  c.Require(o.hankel.stability_orders >= 0, "hankel.stability_orders", o.hankel.stability_orders,
            "an integer >= 0");
  c.Require(std::isfinite(o.hankel.stability_tolerance) && o.hankel.stability_tolerance > 0,
            "hankel.stability_tolerance", o.hankel.stability_tolerance, "a positive number");
  c.Require(o.refinement.max_iterations >= 1, "refinement.max_iterations",
            o.refinement.max_iterations, "an integer >= 1");
  c.Require(o.refinement.function_tolerance > 0, "refinement.function_tolerance",
            o.refinement.function_tolerance, "a positive number");
  c.Require(o.refinement.parameter_tolerance > 0, "refinement.parameter_tolerance",
            o.refinement.parameter_tolerance, "a positive number");
  c.Require(o.refinement.gradient_tolerance > 0, "refinement.gradient_tolerance",
            o.refinement.gradient_tolerance, "a positive number");
  if (!c.problem() && FindMethod(o.method.name()) == nullptr) {
    std::string names;
    for (const std::string& name : MethodNames()) names += (names.empty() ? "" : ", ") + name;
    return OptionProblem{"method", "unknown method '" + o.method.name() + "'", "one of " + names};
  }
  return c.problem();
}

std::string BackboneModeName(BackboneMode mode) {
  switch (mode) {
    case BackboneMode::kAlways:
      return "always";
    case BackboneMode::kNever:
      return "never";
    case BackboneMode::kClusters:
      break;
  }
  return "clusters";
}

bool ParseBackboneMode(const std::string& name, BackboneMode* mode) {
  for (const BackboneMode candidate :
       {BackboneMode::kClusters, BackboneMode::kAlways, BackboneMode::kNever}) {
    if (name == BackboneModeName(candidate)) {
      *mode = candidate;
      return true;
    }
  }
  return false;
}

bool IdentificationOptions::IsValid(std::string* error) const {
  const std::optional<OptionProblem> problem = FindOptionProblem(*this);
  if (problem && error != nullptr) {
    *error = problem->field + ": " + problem->problem + "; expected " + problem->expected;
  }
  return !problem;
}

void IdentificationOptions::Validate(const std::string& source) const {
  if (const std::optional<OptionProblem> problem = FindOptionProblem(*this)) {
    throw InputError(source, problem->field, problem->problem, problem->expected);
  }
}

}  // namespace mbid::identification
