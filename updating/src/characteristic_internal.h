#pragma once

// What eq. 7's solve (characteristic.cc) and the judging of its solution sets share.
// Private to updating/. characteristic.cc: the problem, its residuals and the multi-start
// solve; characteristic_solutions.cc: admissibility, eq. 6 shapes, eq. 8 amplitudes from the
// record, mismatch.

#include <Eigen/Dense>
#include <complex>
#include <limits>
#include <string>

#include "format_value.h"
#include "mbid/updating/characteristic.h"
#include "nan.h"

namespace mbid::updating::internal {

using Complex = std::complex<double>;

// A(lambda) = M lambda^2 + D lambda + C with D = diag(d), C = diag(c) + K_g.
Eigen::MatrixXcd CalcCharacteristicMatrix(const CharacteristicProblem& problem, Complex lambda,
                                          const Eigen::VectorXd& c, const Eigen::VectorXd& d);

// Why a solution set is inadmissible (a coefficient c <= 0 or d < 0), or "".
std::string InadmissibleReason(const CharacteristicProblem& problem,
                               const CharacteristicSolution& solution);

// w_k of eq. 6: the null vector of A(lambda_k), unit largest magnitude.
Eigen::VectorXcd CalcShape(const CharacteristicProblem& problem, Complex lambda,
                           const Eigen::VectorXd& c, const Eigen::VectorXd& d);

// eq. 8: the modal amplitudes (and offsets) that reconstruct the record, the initial state they
// imply and each output's correlation.
void FitAmplitudes(const CharacteristicProblem& problem, const CharacteristicOptions& options,
                   CharacteristicSolution& solution);

// How far the set's initial state is from the test's expected one (or from rest).
void CalcMismatch(const CharacteristicProblem& problem, CharacteristicSolution& solution);

// Marks the admissible sets whose eq. 8 fit leaves significantly more of the record unexplained
// than the best set's (CharacteristicOptions::shape_significance): their mode shapes are not
// the record's. Needs FitAmplitudes on every admissible set; nothing without a record.
void JudgeShapes(const CharacteristicProblem& problem, const CharacteristicOptions& options,
                 std::vector<CharacteristicSolution>& sets);

// The set's distance from the reference values (log-scaled).
double DistanceToReference(const CharacteristicProblem& problem,
                           const CharacteristicSolution& solution);

}  // namespace mbid::updating::internal
