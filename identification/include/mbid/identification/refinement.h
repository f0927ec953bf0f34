#pragma once

#include <Eigen/Core>
#include <complex>
#include <string>
#include <vector>

#include "mbid/identification/options.h"

namespace mbid::identification {

// The parameters of the signal model of modal_fit.h.
struct ModalModel {
  std::vector<std::complex<double>> lambda;  // K poles, lambda = -decay + i omega, omega > 0
  Eigen::MatrixXd coefficients;              // (2 K [+1]) x channels, rows C_k, S_k [, o]
  bool with_offset = false;
};

struct RefinementSummary {
  ModalModel model;
  int iterations = 0;
  // "converged", "no_convergence" (iteration limit, the last iterate is kept) or "failure".
  std::string termination;
  std::string message;      // Ceres' own words
  double initial_cost = 0;  // 1/2 sum of squared weighted residuals
  double final_cost = 0;
};

// Nonlinear least squares over every pole and every channel's coefficients:
//   min sum_c weight_c^2 sum_j (y_c(t_j) - model_c(t_j))^2,
// solved by variable projection: Ceres' Levenberg-Marquardt works on the 2 K pole parameters
// only, the coefficients being the linear least-squares solution for the current poles
// (modal_fit.h), with the exact (Golub-Pereyra) derivative of the projected residual. Same
// minimizer as the joint problem, fewer unknowns and iterations. Poles are bounded to
// 0 < omega <= pi / tau and -1 / T <= decay <= 1 / tau (T the record length) so that an
// iterate can neither alias nor blow up. The returned coefficients are those of the final poles.
RefinementSummary RefineModalModel(const Eigen::MatrixXd& values, double sample_interval_s,
                                   const Eigen::VectorXd& channel_weights,
                                   const ModalModel& initial, const RefinementOptions& options);

// Covariance of (decay_k, omega_k) of each mode at `model`: the (2 x 2 block of the)
// pseudo-inverse of the Fisher information J^T J of the weighted residuals with respect to all
// parameters (poles and coefficients), scaled by the residual variance
// s^2 = sum of squared weighted residuals / (samples * channels - parameters). At a least-squares
// estimate under white noise this is the Cramer-Rao bound evaluated at the estimate.
std::vector<Eigen::Matrix2d> CalcPoleCovariance(const Eigen::MatrixXd& values,
                                                double sample_interval_s,
                                                const Eigen::VectorXd& channel_weights,
                                                const ModalModel& model);

}  // namespace mbid::identification
