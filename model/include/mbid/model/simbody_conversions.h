#pragma once

// Conversions between Eigen and SimTK values (private to the model and simulation layers).
#include <Eigen/Core>

#include "mbid/model/simbody.h"

namespace mbid {

inline SimTK::Vec3 ToVec3(const Eigen::Vector3d& v) { return SimTK::Vec3(v[0], v[1], v[2]); }

inline SimTK::Vector ToVector(const Eigen::VectorXd& v) {
  SimTK::Vector result(static_cast<int>(v.size()));
  for (int i = 0; i < v.size(); ++i) result[i] = v[i];
  return result;
}

inline Eigen::VectorXd ToEigen(const SimTK::Vector& v) {
  Eigen::VectorXd result(v.size());
  for (int i = 0; i < v.size(); ++i) result[i] = v[i];
  return result;
}

inline Eigen::MatrixXd ToEigen(const SimTK::Matrix& m) {
  Eigen::MatrixXd result(m.nrow(), m.ncol());
  for (int i = 0; i < m.nrow(); ++i) {
    for (int j = 0; j < m.ncol(); ++j) result(i, j) = m(i, j);
  }
  return result;
}

}  // namespace mbid
