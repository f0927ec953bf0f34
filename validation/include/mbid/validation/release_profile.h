#pragma once

#include <functional>
#include <map>
#include <string>
#include <vector>

#include "mbid/model/mechanical_model.h"
#include "mbid/updating/global_search.h"
#include "mbid/updating/output_error.h"

namespace mbid::validation {

// A record cut at a release found in it (TestRecord::release_detected) knows the release only
// to a fraction of a sample, and the fit of a long finely sampled record is far more precise
// than that: half a sample at 2 kHz moved the crane's c_theta by 24 of its standard deviations.
// So the fit places the release too. For each such test the cost is profiled over the instant:
// local fits from `best` with the test's samples moved either way (the other tests as they
// are), half a sample first, then twice the instant's std; Newton steps on the parabola (at most
// two samples each, taken only where they lower the cost) until a step at that scale is a tenth
// of the std, and `best` is refitted there. Several tests are placed in sweeps (Aitken's limit
// after two) until no release moves by a tenth of its std. The curvature gives the instant's
// standard deviation, and each shared parameter's std gains what that uncertainty moves it by
// (the slope of the two fits beside it times it); a parameter it widens past what the records
// determine is marked undetermined. `records` are moved in place; each placed test's shift and
// its std go to best->tests[t] (TestFit::release_shift_s); returns one line per test.
std::vector<std::string> PlaceDetectedReleases(const model::MechanicalModel& model,
                                               std::vector<updating::TestRecord>* records,
                                               const updating::UpdateOptions& options,
                                               updating::UpdateResult* best);

// PlaceDetectedReleases in two steps, so that a caller can place the releases from a fit before
// it knows whether that fit will be the result (the global search asks whether its best given
// start explains the records once placed: GlobalSearchOptions::explains_records).
struct ReleasePlacement {
  std::vector<updating::TestRecord> records;     // the releases moved to where the fit placed them
  updating::UpdateResult fit;                    // the fit at the placed releases
  std::vector<size_t> detected;                  // tests with a detected release (none: nothing)
  std::vector<double> shift_s, std_s;            // per detected test: the placed shift and its std
  std::vector<bool> placed;                      // per detected test: the cost had a least point
  std::map<std::string, double> added_variance;  // what the releases' uncertainty adds
  // Whether `fit` is the one the placement started from (the same cost and values).
  bool From(const updating::UpdateResult& other) const;

  double from_cost = 0;
  std::map<std::string, double> from;
};
ReleasePlacement FindReleasePlacement(const model::MechanicalModel& model,
                                      const std::vector<updating::TestRecord>& records,
                                      const updating::UpdateOptions& options,
                                      const updating::UpdateResult& from);
// Moves `records` and `best` (the fit the placement started from, perhaps marked since) to the
// placement, widens its standard deviations; returns one line per test.
std::vector<std::string> TakeReleasePlacement(const ReleasePlacement& placement,
                                              std::vector<updating::TestRecord>* records,
                                              const updating::UpdateOptions& options,
                                              updating::UpdateResult* best);

// What a search whose detected releases are placed after it (TuneModel, `mbid structure`)
// wires in, for `model`: `search`'s explains_records places the releases from the fit it is
// asked about and keeps that placement; the function returned (PlaceDetectedReleases'
// signature) takes the kept placement when the search's result is the fit it started from, or
// places them anew.
using ReleasePlacer = std::function<std::vector<std::string>(
    const model::MechanicalModel&, std::vector<updating::TestRecord>*,
    const updating::UpdateOptions&, updating::UpdateResult*)>;
ReleasePlacer PlaceReleasesEarly(const model::MechanicalModel& model,
                                 updating::GlobalSearchOptions* search);

// Widens each shared parameter's std (and interval) of `best` by the variance the releases'
// uncertainty adds to it (by name), and marks a parameter the widened spread no longer
// determines (UpdateOptions::undetermined_relative_std, an interval reaching a bound)
// undetermined, the reason saying so. Part of PlaceDetectedReleases.
void WidenForReleases(const std::map<std::string, double>& added_variance,
                      const updating::UpdateOptions& options, updating::UpdateResult* best);

// `record` with its release `delta_s` later: every sample's time from the release less by
// `delta_s`; samples that would come before the release are left out.
Measurement MoveRelease(const Measurement& record, double delta_s);

// The record as `fit` used it: `cut` (as cut at its detected release) moved to where the fit
// placed the release (TestFit::release_shift_s), or `cut` itself. What the outputs store
// beside the re-simulation, so that both have the same samples.
Measurement AsFitted(const Measurement& cut, const updating::TestFit& fit);

}  // namespace mbid::validation
