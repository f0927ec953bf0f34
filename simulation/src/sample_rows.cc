#include "sample_rows.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

namespace mbid::simulation::internal {
namespace {

using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// The stencil: nodes k - 2 .. k + 3 around the interval [k, k + 1] (in strides).
constexpr int kStencil = 6;
constexpr int kBefore = 2;

// Lagrange weights of the stencil's nodes at s = r / stride, r = 0 .. stride - 1.
std::vector<std::array<double, kStencil>> CalcWeights(int stride) {
  std::vector<std::array<double, kStencil>> weights(static_cast<size_t>(stride));
  for (int r = 0; r < stride; ++r) {
    const double s = static_cast<double>(r) / stride;
    for (int a = 0; a < kStencil; ++a) {
      double w = 1;
      for (int b = 0; b < kStencil; ++b) {
        if (b != a) w *= (s - (b - kBefore)) / static_cast<double>(a - b);
      }
      weights[static_cast<size_t>(r)][static_cast<size_t>(a)] = w;
    }
  }
  return weights;
}

}  // namespace

int ChooseOutputStride(double tau, const Eigen::MatrixXd& jacobian, bool interpolates_outputs) {
  if (!interpolates_outputs || jacobian.size() == 0 || !(tau > 0)) return 1;
  const double fastest =
      Eigen::EigenSolver<Eigen::MatrixXd>(jacobian, false).eigenvalues().cwiseAbs().maxCoeff();
  // No dynamics at all (a free body) or none that could be read: every sample, as always.
  if (!(fastest > 0) || !std::isfinite(fastest)) return 1;
  const double node_interval_s = 2 * M_PI / (kNodesPerPeriod * fastest);
  const double stride = std::floor(node_interval_s / tau);
  return stride >= 2 ? static_cast<int>(std::min(stride, 1e6)) : 1;
}

int FirstRowAtOrAfter(const SampleGrid& grid, double time_s) {
  const int total = grid.skipped + grid.count;
  int i = 0;
  while (i < total && grid.Time(i) < time_s) ++i;
  return i;
}

Eigen::MatrixXd SampleRows(const SampleGrid& grid, int first_free_row, int stride, int width,
                           const std::function<void(double t, double* row)>& visit) {
  const int total = grid.skipped + grid.count;
  RowMajor values(grid.count, width);
  auto record_row = [&](int i) {
    return i >= grid.skipped ? values.row(i - grid.skipped).data() : nullptr;
  };
  const int exact_end = stride > 1 ? std::min(total, first_free_row + 2 * stride) : total;
  // Nodes k = 0, 1 lie among the rows evaluated at every sample; the first interpolated rows
  // (interval 2) need them.
  const int last_interval = total > exact_end ? (total - 1 - first_free_row) / stride : 0;
  RowMajor nodes(total > exact_end ? last_interval + kStencil - kBefore : 0, width);
  for (int i = 0; i < exact_end; ++i) {
    const bool node = stride > 1 && i >= first_free_row && (i - first_free_row) % stride == 0;
    double* row = record_row(i);
    if (node && nodes.rows() > 0) {
      double* at = nodes.row((i - first_free_row) / stride).data();
      visit(grid.Time(i), at);
      if (row != nullptr) std::copy(at, at + width, row);
    } else {
      visit(grid.Time(i), row);
    }
  }
  if (nodes.rows() == 0) return values;

  // Node k serves the rows of intervals k - 3 .. k + 2: one that serves no row of the record
  // (before its start) is not visited.
  for (int k = 2; k < nodes.rows(); ++k) {
    const int i = first_free_row + k * stride;
    if (i + (kStencil - kBefore - 1) * stride <= grid.skipped) continue;
    visit(grid.Time(i), nodes.row(k).data());
  }
  const std::vector<std::array<double, kStencil>> weights = CalcWeights(stride);
  for (int i = std::max(exact_end, grid.skipped); i < total; ++i) {
    const int k = (i - first_free_row) / stride;
    const int r = (i - first_free_row) % stride;
    auto row = values.row(i - grid.skipped);
    if (r == 0) {
      row = nodes.row(k);
      continue;
    }
    const auto& w = weights[static_cast<size_t>(r)];
    row = w[0] * nodes.row(k - kBefore);
    for (int a = 1; a < kStencil; ++a)
      row += w[static_cast<size_t>(a)] * nodes.row(k - kBefore + a);
  }
  return values;
}

}  // namespace mbid::simulation::internal
