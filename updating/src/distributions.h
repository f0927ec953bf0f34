#pragma once

#include <boost/math/policies/policy.hpp>

namespace mbid::updating::internal {

// Boost.Math's default policy evaluates double distributions in long double. Double is enough
// for tail probabilities and quantiles compared with a significance level, and its long double
// start-up tables overflow under valgrind's 64-bit emulation of x87 (the documented callgrind
// measurements could not run).
using DistributionPolicy =
    boost::math::policies::policy<boost::math::policies::promote_double<false>>;

}  // namespace mbid::updating::internal
