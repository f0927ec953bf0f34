#include "mbid/model/linear_model.h"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "mbid/common/eigen_decompositions.h"

namespace mbid::model {

double Mode::frequency_hz() const { return lambda.imag() / (2 * M_PI); }
double Mode::decay_rate_per_s() const { return -lambda.real(); }
double Mode::damping_ratio() const { return -lambda.real() / std::abs(lambda); }
double Mode::undamped_frequency_hz() const { return std::abs(lambda) / (2 * M_PI); }
double Mode::log_decrement() const { return 2 * M_PI * decay_rate_per_s() / lambda.imag(); }
double Mode::half_life_s() const { return std::log(2.0) / decay_rate_per_s(); }

std::vector<std::string> FindGrowingModes(const std::vector<Mode>& modes) {
  std::vector<std::string> lines;
  for (size_t k = 0; k < modes.size(); ++k) {
    if (!(modes[k].lambda.real() > 0)) continue;
    lines.push_back(fmt::format(
        "mode {} grows at {:.4g} 1/s: the machine is unstable at rest (a spring weaker than "
        "gravity's overturning stiffness?)",
        k + 1, modes[k].lambda.real()));
  }
  return lines;
}

std::string StiffnessUnits(const std::string& coordinate_unit) {
  return coordinate_unit == "m" ? "N/m" : "N*m/rad";
}

std::string DampingUnits(const std::string& coordinate_unit) {
  return coordinate_unit == "m" ? "N*s/m" : "N*m*s/rad";
}

namespace {

std::string MatrixUnits(const std::vector<std::string>& coordinate_units,
                        std::string (*units)(const std::string&)) {
  const std::string first = units(coordinate_units.empty() ? "rad" : coordinate_units[0]);
  for (const std::string& unit : coordinate_units) {
    if (units(unit) != first) return "SI, per coordinate (coordinate_units)";
  }
  return first;
}

}  // namespace

std::string StiffnessMatrixUnits(const std::vector<std::string>& coordinate_units) {
  return MatrixUnits(coordinate_units, &StiffnessUnits);
}

std::string DampingMatrixUnits(const std::vector<std::string>& coordinate_units) {
  return MatrixUnits(coordinate_units, &DampingUnits);
}

std::vector<Mode> CalcModes(const LinearModel& linear) {
  const Eigen::Index n = linear.M.rows();
  if (linear.M.cols() != n || linear.C.rows() != n || linear.C.cols() != n ||
      linear.D.rows() != n || linear.D.cols() != n || linear.H.cols() != n) {
    throw std::invalid_argument("CalcModes: M, D, C must be n x n and H m x n");
  }
  if (!linear.output_orders.empty() &&
      static_cast<Eigen::Index>(linear.output_orders.size()) != linear.H.rows()) {
    throw std::invalid_argument("CalcModes: one output order per row of H");
  }
  // First-order form x' = A x, x = [q; q'] (the exact poles of eq. 1 with r = 0).
  const Eigen::PartialPivLU<Eigen::MatrixXd> M_lu(linear.M);
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(2 * n, 2 * n);
  A.topRightCorner(n, n).setIdentity();
  A.bottomLeftCorner(n, n) = -M_lu.solve(linear.C);
  A.bottomRightCorner(n, n) = -M_lu.solve(linear.D);
  const Eigen::EigenSolver<Eigen::MatrixXd> eigen(A);
  if (eigen.info() != Eigen::Success) throw std::runtime_error("CalcModes: eigensolver failed");

  // Rigid-body motions (free coordinates) give a double pole at 0 that the eigensolver returns
  // as +-1e-8 i or so: a pole at roundoff of the largest one is no oscillation.
  const double roundoff = 1e-7 * std::max(1.0, eigen.eigenvalues().cwiseAbs().maxCoeff());
  std::vector<Mode> oscillatory, real;
  for (Eigen::Index k = 0; k < 2 * n; ++k) {
    std::complex<double> lambda = eigen.eigenvalues()[k];
    // Both members become real poles at 0, as a double root should.
    if (std::abs(lambda) < roundoff) lambda = 0.0;
    // Keep one member of each conjugate pair; a real pole is its own partner.
    if (lambda.imag() < 0) continue;
    Mode mode;
    mode.lambda = lambda;
    mode.shape = eigen.eigenvectors().col(k).head(n);
    Eigen::Index largest = 0;
    mode.shape.cwiseAbs().maxCoeff(&largest);
    mode.shape /= mode.shape[largest];
    mode.output_shape = linear.H * mode.shape;
    // A rate output sees the shape differentiated: q' = lambda q, q'' = lambda^2 q.
    for (size_t i = 0; i < linear.output_orders.size(); ++i) {
      mode.output_shape[static_cast<Eigen::Index>(i)] *= std::pow(lambda, linear.output_orders[i]);
    }
    (lambda.imag() > 0 ? oscillatory : real).push_back(mode);
  }
  std::sort(oscillatory.begin(), oscillatory.end(),
            [](const Mode& a, const Mode& b) { return a.lambda.imag() < b.lambda.imag(); });
  std::sort(real.begin(), real.end(),
            [](const Mode& a, const Mode& b) { return a.lambda.real() > b.lambda.real(); });
  // Ascending frequency, as the contract lists modes: the real poles (frequency 0) first.
  real.insert(real.end(), oscillatory.begin(), oscillatory.end());
  return real;
}

}  // namespace mbid::model
