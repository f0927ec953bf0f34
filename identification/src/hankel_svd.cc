#include "mbid/identification/hankel_svd.h"

#include <Eigen/Cholesky>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <limits>

#include "mbid/common/eigen_decompositions.h"
#include "symmetric_eigen.h"

namespace mbid::identification {
namespace {

// G[a][b] = sum_(i=0)^(R-1) y[i+a] y[i+b] for a, b = 0..L, R = N - L. Row 0 by dot products,
// then along each diagonal G[a+1][b+1] = G[a][b] - y[a] y[b] + y[a+R] y[b+R].
Eigen::MatrixXd CalcHankelGram(const Eigen::VectorXd& y, int columns) {
  const int n = static_cast<int>(y.size());
  const int rows = n - columns + 1;
  Eigen::MatrixXd gram(columns, columns);
  for (int b = 0; b < columns; ++b) gram(0, b) = y.segment(0, rows).dot(y.segment(b, rows));
  for (int a = 0; a + 1 < columns; ++a) {
    for (int b = a; b + 1 < columns; ++b) {
      gram(a + 1, b + 1) = gram(a, b) - y(a) * y(b) + y(a + rows) * y(b + rows);
    }
  }
  return gram.selfadjointView<Eigen::Upper>();
}

}  // namespace

HankelSvd::HankelSvd(const Eigen::MatrixXd& values, int columns, int max_signal_order) {
  const int channels = static_cast<int>(values.cols());
  const int rows = static_cast<int>(values.rows()) - columns + 1;
  // At least half of the spectrum stays for the noise floor.
  const int skip = std::min(max_signal_order, columns / 2);
  const int median_index = (columns - skip) / 2;  // ascending: the median of the tail
  channel_noise_std_.resize(channels);
  Eigen::MatrixXd gram = Eigen::MatrixXd::Zero(columns, columns);
  for (int c = 0; c < channels; ++c) {
    const Eigen::MatrixXd channel_gram = CalcHankelGram(values.col(c), columns);
    // Noiseless channels have a floor of round-off; keep it above zero and comparable.
    const double floor =
        std::max(CalcEigenvalue(channel_gram, median_index),
                 channel_gram.trace() * 1e-15 + std::numeric_limits<double>::min());
    channel_noise_std_(c) = std::sqrt(floor / rows);
    gram += channel_gram / floor;
  }
  eigen_ = std::make_unique<SymmetricEigen>(gram);
  const Eigen::VectorXd& eigenvalues = eigen_->values();
  noise_floor_ = eigenvalues(columns - 1 - median_index);
  // Marchenko-Pastur: white noise in a tall matrix of aspect ratio c = columns / rows has
  // squared singular values up to about (1 + sqrt(c))^2 times their typical value.
  const double aspect = static_cast<double>(columns) / (static_cast<double>(rows) * channels);
  noise_edge_ = (1 + std::sqrt(aspect)) * (1 + std::sqrt(aspect));
  singular_values_ = eigenvalues.cwiseMax(0.0).cwiseSqrt();
}

HankelSvd::~HankelSvd() = default;

int HankelSvd::CountSignal(double noise_floor_factor, double min_relative, int max_order) const {
  const double largest = singular_values_(0);
  int count = 0;
  while (count < max_order && count < columns() - 1) {
    const double s = singular_values_(count);
    if (s * s <= noise_floor_factor * noise_edge_ * noise_floor_ || s <= min_relative * largest) {
      break;
    }
    ++count;
  }
  return count;
}

void HankelSvd::ExtendShiftProducts(const Eigen::Ref<const Eigen::MatrixXd>& v, int order) const {
  const int known = static_cast<int>(shift_gram_.cols());
  if (order <= known) return;
  const int l = columns() - 1;
  const int added = order - known;
  const auto v1 = v.topRows(l);
  const auto v2 = v.bottomRows(l);
  shift_gram_.conservativeResize(order, order);
  shift_cross_.conservativeResize(order, order);
  shift_gram_.rightCols(added) = v1.transpose() * v1.rightCols(added);
  shift_gram_.bottomLeftCorner(added, known) = shift_gram_.topRightCorner(known, added).transpose();
  shift_cross_.rightCols(added) = v1.transpose() * v2.rightCols(added);
  shift_cross_.bottomLeftCorner(added, known) =
      v1.rightCols(added).transpose() * v2.leftCols(known);
}

std::vector<std::complex<double>> HankelSvd::CalcPoles(int order) const {
  const int l = columns() - 1;
  // The right singular vectors are the Gram matrix's eigenvectors, computed as far as needed.
  const Eigen::Ref<const Eigen::MatrixXd> v = eigen_->LeadingVectors(order);
  // V1 Z = V2 in the least-squares sense; eig(Z) are the discrete poles. V has orthonormal
  // columns, so V1^T V1 = I - w w^T (w: V's last row) has its eigenvalues in [1 - |w|^2, 1]:
  // while |w|^2 <= 1/2 the normal equations are as accurate as a QR of V1, and their matrices
  // for every order are the leading blocks of one product (a QR per order was a third of an
  // identification's stabilization data).
  Eigen::MatrixXd z;
  if (v.row(l).squaredNorm() <= 0.5) {
    ExtendShiftProducts(v, order);
    const Eigen::LLT<Eigen::MatrixXd> cholesky(shift_gram_.topLeftCorner(order, order));
    if (cholesky.info() == Eigen::Success) {
      z = cholesky.solve(shift_cross_.topLeftCorner(order, order));
    }
  }
  if (z.size() == 0) z = v.topRows(l).colPivHouseholderQr().solve(v.bottomRows(l));
  Eigen::EigenSolver<Eigen::MatrixXd> eigen(z, /*computeEigenvectors=*/false);
  std::vector<std::complex<double>> mu(eigen.eigenvalues().data(),
                                       eigen.eigenvalues().data() + order);
  return mu;
}

}  // namespace mbid::identification
