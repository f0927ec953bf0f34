// Small things the campaign's studies and runner share.
#pragma once

#include <Eigen/Core>
#include <limits>
#include <vector>

namespace mbid::campaign::internal {

// A value a case or a study did not produce, in tables, figures and files.
inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// `values` as an Eigen vector (a copy).
inline Eigen::VectorXd ToVector(const std::vector<double>& values) {
  return Eigen::Map<const Eigen::VectorXd>(values.data(), static_cast<Eigen::Index>(values.size()));
}

}  // namespace mbid::campaign::internal
