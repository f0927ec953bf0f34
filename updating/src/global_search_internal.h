#pragma once

// What the global search (global_search.cc) takes from its starts and minima files.
// Private to updating/. global_search_starts.cc: where fits start; global_search_minima.cc:
// telling end points apart.

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "mbid/model/mechanical_model.h"
#include "mbid/updating/global_search.h"

namespace mbid::updating::internal {

// `count` points of the unit cube in `dimension` dimensions, seeded.
std::vector<std::vector<double>> SpaceFillingDesign(int count, int dimension, std::uint64_t seed);

// The tests cut to the first `fraction` of each record (the screening window).
std::vector<TestRecord> Window(const std::vector<TestRecord>& tests, double fraction);

// `screen` integrating the state at `relative_tolerance` where its own is tighter, with its
// absolute and its sensitivities' tolerances loosened by the same factor.
void LoosenForScreening(double relative_tolerance, UpdateOptions& screen);

// Whether every channel of every test has its noise level given (else fits estimate it).
bool EveryNoiseGiven(const std::vector<TestRecord>& tests);

// The share of each record a start's cost is first probed on.
constexpr double kProbePrefix = 0.1;

// The cost of the tests at `options`' start, or, when that exceeds `limit`, possibly only the
// cost of the records' first kProbePrefix, which then already exceeds it (a lower bound where
// every channel's noise is given and no baseline is projected out). Far starts (other Route-1
// sets start thousands of times above the best) are decided on a tenth of a simulation.
double CalcStartCostUpTo(const model::MechanicalModel& model, const std::vector<TestRecord>& tests,
                         const UpdateOptions& options, double limit);

// `options` with `settings` whose initial values are `values` where given (clamped to bounds).
UpdateOptions StartOptions(const UpdateOptions& options,
                           const std::vector<ParameterSetting>& settings,
                           const std::map<std::string, double>& values);

// Every other admissible solution of eq. 7 for the exact poles of `model` carrying `fit`'s
// values, as starts; none unless every coordinate has a tuned spring and damper and all its
// modes oscillate.
std::vector<SearchStart> PoleEquivalentStarts(const model::MechanicalModel& model,
                                              const UpdateResult& fit, std::uint64_t seed);

// The admissible solutions of eq. 7 for the exact poles of `model` carrying `fit`'s values with
// each mode at or above `nyquist_hz` moved to its alias below it (|f - k f_s|, the same decay):
// the sets whose modes a record sampled so shows as it shows the fit's. Empty when no mode is
// above, or on PoleEquivalentStarts' conditions. `aliased` (if set) gets "53.28 Hz -> 46.72 Hz"
// per moved mode.
// The damped frequencies (Hz) of the exact modes of `model` carrying `fit`'s values at or above
// `nyquist_hz`.
std::vector<double> FrequenciesAbove(const model::MechanicalModel& model, const UpdateResult& fit,
                                     double nyquist_hz);

std::vector<SearchStart> AliasStarts(const model::MechanicalModel& model, const UpdateResult& fit,
                                     std::uint64_t seed, double nyquist_hz,
                                     std::vector<std::string>* aliased = nullptr);

// Parameters (shared, tuned) in which two end points differ beyond the clustering tolerance
// and 3 standard deviations: both ends' combined (one minimum reached twice), or only `a`'s
// (`a` the best: is the other end inside its confidence interval?).
std::vector<std::string> Differences(const UpdateResult& a, const UpdateResult& b, double tolerance,
                                     bool combined_std = true);

}  // namespace mbid::updating::internal
