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

// The modal assurance criterion |a^H W b|^2 / (a^H W a b^H W b) of two complex shapes over the
// channels, W = diag(1 / noise^2): each channel in units of its noise (a channel without one,
// or an empty `noise`, counts as 1). Near 1 for one shape, near 0 for shapes in other channels
// or out of phase; 1 where a shape is zero.
inline double ShapeCorrelation(const Eigen::VectorXcd& a, const Eigen::VectorXcd& b,
                               const Eigen::VectorXd& noise = Eigen::VectorXd()) {
  std::complex<double> ab = 0;
  double aa = 0, bb = 0;
  for (Eigen::Index c = 0; c < a.size(); ++c) {
    const double w = c < noise.size() && noise[c] > 0 ? 1 / (noise[c] * noise[c]) : 1.0;
    ab += std::conj(a[c]) * b[c] * w;
    aa += std::norm(a[c]) * w;
    bb += std::norm(b[c]) * w;
  }
  return aa > 0 && bb > 0 ? std::norm(ab) / (aa * bb) : 1.0;
}

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
