#pragma once

// Eigen-decompositions of the small symmetric Gram matrices of hankel_svd.cc that compute only
// what is used: Eigen's SelfAdjointEigenSolver spends most of its time accumulating the
// rotations of every eigenvector, while the Hankel SVD needs the vectors of the leading few
// and, per channel, one eigenvalue (the median).

#include <Eigen/Core>
#include <Eigen/Eigenvalues>

namespace mbid::identification {

// Householder tridiagonalization A = Q T Q^T and the eigenvalues of T (implicit QL, no
// vectors); eigenvectors on demand, largest first, by inverse iteration on T (reorthogonalized,
// so that clustered and repeated eigenvalues still give an orthonormal basis) and x -> Q x.
// O(n^3) only in the tridiagonalization; O(n^2) per vector. Not thread-safe (the vectors are a
// cache filled by const calls).
class SymmetricEigen {
 public:
  explicit SymmetricEigen(const Eigen::MatrixXd& symmetric);

  const Eigen::VectorXd& values() const { return values_; }  // all, descending
  // The eigenvectors of values(0..count-1): n x count, orthonormal.
  Eigen::Ref<const Eigen::MatrixXd> LeadingVectors(int count) const;

 private:
  Eigen::Tridiagonalization<Eigen::MatrixXd> tridiagonal_;
  Eigen::VectorXd diagonal_, off_diagonal_;
  Eigen::VectorXd values_;
  mutable Eigen::MatrixXd tridiagonal_vectors_;  // eigenvectors of T found so far
  mutable Eigen::MatrixXd vectors_;              // Q times them
};

// The eigenvalue with ascending index `index` (0 = smallest) by Sturm-sequence bisection on the
// tridiagonal form, to full precision.
double CalcEigenvalue(const Eigen::MatrixXd& symmetric, int index);

}  // namespace mbid::identification
