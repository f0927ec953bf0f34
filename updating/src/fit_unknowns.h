#pragma once

// The unknowns of the output-error fit (output_error.h): shared model parameters and nuisance
// parameters of single tests. Not part of the public API.

#include <cmath>
#include <string>
#include <vector>

#include "format_value.h"
#include "mbid/model/mechanical_model.h"
#include "mbid/updating/output_error.h"

namespace mbid::updating::internal {

// One unknown of the fit: a shared model parameter or a nuisance parameter of one test.
struct Unknown {
  enum class Kind { kModel, kPayloadMass, kDeflection };
  Kind kind = Kind::kModel;
  std::string name;  // model parameter name, or "<test>:payload_mass_kg" ...
  std::string units;
  int test = -1;           // owning test of a nuisance parameter
  std::string coordinate;  // kDeflection
  bool log_scale = true;
  double initial = 0, lower = 0, upper = 0;
  // A linear-scale unknown's standard deviation is relative to the larger of its value and this:
  // a deflection fitted near 0 (2e-6 +- 5e-6 rad beside a test's 0.04) is known to be small,
  // not "undetermined" for a relative std of 2.5. 0: its value alone.
  double scale = 0;

  // Ceres' coordinate x and back.
  double ToInternal(double value) const { return log_scale ? std::log(value) : value; }
  double ToValue(double x) const { return log_scale ? std::exp(x) : x; }
};

// An estimate's value in Ceres' coordinate (log p on the log scale) and back.
inline double ToInternal(const ParameterEstimate& p, double value) {
  return p.log_scale ? std::log(value) : value;
}
inline double ToValue(const ParameterEstimate& p, double x) {
  return p.log_scale ? std::exp(x) : x;
}

// The unknowns of `options.parameters` (all of the model's if empty) and the tests' nuisance
// parameters (payload mass of a load drop, initial deflections), starts and bounds checked.
std::vector<Unknown> ResolveUnknowns(const model::MechanicalModel& model,
                                     const std::vector<TestRecord>& tests,
                                     const UpdateOptions& options);

// Moves the tests' nuisance starts (a load drop's payload mass, initial deflections) to the
// estimates in `result`: a later fit on the same tests starts where this one ended.
void StartNuisanceAt(const UpdateResult& result, std::vector<TestRecord>& tests);

// Gives every channel of `tests` without a noise level the weight `result` used for it, so that
// later fits' costs are in the same units as `result`'s.
void WeighAs(const UpdateResult& result, std::vector<TestRecord>& tests);

}  // namespace mbid::updating::internal
