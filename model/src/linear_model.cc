#include "mbid/model/linear_model.h"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <utility>

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

std::vector<std::string> FindImpreciseModes(const std::vector<Mode>& modes) {
  double fastest = 0, smallest = std::numeric_limits<double>::infinity();
  for (const Mode& mode : modes) {
    const double magnitude = std::abs(mode.lambda);
    fastest = std::max(fastest, magnitude);
    if (magnitude > 0) smallest = std::min(smallest, magnitude);
  }
  // omega^2 is solved to about eps |C| (of the fastest omega^2): the smallest's relative error.
  const double error =
      0.5 * std::numeric_limits<double>::epsilon() * fastest * fastest / (smallest * smallest);
  if (!(error > 1e-6) || std::isinf(smallest)) return {};
  return {fmt::format(
      "the modes span {:.4g} to {:.4g} Hz (undamped): double precision bounds the slowest's "
      "error only by {:.1g} of itself, and beyond 1e-3 by nothing (a joint given a huge "
      "stiffness to make it rigid is better welded, joint type: weld; a body far lighter than "
      "the others, merged)",
      smallest / (2 * M_PI), fastest / (2 * M_PI), error)};
}

std::vector<std::string> FindModeDoubts(const std::vector<Mode>& modes) {
  std::vector<std::string> lines = FindGrowingModes(modes);
  for (std::string& line : FindImpreciseModes(modes)) lines.push_back(std::move(line));
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
  // First-order form x' = A x (the exact poles of eq. 1 with r = 0). M, C, D symmetric (M
  // positive definite), as a linearization at rest makes them: in the undamped modes q = Phi p
  // (C Phi = M Phi Omega^2, Phi' M Phi = I, solved symmetric and so to eps * |C| in omega^2) with
  // x = [S p; p'], S = |omega| (1 for a pole at 0), A = [0 S; -Omega^2 / S  -Phi' D Phi] has a
  // norm of the largest omega, not its square: a joint 1e12 times stiffer than the others put
  // the fast mode 6.8 % and the slow mode's decay 1.7 % off in the plain form [0 I; -M^-1 C
  // -M^-1 D] (|A| ~ omega_max^2), and a body 1e-9 kg light lost a mode to round-off.
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(2 * n, 2 * n);
  Eigen::MatrixXd to_q;   // q = to_q * (top half of x)
  Eigen::VectorXd scale;  // per top state
  const bool symmetric = linear.M.isApprox(linear.M.transpose(), 1e-12) &&
                         linear.C.isApprox(linear.C.transpose(), 1e-12) &&
                         linear.D.isApprox(linear.D.transpose(), 1e-12);
  std::optional<Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd>> undamped;
  if (symmetric) undamped.emplace(linear.C, linear.M);  // not solved for the other form
  if (undamped && undamped->info() == Eigen::Success) {
    const Eigen::MatrixXd& phi = undamped->eigenvectors();
    const Eigen::VectorXd& omega2 = undamped->eigenvalues();
    scale = omega2.cwiseAbs().cwiseSqrt();
    for (Eigen::Index i = 0; i < n; ++i) {
      if (!(scale[i] > 0)) scale[i] = 1;
    }
    A.topRightCorner(n, n) = scale.asDiagonal();
    A.bottomLeftCorner(n, n) = (-omega2.cwiseQuotient(scale)).asDiagonal();
    A.bottomRightCorner(n, n) = -phi.transpose() * linear.D * phi;
    to_q = phi * scale.cwiseInverse().asDiagonal();
  } else {
    const Eigen::PartialPivLU<Eigen::MatrixXd> M_lu(linear.M);
    A.topRightCorner(n, n).setIdentity();
    A.bottomLeftCorner(n, n) = -M_lu.solve(linear.C);
    A.bottomRightCorner(n, n) = -M_lu.solve(linear.D);
    to_q = Eigen::MatrixXd::Identity(n, n);
  }
  const Eigen::EigenSolver<Eigen::MatrixXd> eigen(A);
  if (eigen.info() != Eigen::Success) throw std::runtime_error("CalcModes: eigensolver failed");

  // Rigid-body motions (free coordinates) give a double pole at 0, a Jordan block that round-off
  // e splits to +-sqrt(e) (+-1e-8 i or so on the crane): a pole that small beside the largest
  // is no oscillation. (1e-7 of the largest had taken a light body's 2.75 Hz mode for one.)
  const double biggest = std::max(1.0, eigen.eigenvalues().cwiseAbs().maxCoeff());
  const double roundoff = 1e3 * std::sqrt(std::numeric_limits<double>::epsilon() * biggest);
  std::vector<Mode> oscillatory, real;
  for (Eigen::Index k = 0; k < 2 * n; ++k) {
    std::complex<double> lambda = eigen.eigenvalues()[k];
    // Both members become real poles at 0, as a double root should.
    if (std::abs(lambda) < roundoff) lambda = 0.0;
    // Keep one member of each conjugate pair; a real pole is its own partner.
    if (lambda.imag() < 0) continue;
    Mode mode;
    mode.lambda = lambda;
    mode.shape = to_q * eigen.eigenvectors().col(k).head(n);
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
