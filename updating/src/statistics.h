#pragma once

#include <Eigen/Core>
#include <cmath>

namespace mbid::updating {

// Pearson's correlation of two equally long series (the paper's K of record and
// reconstruction); 0 when either is constant.
inline double CalcPearson(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  const Eigen::VectorXd x = a.array() - a.mean();
  const Eigen::VectorXd y = b.array() - b.mean();
  const double denominator = std::sqrt(x.squaredNorm() * y.squaredNorm());
  return denominator > 0 ? x.dot(y) / denominator : 0.0;
}

}  // namespace mbid::updating
