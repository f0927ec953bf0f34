// Telling the global search's end points apart: parameter differences and the F-test.
#include <boost/math/distributions/fisher_f.hpp>
#include <cmath>
#include <string>
#include <vector>

#include "distributions.h"
#include "global_search_internal.h"
#include "mbid/updating/global_search.h"

namespace mbid::updating {
namespace internal {
namespace {

// Ceres' coordinate of a parameter and the relative size of a difference in it.
double Internal(const ParameterEstimate& p, double value) {
  return p.log_scale ? std::log(value) : value / std::max(std::abs(p.value), 1e-6);
}

}  // namespace

std::vector<std::string> Differences(const UpdateResult& a, const UpdateResult& b, double tolerance,
                                     bool combined_std) {
  std::vector<std::string> differ;
  for (const ParameterEstimate& p : a.parameters) {
    if (!p.test.empty()) continue;
    const ParameterEstimate& q = b.Find(p.name);
    const double distance = std::abs(Internal(p, p.value) - Internal(p, q.value));
    double allowed = tolerance;
    const double std = combined_std ? std::hypot(p.relative_std, q.relative_std) : p.relative_std;
    if (std::isfinite(std)) allowed = std::max(allowed, 3 * std);
    if (distance > allowed) differ.push_back(p.name);
  }
  return differ;
}

}  // namespace internal

double FQuantile(double alpha, double d1, double d2) {
  return boost::math::quantile(boost::math::complement(
      boost::math::fisher_f_distribution<double, internal::DistributionPolicy>(d1, d2), alpha));
}

double FSurvival(double f, double d1, double d2) {
  if (!(f > 0)) return 1.0;
  return boost::math::cdf(boost::math::complement(
      boost::math::fisher_f_distribution<double, internal::DistributionPolicy>(d1, d2), f));
}

}  // namespace mbid::updating
