// Judging eq. 7's solution sets: admissibility, shapes (eq. 6), amplitudes (eq. 8), mismatch.
#include <Eigen/Dense>
#include <algorithm>
#include <boost/math/distributions/chi_squared.hpp>
#include <cmath>
#include <complex>
#include <limits>
#include <string>
#include <vector>

#include "characteristic_internal.h"
#include "distributions.h"
#include "mbid/common/eigen_decompositions.h"
#include "mbid/updating/characteristic.h"
#include "statistics.h"

namespace mbid::updating::internal {
std::string InadmissibleReason(const CharacteristicProblem& problem,
                               const CharacteristicSolution& solution) {
  std::string reason;
  for (Eigen::Index i = 0; i < solution.c.size(); ++i) {
    if (!(solution.c[i] > 0)) {
      reason += (reason.empty() ? "" : ", ") + ("c_" + problem.coordinates[i]) + " = " +
                FormatValue(solution.c[i]) + " <= 0";
    }
  }
  for (Eigen::Index i = 0; i < solution.d.size(); ++i) {
    if (!(solution.d[i] >= 0)) {
      reason += (reason.empty() ? "" : ", ") + ("d_" + problem.coordinates[i]) + " = " +
                FormatValue(solution.d[i]) + " < 0";
    }
  }
  return reason;
}

// w_k of eq. 6: the null vector of A(lambda_k), unit largest magnitude.
Eigen::VectorXcd CalcShape(const CharacteristicProblem& problem, Complex lambda,
                           const Eigen::VectorXd& c, const Eigen::VectorXd& d) {
  const Eigen::MatrixXcd A = CalcCharacteristicMatrix(problem, lambda, c, d);
  const Eigen::JacobiSVD<Eigen::MatrixXcd> svd(A, Eigen::ComputeFullV);
  Eigen::VectorXcd w = svd.matrixV().col(A.cols() - 1);
  Eigen::Index largest = 0;
  w.cwiseAbs().maxCoeff(&largest);
  return w / w[largest];
}

// Lags over which eq. 8's residual autocorrelation is summed: up to 101 samples per independent
// residual, so that a smooth residual (model error) does not pass for white noise.
constexpr int kResidualLags = 50;

// eq. 8: y_j = sum_k 2 Re(a_k H w_k exp(lambda_k t_j)) (+ offset) by linear least squares in
// Re a_k, Im a_k (minimum norm where a mode is invisible in the outputs).
void FitAmplitudes(const CharacteristicProblem& problem, const CharacteristicOptions& options,
                   CharacteristicSolution& solution) {
  const Measurement& record = *problem.record;
  const Eigen::Index n = problem.M.rows();
  std::vector<Eigen::Index> rows, columns;  // H rows and record columns of the used outputs
  for (size_t i = 0; i < problem.outputs.size(); ++i) {
    const int column = record.FindChannel(problem.outputs[i]);
    if (column >= 0) {
      rows.push_back(static_cast<Eigen::Index>(i));
      columns.push_back(column);
    }
  }
  const Eigen::Index m = static_cast<Eigen::Index>(rows.size());
  const Eigen::Index samples = record.samples();
  const Eigen::Index unknowns = 2 * n + (options.fit_offset ? m : 0);
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(samples * m, unknowns);
  Eigen::VectorXd b(samples * m);
  std::vector<Eigen::VectorXcd> output_shapes;
  for (Eigen::Index k = 0; k < n; ++k) {
    Eigen::VectorXcd shape = problem.H * solution.shapes[static_cast<size_t>(k)];
    // Rate outputs see the mode differentiated: lambda or lambda^2 times the shape.
    for (size_t i = 0; i < problem.output_orders.size(); ++i) {
      shape[static_cast<Eigen::Index>(i)] *=
          std::pow(problem.lambda[static_cast<size_t>(k)], problem.output_orders[i]);
    }
    output_shapes.push_back(shape);
  }
  for (Eigen::Index j = 0; j < samples; ++j) {
    const double t = record.start_time_s + static_cast<double>(j) * record.sample_interval_s;
    for (Eigen::Index r = 0; r < m; ++r) {
      const Eigen::Index row = j * m + r;
      b[row] = record.values(j, columns[static_cast<size_t>(r)]);
      for (Eigen::Index k = 0; k < n; ++k) {
        const Complex h = output_shapes[static_cast<size_t>(k)][rows[static_cast<size_t>(r)]] *
                          std::exp(problem.lambda[static_cast<size_t>(k)] * t);
        A(row, 2 * k) = 2 * h.real();
        A(row, 2 * k + 1) = -2 * h.imag();
      }
      if (options.fit_offset) A(row, 2 * n + r) = 1.0;
    }
  }
  const Eigen::VectorXd x = A.completeOrthogonalDecomposition().solve(b);
  solution.amplitudes.resize(n);
  solution.initial_q = Eigen::VectorXd::Zero(n);
  solution.initial_u = Eigen::VectorXd::Zero(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    const Complex a(x[2 * k], x[2 * k + 1]);
    solution.amplitudes[k] = a;
    const Eigen::VectorXcd& w = solution.shapes[static_cast<size_t>(k)];
    solution.initial_q += 2 * (a * w).real();
    solution.initial_u += 2 * (a * problem.lambda[static_cast<size_t>(k)] * w).real();
  }
  solution.offset = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(problem.outputs.size()));
  if (options.fit_offset) {
    for (Eigen::Index r = 0; r < m; ++r)
      solution.offset[rows[static_cast<size_t>(r)]] = x[2 * n + r];
  }
  const Eigen::VectorXd fit = A * x;
  const Eigen::Index outputs = static_cast<Eigen::Index>(problem.outputs.size());
  solution.correlation = Eigen::VectorXd::Constant(outputs, kNaN);
  solution.residual_ss = Eigen::VectorXd::Constant(outputs, kNaN);
  solution.total_ss = Eigen::VectorXd::Constant(outputs, kNaN);
  solution.residual_time = Eigen::VectorXd::Constant(outputs, kNaN);
  for (Eigen::Index r = 0; r < m; ++r) {
    Eigen::VectorXd measured(samples), reconstructed(samples);
    for (Eigen::Index j = 0; j < samples; ++j) {
      measured[j] = b[j * m + r];
      reconstructed[j] = fit[j * m + r];
    }
    const Eigen::Index output = rows[static_cast<size_t>(r)];
    solution.correlation[output] = CalcPearson(measured, reconstructed);
    solution.residual_ss[output] = (measured - reconstructed).squaredNorm();
    solution.total_ss[output] = (measured.array() - measured.mean()).matrix().squaredNorm();
    double q = 0, p = 0;
    Whiteness(measured - reconstructed, kResidualLags, &q, &p, &solution.residual_time[output]);
  }
}

void JudgeShapes(const CharacteristicProblem& problem, const CharacteristicOptions& options,
                 std::vector<CharacteristicSolution>& sets) {
  if (!problem.record) return;
  const double samples = static_cast<double>(problem.record->samples());
  // The best set: the least unexplained share of the record, summed over outputs (unit-free).
  const CharacteristicSolution* best = nullptr;
  double best_share = std::numeric_limits<double>::infinity();
  for (const CharacteristicSolution& set : sets) {
    if (!set.admissible || set.residual_ss.size() == 0) continue;
    double share = 0;
    for (Eigen::Index r = 0; r < set.residual_ss.size(); ++r) {
      if (std::isfinite(set.residual_ss[r]) && set.total_ss[r] > 0) {
        share += set.residual_ss[r] / set.total_ss[r];
      }
    }
    if (share < best_share) {
      best_share = share;
      best = &set;
    }
  }
  if (best == nullptr) return;
  // The best fit's residual per output is its noise (and model error) level, per independent
  // sample: a residual correlated over tau samples counts as samples / tau. A floor of 1e-6 of
  // the signal's amplitude keeps round-off differences of noiseless records equivalent.
  Eigen::VectorXd variance = best->residual_ss;
  int used = 0;
  for (Eigen::Index r = 0; r < variance.size(); ++r) {
    if (!std::isfinite(variance[r]) || !(best->total_ss[r] > 0)) continue;
    variance[r] =
        std::max(variance[r], 1e-12 * best->total_ss[r]) / samples * best->residual_time[r];
    ++used;
  }
  // The amplitudes' degrees of freedom: 2 per mode and an offset per output.
  const double dof =
      static_cast<double>(best->amplitudes.size() * 2 + (options.fit_offset ? used : 0));
  const boost::math::chi_squared_distribution<double, DistributionPolicy> chi_square(dof);
  const double limit =
      boost::math::quantile(boost::math::complement(chi_square, options.shape_significance));
  for (CharacteristicSolution& set : sets) {
    if (!set.admissible || set.residual_ss.size() == 0) continue;
    double misfit = 0;
    for (Eigen::Index r = 0; r < variance.size(); ++r) {
      if (!std::isfinite(variance[r]) || !(best->total_ss[r] > 0)) continue;
      misfit += (set.residual_ss[r] - best->residual_ss[r]) / variance[r];
    }
    // A set's residual below the best's (another output mix) counts as no misfit.
    set.shape_misfit = std::max(0.0, misfit);
    set.fits_shapes = set.shape_misfit <= limit;
  }
}

void CalcMismatch(const CharacteristicProblem& problem, CharacteristicSolution& solution) {
  double omega = 0;
  for (const Complex& lambda : problem.lambda) omega += std::abs(lambda);
  omega /= static_cast<double>(problem.lambda.size());
  if (problem.expected_free_decay_start) {
    const simulation::FreeDecayStart start =
        problem.expected_free_decay_start(solution.c, solution.d);
    solution.expected_time_s = start.time_s;
    solution.expected_initial_q = start.q;
    solution.expected_u = start.u;
    // The set's modes carried to the forcing's end.
    Eigen::VectorXd q = Eigen::VectorXd::Zero(start.q.size());
    Eigen::VectorXd u = q;
    for (size_t k = 0; k < problem.lambda.size(); ++k) {
      const Complex lambda = problem.lambda[k];
      const Complex a =
          solution.amplitudes[static_cast<Eigen::Index>(k)] * std::exp(lambda * start.time_s);
      q += 2 * (a * solution.shapes[k]).real();
      u += 2 * (a * lambda * solution.shapes[k]).real();
    }
    const double size = std::hypot(start.q.norm(), start.u.norm() / omega);
    solution.displacement_mismatch = (q - start.q).norm() / size;
    solution.velocity_mismatch = (u - start.u).norm() / (omega * size);
  } else if (problem.expected_initial_q) {
    solution.expected_initial_q = problem.expected_initial_q(solution.c, solution.d);
    const double size = solution.expected_initial_q.norm();
    solution.displacement_mismatch =
        (solution.initial_q - solution.expected_initial_q).norm() / size;
    solution.velocity_mismatch = solution.initial_u.norm() / (omega * size);
  } else {
    solution.displacement_mismatch = kNaN;
    solution.velocity_mismatch = solution.initial_u.norm() / (omega * solution.initial_q.norm());
  }
  solution.mismatch =
      std::hypot(std::isnan(solution.displacement_mismatch) ? 0.0 : solution.displacement_mismatch,
                 solution.velocity_mismatch);
}

double DistanceToReference(const CharacteristicProblem& problem,
                           const CharacteristicSolution& solution) {
  return std::sqrt(solution.c.cwiseQuotient(problem.c_reference).array().log().square().sum() +
                   solution.d.cwiseQuotient(problem.d_reference).array().log().square().sum());
}

}  // namespace mbid::updating::internal
