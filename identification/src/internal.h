#pragma once

// Helpers shared by the identification sources; not part of the public API.

#include <Eigen/Core>
#include <complex>
#include <optional>
#include <string>
#include <vector>

#include "mbid/identification/options.h"

namespace mbid::identification {

// The first option out of range: field name, problem, what was expected.
struct OptionProblem {
  std::string field;
  std::string problem;
  std::string expected;
};
std::optional<OptionProblem> FindOptionProblem(const IdentificationOptions& options);

// Samples between exact evaluations of exp(lambda t) in the recurrence z_(j+1) = mu z_j.
inline constexpr int kAnchorInterval = 256;

// Calls visit(i, exp(lambda * (first + i) * tau)) for i = 0..count-1.
template <typename Visit>
void ForEachModeSample(std::complex<double> lambda, double tau, int first, int count,
                       Visit&& visit) {
  const std::complex<double> mu = std::exp(lambda * tau);
  std::complex<double> z;
  for (int i = 0; i < count; ++i) {
    if (i % kAnchorInterval == 0) {
      z = std::exp(lambda * (static_cast<double>(first + i) * tau));
    } else {
      z *= mu;
    }
    visit(i, z);
  }
}

// CalcDampedSinusoidBasis into an existing matrix (resized only when the shape changes).
void FillDampedSinusoidBasis(const std::vector<std::complex<double>>& lambda,
                             double sample_interval_s, bool with_offset, int samples,
                             Eigen::MatrixXd* basis);

}  // namespace mbid::identification
