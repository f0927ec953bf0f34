#include "estimate.h"

#include <algorithm>
#include <cmath>

#include "mbid/common/error.h"

namespace mbid::identification {

Eigen::MatrixXd DecimatedResidual(const AnalysisRecord& record, const Estimate& estimate) {
  return record.decimated - estimate.fit.reconstruction.topRows(record.decimated.rows());
}

double RoundOffNoiseStd(const Eigen::MatrixXd& values, Eigen::Index c) {
  return 1e-6 * std::sqrt(values.col(c).squaredNorm() / static_cast<double>(values.rows()));
}

void NoModes(const std::string& reason) {
  throw NumericalError("identification", "no modes found: " + reason);
}

bool PassesFilter(std::complex<double> lambda, const IdentificationOptions& options,
                  double max_frequency_hz) {
  if (!std::isfinite(lambda.real()) || !std::isfinite(lambda.imag())) return false;
  const double frequency_hz = lambda.imag() / (2 * M_PI);
  const double decay = -lambda.real();
  const double damping_ratio = decay / std::abs(lambda);
  return frequency_hz > options.min_frequency_hz && frequency_hz <= max_frequency_hz &&
         damping_ratio >= options.min_damping_ratio && damping_ratio <= options.max_damping_ratio &&
         decay <= options.max_decay_rate_per_s;
}

Poles ToContinuous(const Poles& mu, double tau) {
  Poles lambda;
  for (const auto& z : mu) lambda.push_back(std::log(z) / tau);  // eq. 4
  return lambda;
}

bool HasMatch(std::complex<double> lambda, const Poles& others, double tolerance) {
  return std::any_of(others.begin(), others.end(), [&](std::complex<double> other) {
    return std::abs(other - lambda) <= tolerance * std::abs(lambda);
  });
}

int AutoStabilizationOrder(const IdentificationOptions& options, int effective_rank, int cap) {
  const int wanted = options.stabilization_max_order > 0 ? options.stabilization_max_order
                                                         : std::max(2 * effective_rank + 10, 20);
  return std::min(wanted, cap);
}

void MarkStable(std::vector<StabilizationOrder>* orders, double tolerance) {
  for (size_t i = 0; i < orders->size(); ++i) {
    StabilizationOrder& entry = (*orders)[i];
    const StabilizationOrder* next = nullptr;
    for (size_t j = i + 1; j < orders->size(); ++j) {
      if ((*orders)[j].order == entry.order + 2) next = &(*orders)[j];
    }
    entry.stable.assign(entry.lambda.size(), false);
    if (next == nullptr) continue;
    for (size_t k = 0; k < entry.lambda.size(); ++k) {
      entry.stable[k] = HasMatch(entry.lambda[k], next->lambda, tolerance);
    }
  }
}

StabilizationOrder UpperHalf(int order, const Poles& lambda) {
  StabilizationOrder entry;
  entry.order = order;
  for (const auto& pole : lambda) {
    if (pole.imag() >= 0 && std::isfinite(pole.real())) entry.lambda.push_back(pole);
  }
  return entry;
}

}  // namespace mbid::identification
