#include "mbid/identification/prony_svd.h"

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <limits>

#include "mbid/common/eigen_decompositions.h"

namespace mbid::identification {

PronySvdSolution SolvePronySvd(const Eigen::MatrixXd& values, double sample_interval_s, int order,
                               double rank_tolerance, double noise_floor_factor,
                               const Eigen::VectorXd& channel_noise_std) {
  const int m = static_cast<int>(values.cols());
  const int p = order;
  const int rows = static_cast<int>(values.rows()) - p;  // j = 0..s-p
  const int unknowns = m * p + 1;

  // Channels in units of their noise: z = y D^-1.
  Eigen::VectorXd noise = Eigen::VectorXd::Ones(m);
  if (channel_noise_std.size() == m) {
    for (int c = 0; c < m; ++c) {
      // A noiseless channel has a round-off noise level; keep the scaling finite.
      const double rms = std::sqrt(values.col(c).squaredNorm() / values.rows());
      noise(c) = std::max(channel_noise_std(c), 1e-14 * std::max(rms, 1e-300));
    }
  }
  const Eigen::MatrixXd z = values * noise.cwiseInverse().asDiagonal();
  const double ones_scale = std::max(std::sqrt(z.squaredNorm() / static_cast<double>(z.size())),
                                     std::numeric_limits<double>::min());

  // Eq. 3 as X [B1 ... Bp B0]^T = -[y_(j+p)]^T, one column per channel.
  Eigen::MatrixXd X(rows, unknowns);
  for (int i = 1; i <= p; ++i) X.middleCols(m * (i - 1), m) = z.middleRows(p - i, rows);
  X.col(unknowns - 1).setConstant(ones_scale);
  const Eigen::MatrixXd rhs = -z.bottomRows(rows);

  // Step 3: minimum-norm solution through the SVD truncated at the effective rank.
  Eigen::BDCSVD<Eigen::MatrixXd> svd(X, Eigen::ComputeThinU | Eigen::ComputeThinV);
  PronySvdSolution solution;
  solution.order = p;
  solution.singular_values = svd.singularValues();
  const Eigen::VectorXd& s = solution.singular_values;
  if (noise_floor_factor > 0) {
    const double aspect = static_cast<double>(m * p) / rows;
    solution.noise_threshold = std::sqrt(noise_floor_factor * rows) * (1 + std::sqrt(aspect));
  }
  const double threshold = std::max(rank_tolerance * s(0), solution.noise_threshold);
  int k = 0;
  while (k < s.size() && s(k) > threshold) ++k;
  solution.effective_rank = k;
  const Eigen::MatrixXd theta = svd.matrixV().leftCols(k) * s.head(k).cwiseInverse().asDiagonal() *
                                (svd.matrixU().leftCols(k).transpose() * rhs);  // unknowns x m
  // Back to the channels' own units: B_i = D B'_i D^-1, B0 = D B'0 ones_scale.
  solution.B = noise.asDiagonal() * theta.topRows(m * p).transpose();
  for (int i = 0; i < p; ++i) {
    solution.B.middleCols(m * i, m) =
        solution.B.middleCols(m * i, m) * noise.cwiseInverse().asDiagonal();
  }
  solution.B0 = ones_scale * noise.asDiagonal() * theta.row(unknowns - 1).transpose();

  // Step 4: roots of the matrix polynomial = eigenvalues of the block companion matrix.
  Eigen::MatrixXd companion = Eigen::MatrixXd::Zero(m * p, m * p);
  companion.topRows(m) = -solution.B;
  if (p > 1) companion.bottomLeftCorner(m * (p - 1), m * (p - 1)).setIdentity();
  Eigen::EigenSolver<Eigen::MatrixXd> eigen(companion, /*computeEigenvectors=*/true);
  for (int i = 0; i < m * p; ++i) {
    const std::complex<double> mu = eigen.eigenvalues()(i);
    solution.mu.push_back(mu);
    solution.lambda.push_back(std::log(mu) / sample_interval_s);  // eq. 4
    // The eigenvector is [mu^(p-1) w; ...; mu w; w]: its last block is the output vector.
    Eigen::VectorXcd w = eigen.eigenvectors().col(i).tail(m);
    Eigen::Index largest = 0;
    w.cwiseAbs().maxCoeff(&largest);
    if (std::abs(w(largest)) > 0) w /= w(largest);
    solution.w.push_back(w);
  }
  return solution;
}

Eigen::MatrixXd CalcEq2Coefficients(const std::vector<std::complex<double>>& lambda,
                                    const std::vector<Eigen::VectorXcd>& w) {
  const int n = static_cast<int>(lambda.size());
  if (n == 0) return {};
  const int m = static_cast<int>(w.front().size());
  const int p = (2 * n + m - 1) / m;
  // A Z = -W with Z = [lambda^(p-1) w; ...; w] (m p x n) and W = [lambda^p w] (m x n); the real
  // and imaginary parts side by side give the real system A [Re Z Im Z] = -[Re W Im W].
  Eigen::MatrixXd Z(m * p, 2 * n);
  Eigen::MatrixXd W(m, 2 * n);
  for (int k = 0; k < n; ++k) {
    for (int i = 1; i <= p; ++i) {
      const Eigen::VectorXcd block = std::pow(lambda[k], p - i) * w[k];
      Z.block(m * (i - 1), k, m, 1) = block.real();
      Z.block(m * (i - 1), n + k, m, 1) = block.imag();
    }
    const Eigen::VectorXcd top = std::pow(lambda[k], p) * w[k];
    W.col(k) = top.real();
    W.col(n + k) = top.imag();
  }
  // Transposed: Z^T A^T = -W^T, minimum norm when under-determined.
  return Z.transpose().completeOrthogonalDecomposition().solve(-W.transpose()).transpose();
}

}  // namespace mbid::identification
