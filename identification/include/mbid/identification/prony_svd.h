#pragma once

#include <Eigen/Core>
#include <complex>
#include <vector>

namespace mbid::identification {

// Steps 2-4 of method.md for a record y_j (values: samples x m channels, sample interval tau).
struct PronySvdSolution {
  int order = 0;           // p of eq. 3
  int effective_rank = 0;  // k of step 3
  // B1..Bp of eq. 3 side by side: m x (m p), B.block(0, m (i - 1), m, m) = Bi.
  Eigen::MatrixXd B;
  Eigen::VectorXd B0;               // the constant term of eq. 3, m
  Eigen::VectorXd singular_values;  // of the scaled regression matrix, descending
  // The largest singular value that noise alone gives the scaled regression matrix (0 when the
  // rank is not set by the noise): singular values above it are the model order.
  double noise_threshold = 0;
  // Every root mu of det(E mu^p + B1 mu^(p-1) + ... + Bp) = 0 (m p of them), its continuous
  // pole lambda = ln(mu) / tau (eq. 4, principal logarithm: |Im lambda| <= pi / tau) and its
  // output vector w (the last m entries of the companion eigenvector, unit largest magnitude).
  std::vector<std::complex<double>> mu;
  std::vector<std::complex<double>> lambda;
  std::vector<Eigen::VectorXcd> w;
};

// Solves eq. 3,
//   y_(j+p) + B1 y_(j+p-1) + ... + Bp y_j + B0 = 0,   j = 0..s-p,
// for B0..Bp: the m channels are m least-squares systems sharing the matrix
// X = [y_(j+p-1)^T ... y_j^T 1] (rows j), solved with the truncated pseudo-inverse
// V_k S_k^-1 U_k^T (steps 2-3, minimum-norm solution). Then step 4: mu are the eigenvalues of
// the block companion matrix [-B1 -B2 ... -Bp; E 0 ... 0; ...; 0 ... E 0], and eq. 4 gives
// lambda. The caller checks the sizes: samples - order >= m order + 1 rows are needed.
//
// X is scaled before the SVD so that its singular values mean something: each channel is divided
// by its noise level `channel_noise_std` (the poles do not change: B_i becomes D^-1 B_i D) and the
// column of ones is scaled to the root mean square of the data columns, so that B0 neither
// dominates nor vanishes from the spectrum. The effective rank k (step 3, "a threshold that
// reflects the data's accuracy") counts the singular values above
//   - sqrt(noise_floor_factor) (1 + sqrt(m p / rows)) sqrt(rows): the largest that unit white
//     noise gives a rows x m p matrix (Marchenko-Pastur), times a margin; skipped when
//     noise_floor_factor is 0 (plain least squares, the method as usually applied);
//   - rank_tolerance times the largest (round-off).
// With the noise rule k estimates the model order 2 n (+ 1 for the constant), sub-problem 4.
// `channel_noise_std` empty: unit noise per channel (only the round-off rule is meaningful).
PronySvdSolution SolvePronySvd(const Eigen::MatrixXd& values, double sample_interval_s, int order,
                               double rank_tolerance, double noise_floor_factor = 0,
                               const Eigen::VectorXd& channel_noise_std = Eigen::VectorXd());

// Step 6 (eq. 5): the coefficients A1..Ap of eq. 2,
//   y^(p) + A1 y^(p-1) + ... + Ap y = 0,
// from n identified poles lambda_k (Im > 0; their conjugates are implied) and output vectors
// w_k (m entries each): the real and imaginary parts of
//   (E lambda_k^p + A1 lambda_k^(p-1) + ... + Ap) w_k = 0,   k = 1..n,
// are 2 m n linear equations in the m^2 p unknowns, with p = ceil(2 n / m); square when 2n/m is
// an integer (the paper's case), otherwise the minimum-norm least-squares solution. Returns
// [A1 ... Ap]: m x (m p); empty if there are no poles.
Eigen::MatrixXd CalcEq2Coefficients(const std::vector<std::complex<double>>& lambda,
                                    const std::vector<Eigen::VectorXcd>& w);

}  // namespace mbid::identification
