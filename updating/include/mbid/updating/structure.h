#pragma once

#include <Eigen/Core>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "mbid/model/mechanical_model.h"
#include "mbid/updating/global_search.h"
#include "mbid/updating/output_error.h"

namespace mbid::updating {

// Structural identification (the paper's sub-problem 4): which degrees of freedom the records
// support. Each candidate structure (the scenario's model, the model with some compliant
// coordinates made rigid, an alternative description) is fitted to the records by Route 2 and
// the candidates are ranked by the Bayesian information criterion.
//
// With residuals in noise units the weighted cost of a fit is
//   cost = 1/2 sum_tests sum_j sum_c ((y_c(t_j; p) - y_meas_c(t_j)) / sigma_c)^2,
// and for Gaussian noise of those sigmas -2 log L = 2 cost + const (the const, N log(2 pi) +
// 2 sum log sigma, is the same for every candidate because sigma is). Then, with k the number of
// fitted parameters and N the number of residuals (samples x channels over all records):
//   AIC = 2 cost + 2 k,     BIC = 2 cost + k ln N.
// The lower BIC wins: an extra degree of freedom (two parameters, c_ and d_) must lower the cost
// by about ln N to pay for itself (N = 2002: 7.6 per parameter), far more than fitting noise does
// (1/2 per parameter on average), far less than a missing mode costs.
//
// With several records each candidate is also judged by how well it predicts a record it was not
// fitted to (leave-one-out): fitted to all records but i, it simulates record i's test (the test's
// excitation as given, its fitted offsets and drifts projected out as in the fit) and
//   prediction_error = sqrt(sum_i sum_j sum_c (r_ijc / sigma_c)^2 / sum_i N_i),
// the weighted rms residual over every held-out record: about 1 for a structure that predicts to
// the noise level, larger for one that only fits.

// One candidate to rank.
struct StructureCandidate {
  // "full", "rigid theta", "rigid alpha,theta", or an alternative description's file.
  std::string name;
  std::vector<std::string> rigid;  // coordinates made rigid; empty for the full and alternatives
  std::string description;         // an alternative description's file; empty otherwise
  std::shared_ptr<const model::MechanicalModel> model;
  // Route 2's parameters, start and bounds; parameters the model lacks are dropped. When
  // `start_from_reference` is set, a parameter without an explicit start starts at the reference
  // candidate's estimate (a rigid variant of the reference shares its other joints).
  UpdateOptions options;
  bool start_from_reference = false;
};

struct StructureOptions {
  // Fits in parallel: candidates and leave-one-out fits are independent jobs; each fit itself
  // runs on one thread, so the results do not depend on this number.
  int threads = 1;
  bool leave_one_out = true;  // with two or more records
  // Progress (one line per finished fit) on standard error unless quiet.
  bool quiet = false;
  // The reference (full model) is fitted with the global search (global_search.h): its
  // estimate starts the rigid variants and its noise weighs them all, so a wrong minimum there
  // would mislead the whole ranking. The variants and the leave-one-out fits start from it and
  // are local fits.
  GlobalSearchOptions search;
  // The reference's further starts (Route 1's other sets, as `mbid update` gives them; with
  // search.complete_starts when they hold every set matching the identified poles) and its
  // primary start's label ("route1", "scenario").
  std::vector<SearchStart> reference_starts;
  std::string reference_start = "start";
  // Called with the reference's fit before the others start from it: may move the records and
  // refit the reference to them (`mbid structure` places detected releases so,
  // validation/release_profile.h); every candidate is then fitted to the moved records. Returns
  // lines for the progress output.
  std::function<std::vector<std::string>(const model::MechanicalModel&, std::vector<TestRecord>*,
                                         const UpdateOptions&, UpdateResult*)>
      after_reference;
};

struct StructureFit {
  std::string name;
  std::vector<std::string> rigid;
  std::string description;
  std::vector<std::string> coordinates;                    // the degrees of freedom left
  UpdateResult fit;                                        // Route 2 on every record
  double cost = std::numeric_limits<double>::quiet_NaN();  // weighted, the reference's sigma
  int parameter_count = 0;                                 // k: shared and nuisance parameters
  long residual_count = 0;                                 // N
  double aic = std::numeric_limits<double>::quiet_NaN();
  double bic = std::numeric_limits<double>::quiet_NaN();
  double delta_bic = std::numeric_limits<double>::quiet_NaN();  // BIC - the best BIC
  // Leave-one-out (NaN with one record, or when a fit failed): the pooled value and one per
  // held-out record (weighted rms of that record's residual).
  double prediction_error = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> prediction_error_per_record;
  // Why the candidate could not be fitted (a record channel it cannot compute, a failed fit);
  // empty when it was. Such candidates rank last.
  std::string skipped;
  int rank = 0;  // 1 = best
};

struct StructureRanking {
  std::vector<StructureFit> structures;  // best first
  // The noise standard deviations every candidate was weighed with: the reference fit's, per test
  // and channel.
  std::vector<std::map<std::string, double>> noise_std;
  // How the reference was searched (starts, screened design points, whole-record fits, notes);
  // its best is the reference's fit.
  GlobalSearchResult reference_search;
  double wall_time_s = 0;
};

// The subsets of `compliant` with 1 to `max_rigid` elements, smaller first, each in the order of
// `compliant` (lexicographic among subsets of one size).
std::vector<std::vector<std::string>> EnumerateRigidSets(const std::vector<std::string>& compliant,
                                                         int max_rigid);

// Fits candidates[0] (the reference: the scenario's full model) first; its noise weights
// (TestFit::noise_std) then weigh every candidate, so that costs compare. Then every other
// candidate, and with two or more records the leave-one-out fits, in parallel. Throws InputError
// when the reference cannot be fitted (its channels, its parameters) or has no records.
StructureRanking RankStructures(const std::vector<StructureCandidate>& candidates,
                                const std::vector<TestRecord>& tests,
                                const StructureOptions& options);

// The weighted residual (r / sigma_c, samples x channels) of `test` simulated by `model` as it
// is, the test's baseline (fit_offsets, fit_drift) projected out as in Route 2, sigma from
// test.noise_std (every channel must have one). Throws NumericalError if the simulation fails.
Eigen::MatrixXd CalcWeightedResidual(const model::MechanicalModel& model, const TestRecord& test,
                                     const simulation::IntegratorOptions& integrator);

}  // namespace mbid::updating
