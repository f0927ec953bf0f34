#include "symmetric_eigen.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "mbid/common/eigen_decompositions.h"

namespace mbid::identification {
namespace {

// (T - shift I) x = b for the symmetric tridiagonal T (diagonal d, off-diagonal e): Gaussian
// elimination with partial pivoting (the LAPACK dgttrf/dgtts2 scheme). A zero pivot becomes
// `tiny`: inverse iteration solves with an almost singular matrix on purpose.
class ShiftedTridiagonalSolver {
 public:
  ShiftedTridiagonalSolver(const Eigen::VectorXd& d, const Eigen::VectorXd& e, double shift,
                           double tiny)
      : n_(static_cast<int>(d.size())),
        diagonal_(d.array() - shift),
        upper_(e),
        lower_(e),
        upper2_(Eigen::VectorXd::Zero(std::max(n_ - 2, 0))),
        swapped_(std::max(n_ - 1, 0), false) {
    for (int i = 0; i + 1 < n_; ++i) {
      if (std::abs(diagonal_(i)) >= std::abs(lower_(i))) {
        if (diagonal_(i) == 0) diagonal_(i) = tiny;
        const double factor = lower_(i) / diagonal_(i);
        lower_(i) = factor;
        diagonal_(i + 1) -= factor * upper_(i);
      } else {
        swapped_[i] = true;
        const double factor = diagonal_(i) / lower_(i);
        diagonal_(i) = lower_(i);
        lower_(i) = factor;
        const double temp = upper_(i);
        upper_(i) = diagonal_(i + 1);
        diagonal_(i + 1) = temp - factor * diagonal_(i + 1);
        if (i + 2 < n_) {
          upper2_(i) = upper_(i + 1);
          upper_(i + 1) = -factor * upper_(i + 1);
        }
      }
    }
    if (n_ > 0 && diagonal_(n_ - 1) == 0) diagonal_(n_ - 1) = tiny;
  }

  void SolveInPlace(Eigen::VectorXd* b) const {
    Eigen::VectorXd& x = *b;
    for (int i = 0; i + 1 < n_; ++i) {
      if (!swapped_[i]) {
        x(i + 1) -= lower_(i) * x(i);
      } else {
        const double temp = x(i);
        x(i) = x(i + 1);
        x(i + 1) = temp - lower_(i) * x(i);
      }
    }
    for (int i = n_ - 1; i >= 0; --i) {
      double value = x(i);
      if (i + 1 < n_) value -= upper_(i) * x(i + 1);
      if (i + 2 < n_) value -= upper2_(i) * x(i + 2);
      x(i) = value / diagonal_(i);
    }
  }

 private:
  int n_;
  Eigen::VectorXd diagonal_, upper_, lower_, upper2_;
  std::vector<bool> swapped_;
};

// Number of eigenvalues of the tridiagonal matrix below x (Sturm sequence).
int CountBelow(const Eigen::VectorXd& d, const Eigen::VectorXd& e, double x, double tiny) {
  int count = 0;
  double q = 1;
  for (Eigen::Index i = 0; i < d.size(); ++i) {
    q = d(i) - x - (i > 0 ? e(i - 1) * e(i - 1) / q : 0.0);
    if (q == 0) q = -tiny;
    if (q < 0) ++count;
  }
  return count;
}

}  // namespace

SymmetricEigen::SymmetricEigen(const Eigen::MatrixXd& symmetric)
    : tridiagonal_(symmetric),
      diagonal_(tridiagonal_.diagonal()),
      off_diagonal_(tridiagonal_.subDiagonal()) {
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen;
  eigen.computeFromTridiagonal(diagonal_, off_diagonal_, Eigen::EigenvaluesOnly);
  values_ = eigen.eigenvalues().reverse();
  vectors_.resize(symmetric.rows(), 0);
  tridiagonal_vectors_.resize(symmetric.rows(), 0);
}

Eigen::Ref<const Eigen::MatrixXd> SymmetricEigen::LeadingVectors(int count) const {
  const int n = static_cast<int>(values_.size());
  const int known = static_cast<int>(tridiagonal_vectors_.cols());
  if (count > known) {
    const double norm = std::max(values_.cwiseAbs().maxCoeff(), std::numeric_limits<double>::min());
    const double tiny = std::numeric_limits<double>::epsilon() * norm;
    tridiagonal_vectors_.conservativeResize(n, count);
    std::mt19937_64 rng(1);  // fixed start vectors: deterministic results
    rng.discard(static_cast<unsigned long long>(known) * n);
    std::uniform_real_distribution<double> uniform(-1.0, 1.0);
    for (int k = known; k < count; ++k) {
      // A shift just off the eigenvalue keeps the solve finite; the solution still grows by
      // about 1 / epsilon in the eigenvector's direction.
      const ShiftedTridiagonalSolver solver(diagonal_, off_diagonal_, values_(k) + tiny, tiny);
      Eigen::VectorXd v(n);
      for (int i = 0; i < n; ++i) v(i) = uniform(rng);
      for (int iteration = 0; iteration < 3; ++iteration) {
        solver.SolveInPlace(&v);
        // Against the vectors found so far, twice (classical Gram-Schmidt loses orthogonality
        // once in a while): repeated eigenvalues get orthogonal vectors this way.
        const auto previous = tridiagonal_vectors_.leftCols(k);
        for (int pass = 0; pass < 2; ++pass) v -= previous * (previous.transpose() * v);
        v.normalize();
      }
      tridiagonal_vectors_.col(k) = v;
    }
    vectors_.conservativeResize(n, count);
    vectors_.rightCols(count - known) =
        tridiagonal_.matrixQ() * tridiagonal_vectors_.rightCols(count - known);
  }
  return vectors_.leftCols(count);
}

double CalcEigenvalue(const Eigen::MatrixXd& symmetric, int index) {
  const Eigen::Tridiagonalization<Eigen::MatrixXd> tridiagonal(symmetric);
  const Eigen::VectorXd d = tridiagonal.diagonal();
  const Eigen::VectorXd e = tridiagonal.subDiagonal();
  // Gershgorin bounds.
  double low = std::numeric_limits<double>::infinity();
  double high = -low;
  for (Eigen::Index i = 0; i < d.size(); ++i) {
    const double radius =
        (i > 0 ? std::abs(e(i - 1)) : 0.0) + (i < e.size() ? std::abs(e(i)) : 0.0);
    low = std::min(low, d(i) - radius);
    high = std::max(high, d(i) + radius);
  }
  const double tiny = std::numeric_limits<double>::epsilon() *
                      std::max({std::abs(low), std::abs(high), std::numeric_limits<double>::min()});
  // The eigenvalue is the x where the count of eigenvalues below x passes index.
  for (int iteration = 0; iteration < 200 && high - low > 2 * tiny; ++iteration) {
    const double middle = 0.5 * (low + high);
    (CountBelow(d, e, middle, tiny) > index ? high : low) = middle;
  }
  return 0.5 * (low + high);
}

}  // namespace mbid::identification
