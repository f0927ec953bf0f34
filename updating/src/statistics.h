#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <boost/math/distributions/chi_squared.hpp>
#include <cmath>

#include "distributions.h"

namespace mbid::updating {

// Pearson's correlation of two equally long series (the paper's K of record and
// reconstruction); 0 when either is constant.
inline double CalcPearson(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  const Eigen::VectorXd x = a.array() - a.mean();
  const Eigen::VectorXd y = b.array() - b.mean();
  const double denominator = std::sqrt(x.squaredNorm() * y.squaredNorm());
  return denominator > 0 ? x.dot(y) / denominator : 0.0;
}

// Ljung-Box Q of `residual` over `lags` lags (at most a quarter of its length), its p-value
// (chi-square), and the integrated autocorrelation time 1 + 2 sum rho_k (at least 1): how many
// samples one independent residual spans.
// Two estimates correlated beyond this are known only in a combination (the warning "c_qa and
// c_qb are correlated -1", and the partner a parameter undetermined for its spread names).
inline constexpr double kCombinationCorrelation = 0.99;

inline void Whiteness(const Eigen::VectorXd& residual, int lags, double* q, double* p,
                      double* time) {
  const Eigen::VectorXd r = residual.array() - residual.mean();
  const double n = static_cast<double>(r.size());
  const double power = r.squaredNorm();
  const int count = std::min<int>(lags, static_cast<int>(r.size()) / 4);
  *q = 0;
  *time = 1;
  *p = 1;
  if (count < 1 || !(power > 0)) return;
  for (int k = 1; k <= count; ++k) {
    const double rho = r.head(r.size() - k).dot(r.tail(r.size() - k)) / power;
    *q += rho * rho / (n - k);
    *time += 2 * rho;
  }
  *q *= n * (n + 2);
  *time = std::max(1.0, *time);
  *p = boost::math::cdf(boost::math::complement(
      boost::math::chi_squared_distribution<double, internal::DistributionPolicy>(count), *q));
}

}  // namespace mbid::updating
