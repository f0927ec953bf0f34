#pragma once

#include <Eigen/Core>
#include <complex>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "mbid/common/error.h"
#include "mbid/common/measurement.h"
#include "mbid/model/mechanical_model.h"
#include "mbid/simulation/excitation.h"
#include "mbid/simulation/simulate.h"

namespace mbid::updating {

// Route 1 of model updating: the paper's algebraic route (method.md, eqs. 6-8). The joint
// stiffness c and damping d of
//   M q'' + D q' + C q = 0,   D = diag(d),   C = diag(c) + K_g,   y = H q
// follow from the identified poles lambda_k through the characteristic equation (eq. 7), one
// complex equation per mode for the 2n real unknowns. It has several solution sets; each
// admissible one (c, d > 0) gets its eigenvectors (eq. 6), complex amplitudes from the record
// (eq. 8) and so an initial state q(0), q'(0); the set whose initial state agrees with the test
// wins.

// What eq. 7 needs: the model's linearization at the test configuration, the poles, and
// optionally the record (eq. 8) and the initial state the test is known to start from.
struct CharacteristicProblem {
  Eigen::MatrixXd M;    // n x n, kg*m^2
  Eigen::MatrixXd K_g;  // n x n, gravity stiffness C - diag(c), N*m/rad
  Eigen::MatrixXd H;    // m x n, rad/rad
  // Per output, the derivative of q that H maps (model::LinearModel::output_orders); empty: 0.
  std::vector<int> output_orders;
  std::vector<std::string> coordinate_units;  // "rad" or "m" per coordinate; empty: all "rad"
  std::vector<std::string> coordinates;       // n names: parameters are c_<name>, d_<name>
  std::vector<std::string> outputs;           // m names: the rows of H, matched to record channels
  // Identified poles, one per mode (Im > 0), 1/s. n of them.
  std::vector<std::complex<double>> lambda;
  // Typical values (> 0): the multi-start draws around them and the equations are scaled by
  // them (e.g. the scenario's design values).
  Eigen::VectorXd c_reference, d_reference;
  // The record for eq. 8 (channels named as `outputs`; others are ignored). Without it no
  // initial state is computed and the set nearest the reference values is chosen.
  std::optional<Measurement> record;
  // The coordinates the test starts from, as a function of a candidate set (a load drop's
  // loaded equilibrium depends on the stiffnesses); the start is at rest. Empty: only the zero
  // initial velocity is checked.
  std::function<Eigen::VectorXd(const Eigen::VectorXd& c, const Eigen::VectorXd& d)>
      expected_initial_q;
  // For a forced test (an impulse, a burst): where its free decay starts, coordinates and
  // speeds at the forcing's end, as a function of a candidate set. Each set's state there
  // (eq. 8's modes carried to that time) is compared with it.
  std::function<simulation::FreeDecayStart(const Eigen::VectorXd& c, const Eigen::VectorXd& d)>
      expected_free_decay_start;
};

// The first coordinate of `model` without a spring (no c_<coordinate> parameter), or "" when
// every one has one: eq. 7 solves for c and d of every coordinate, so a free one rules it out.
std::string FindFreeCoordinate(const model::MechanicalModel& model);

// The problem for `model` (its linearization and current parameters c_<coordinate>,
// d_<coordinate> as reference) and poles `lambda`; with a record, and with the excitation giving
// the expected initial state through CalcInitialCoordinates on a copy of the model carrying the
// candidate set. Throws InputError if the model lacks c_/d_ parameters for its coordinates or
// the number of poles is not n.
CharacteristicProblem MakeCharacteristicProblem(
    const model::MechanicalModel& model, const std::vector<std::complex<double>>& lambda,
    const std::optional<Measurement>& record,
    const std::optional<simulation::Excitation>& excitation);

struct CharacteristicOptions {
  int starts = 100;            // multi-start: starting points per solve
  std::uint64_t seed = 1;      // of the starting points (log-uniform around the reference)
  double start_spread = 10.0;  // starts in [reference / spread, reference * spread]
  int max_iterations = 100;    // Ceres iterations per start
  // A start has converged to a solution when every |det(M lambda_k^2 + D lambda_k + C)|,
  // divided by the product of its diagonal magnitudes at the reference, is below this.
  double residual_tolerance = 1e-9;
  // Two solutions are one set when every c_i, d_i agrees to this, relative to the reference.
  double duplicate_tolerance = 1e-6;
  // eq. 8 with a constant per channel (a sensor offset) besides the modes.
  bool fit_offset = false;
  // The choice is ambiguous when the runner-up's mismatch is within this factor of the
  // winner's: the record does not single out one set (e.g. modes it barely excites).
  double ambiguity_ratio = 2.0;
  // A set whose eq.-8 fit leaves more of the record unexplained than the best set's, by more
  // than the chi-square quantile at this level (residuals in units of the best fit's residual
  // per channel), does not reproduce the record's mode shapes: it is ranked after those that
  // do and is no rival, whatever its initial state.
  double shape_significance = 1e-3;

  bool IsValid(std::string* why) const;
};

// One solution set of eq. 7.
struct CharacteristicSolution {
  Eigen::VectorXd c, d;  // N*m/rad, N*m*s/rad
  double residual = 0;   // largest scaled |det| over the poles
  int hits = 0;          // starts that converged to this set
  bool admissible = false;
  std::string reason;  // why not admissible ("c_gamma = -3.1e+05 < 0")
  // Admissible sets only:
  std::vector<Eigen::VectorXcd> shapes;  // w_k of eq. 6, unit largest magnitude
  // With a record: eq. 8's complex amplitudes a_k (y_j = sum_k 2 Re(a_k H w_k mu_k^j)), the
  // fit's correlation per output and the initial state q(0) = sum 2 Re(a_k w_k),
  // q'(0) = sum 2 Re(a_k lambda_k w_k).
  Eigen::VectorXcd amplitudes;
  Eigen::VectorXd offset;       // per output, 0 unless fit_offset
  Eigen::VectorXd correlation;  // per output: Pearson's K of record and eq. 8 reconstruction
  // Per output: eq. 8's residual and the record's sums of squares about its mean, and the
  // residual's integrated autocorrelation time in samples (NaN where the record lacks the
  // output).
  Eigen::VectorXd residual_ss, total_ss, residual_time;
  // sum over outputs of (residual_ss - the best set's) / (the best set's residual variance
  // times its residual_time: a smooth residual, model error rather than noise, has fewer
  // independent samples): 0 for the set that reproduces the record best; fits_shapes when
  // below the chi-square quantile of CharacteristicOptions::shape_significance.
  double shape_misfit = 0;
  bool fits_shapes = true;
  Eigen::VectorXd initial_q, initial_u;  // rad, rad/s
  Eigen::VectorXd expected_initial_q;    // rad, empty if not known
  // A forced test's: where the free decay starts, and the expected speeds there
  // (expected_initial_q then holds the coordinates there).
  double expected_time_s = 0;
  Eigen::VectorXd expected_u;
  // |q(0) - q_expected| / |q_expected| (NaN if not known), |q'(0)| / (omega |q_expected|) or,
  // without an expected state, / (omega |q(0)|), omega the mean |lambda_k|; for a forced test
  // |q(T) - q_expected| / s and |q'(T) - u_expected| / (omega s) at the forcing's end T with
  // s = sqrt(|q_expected|^2 + |u_expected / omega|^2); and their root sum of squares, by which
  // the sets are ranked.
  double displacement_mismatch = 0;
  double velocity_mismatch = 0;
  double mismatch = 0;
};

struct CharacteristicResult {
  enum class Status {
    kSolved,           // at least one admissible set; `chosen` names the winner
    kNoAdmissibleSet,  // solutions exist, none with c, d > 0
    kNoSolution,       // no start converged
  };
  Status status = Status::kNoSolution;
  std::vector<std::complex<double>> lambda;
  std::vector<std::string> coordinates;
  std::vector<std::string> coordinate_units;  // "rad" or "m" per coordinate; empty: all "rad"
  std::vector<std::string> outputs;
  // Admissible sets first: with a record those that reproduce its shapes (fits_shapes) by
  // ascending mismatch, then the others by mismatch; without one by distance to the reference.
  // Then the inadmissible sets by residual.
  std::vector<CharacteristicSolution> solutions;
  int chosen = -1;                           // index into solutions, -1 unless kSolved
  Eigen::VectorXd c_reference, d_reference;  // the problem's (the model's values)
  // Other admissible sets agree with the test almost as well (CharacteristicOptions::
  // ambiguity_ratio): the choice is not backed by the record. `rivals` are their indices.
  bool ambiguous = false;
  std::vector<int> rivals;
  int starts = 0;
  int converged_starts = 0;
  double best_residual = 0;  // smallest scaled residual any start reached
  std::string message;
  // The poles came from modes that explain the record (a reliable identification, or one whose
  // modes correlate with every channel at its min_correlation). Sets solved from doubtful poles
  // (a noise peak taken for the mode) are starts, never every set the records allow.
  bool poles_reliable = true;

  std::string status_name() const;  // "solved" | "no_admissible_set" | "no_solution"
};

// Solves eq. 7 for the diagonal c, d from every start, deduplicates, drops sets with negative
// coefficients (the unknowns are real, so complex sets cannot arise), then for each admissible
// set: eigenvectors (eq. 6), amplitudes (eq. 8), initial state and its mismatch with the test.
// Throws InputError for inconsistent sizes, poles with Im <= 0 or reference values <= 0.
CharacteristicResult SolveCharacteristicEquation(const CharacteristicProblem& problem,
                                                 const CharacteristicOptions& options);

// The scaled residuals of eq. 7 at (c, d): [Re, Im] of det(M lambda_k^2 + D lambda_k + C) / s_k
// per pole, s_k the product over i of |M_ii| |lambda_k|^2 + c_ref_i + d_ref_i |lambda_k|.
Eigen::VectorXd CalcCharacteristicResiduals(const CharacteristicProblem& problem,
                                            const Eigen::VectorXd& c, const Eigen::VectorXd& d);

}  // namespace mbid::updating
