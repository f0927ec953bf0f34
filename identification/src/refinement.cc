#include "mbid/identification/refinement.h"

#include <ceres/ceres.h>

#include <Eigen/QR>
#include <algorithm>
#include <array>
#include <cmath>
#include <memory>

#include "internal.h"
#include "mbid/common/eigen_decompositions.h"
#include "mbid/common/stop.h"
#include "mbid/identification/modal_fit.h"

namespace mbid::identification {
namespace {

// A long record's refinement runs for seconds: a requested stop (stop.h) ends it at the next
// iteration.
class StopWhenRequested final : public ceres::IterationCallback {
 public:
  ceres::CallbackReturnType operator()(const ceres::IterationSummary&) override {
    return StopRequested() ? ceres::SOLVER_ABORT : ceres::SOLVER_CONTINUE;
  }
};

// Rows per residual block: short enough for cache-friendly Jacobian blocks.
constexpr int kChunkSamples = 1024;

// Weighted residuals r_j = w (y_c(t_j) - model_c(t_j)) of one channel over samples
// first..first+count-1. Parameter blocks: one {decay, omega} per mode, then the channel's
// coefficients {C_1, S_1, ..., C_K, S_K [, o]}.
class ChannelChunkCost final : public ceres::CostFunction {
 public:
  ChannelChunkCost(const double* y, int first, int count, double tau, double weight, int modes,
                   bool with_offset)
      : y_(y),
        first_(first),
        tau_(tau),
        weight_(weight),
        modes_(modes),
        coefficient_count_(2 * modes + (with_offset ? 1 : 0)),
        with_offset_(with_offset) {
    set_num_residuals(count);
    for (int k = 0; k < modes; ++k) mutable_parameter_block_sizes()->push_back(2);
    mutable_parameter_block_sizes()->push_back(coefficient_count_);
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const int count = num_residuals();
    const double w = weight_;
    const double* coefficients = parameters[modes_];
    const double offset = with_offset_ ? coefficients[coefficient_count_ - 1] : 0.0;
    for (int i = 0; i < count; ++i) residuals[i] = w * (y_[first_ + i] - offset);
    double* coefficient_jacobian = jacobians != nullptr ? jacobians[modes_] : nullptr;
    if (coefficient_jacobian != nullptr && with_offset_) {
      for (int i = 0; i < count; ++i)
        coefficient_jacobian[i * coefficient_count_ + 2 * modes_] = -w;
    }
    for (int k = 0; k < modes_; ++k) {
      const std::complex<double> lambda(-parameters[k][0], parameters[k][1]);
      const std::complex<double> a(coefficients[2 * k], coefficients[2 * k + 1]);  // C + i S
      double* pole_jacobian = jacobians != nullptr ? jacobians[k] : nullptr;
      ForEachModeSample(lambda, tau_, first_, count, [&](int i, std::complex<double> z) {
        const std::complex<double> u = a * z;  // the mode's term is Re(u)
        residuals[i] -= w * u.real();
        if (pole_jacobian != nullptr) {
          const double t = (first_ + i) * tau_;
          pole_jacobian[2 * i] = w * t * u.real();      // d/d decay
          pole_jacobian[2 * i + 1] = w * t * u.imag();  // d/d omega
        }
        if (coefficient_jacobian != nullptr) {
          coefficient_jacobian[i * coefficient_count_ + 2 * k] = -w * z.real();
          coefficient_jacobian[i * coefficient_count_ + 2 * k + 1] = w * z.imag();
        }
      });
    }
    return true;
  }

 private:
  const double* y_;
  int first_;
  double tau_;
  double weight_;
  int modes_;
  int coefficient_count_;
  bool with_offset_;
};

// Variable projection (Golub-Pereyra): for poles theta the coefficients are the linear
// least-squares solution beta = Phi^+ y_c, and the residual of channel c is
// r_c = w_c P y_c with P = I - Phi Phi^+. Its exact derivative with respect to a pole
// parameter is
//   dr_c/dtheta = -w_c (P Phi_theta beta_c + (Phi^+)^T Phi_theta^T P y_c),
// where Phi_theta has the two nonzero columns of the pole's own pair. Residuals: all samples of
// channel 0, then channel 1, ...; parameter blocks: one {decay, omega} per mode.
class VarProCost final : public ceres::CostFunction {
 public:
  VarProCost(const Eigen::MatrixXd& values, double tau, const Eigen::VectorXd& weights, int modes,
             bool with_offset)
      : values_(values),
        tau_(tau),
        min_decay_(-1.0 / (values.rows() * tau)),
        weights_(weights),
        modes_(modes),
        with_offset_(with_offset),
        t_(Eigen::ArrayXd::LinSpaced(values.rows(), 0.0, (values.rows() - 1) * tau)) {
    set_num_residuals(static_cast<int>(values.size()));
    for (int k = 0; k < modes; ++k) mutable_parameter_block_sizes()->push_back(2);
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const int n = static_cast<int>(values_.rows());
    const int channels = static_cast<int>(values_.cols());
    lambda_.clear();
    for (int k = 0; k < modes_; ++k) {
      const double decay = parameters[k][0];
      const double omega = parameters[k][1];
      // Out of the admissible range: rejected, so that an iterate can neither alias nor blow
      // up (bounds in Ceres would add a line search with extra Jacobian evaluations per step).
      if (!(omega > 0 && omega <= M_PI / tau_ && decay >= min_decay_ && decay <= 1.0 / tau_)) {
        return false;
      }
      lambda_.emplace_back(-decay, omega);
    }
    FillDampedSinusoidBasis(lambda_, tau_, with_offset_, n, &phi_);
    const int p = static_cast<int>(phi_.cols());
    qr_.compute(phi_);
    // A (near) rank-deficient basis (two poles merged) has no unique projection: reject the
    // step, Levenberg-Marquardt then shortens it.
    const Eigen::VectorXd diagonal = qr_.matrixQR().diagonal().head(p).cwiseAbs();
    if (!(diagonal.minCoeff() > 1e-13 * diagonal.maxCoeff())) return false;
    const auto r = qr_.matrixQR().topLeftCorner(p, p).triangularView<Eigen::Upper>();
    beta_ = qr_.solve(values_);  // Phi^+ y, p x m
    projected_ = values_;
    projected_.noalias() -= phi_ * beta_;  // P y, n x m
    Eigen::Map<Eigen::MatrixXd>(residuals, n, channels) = projected_ * weights_.asDiagonal();
    if (jacobians == nullptr) return true;

    // Column (2 k + which) * m + c of `v` is Phi_theta beta_c for theta = decay_k (which 0) or
    // omega_k (which 1); the same column of `u` is Phi_theta^T P y_c (nonzero in rows 2k, 2k+1).
    // Phi_theta's two columns: d/d decay = -t [cos_column, sin_column], d/d omega =
    // t [sin_column, -cos_column], with cos_column = e^(-dt) cos(wt) and sin_column =
    // -e^(-dt) sin(wt) the pole's columns of Phi.
    const int thetas = 2 * modes_;
    v_.resize(n, thetas * channels);
    u_.setZero(p, thetas * channels);
    dphi_.resize(n, 4);
    for (int k = 0; k < modes_; ++k) {
      dphi_.col(0) = -t_ * phi_.col(2 * k).array();      // d/d decay
      dphi_.col(1) = -t_ * phi_.col(2 * k + 1).array();  //
      dphi_.col(2) = -dphi_.col(1);                      // d/d omega
      dphi_.col(3) = dphi_.col(0);                       //
      for (int which = 0; which < 2; ++which) {
        const auto columns = dphi_.middleCols(2 * which, 2);
        const int first = (2 * k + which) * channels;
        v_.middleCols(first, channels).noalias() = columns * beta_.middleRows(2 * k, 2);
        u_.block(2 * k, first, 2, channels).noalias() = columns.transpose() * projected_;
      }
    }
    // dr/dtheta = -w (P v + (Phi^+)^T u) = -w (v - Phi R^-1 R^-T (Phi^T v - u)). The
    // semi-normal form (R from the QR, no second pass of Householder reflections) is 3x cheaper;
    // its error only slows convergence down a little, the residual itself is exact.
    coefficients_ = -u_;
    coefficients_.noalias() += phi_.transpose() * v_;
    r.transpose().solveInPlace(coefficients_);
    r.solveInPlace(coefficients_);
    v_.noalias() -= phi_ * coefficients_;
    for (int k = 0; k < modes_; ++k) {
      if (jacobians[k] == nullptr) continue;
      Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor>> jacobian(
          jacobians[k], static_cast<Eigen::Index>(n) * channels, 2);
      for (int which = 0; which < 2; ++which) {
        for (int c = 0; c < channels; ++c) {
          jacobian.col(which).segment(static_cast<Eigen::Index>(c) * n, n) =
              -weights_(c) * v_.col((2 * k + which) * channels + c);
        }
      }
    }
    return true;
  }

 private:
  const Eigen::MatrixXd& values_;
  double tau_;
  double min_decay_;  // a mode may grow by at most e over the record
  Eigen::VectorXd weights_;
  int modes_;
  bool with_offset_;
  Eigen::ArrayXd t_;
  // Scratch reused across evaluations (Ceres runs single-threaded here): no allocation per call.
  mutable std::vector<std::complex<double>> lambda_;
  mutable Eigen::MatrixXd phi_, beta_, projected_, v_, u_, dphi_, coefficients_;
  mutable Eigen::HouseholderQR<Eigen::MatrixXd> qr_;
};

// The parameters in the layout Ceres works on.
struct ParameterBlocks {
  std::vector<std::array<double, 2>> poles;       // {decay, omega}
  std::vector<std::vector<double>> coefficients;  // per channel

  explicit ParameterBlocks(const ModalModel& model) {
    for (const auto& lambda : model.lambda) poles.push_back({-lambda.real(), lambda.imag()});
    for (Eigen::Index c = 0; c < model.coefficients.cols(); ++c) {
      const Eigen::VectorXd column = model.coefficients.col(c);
      coefficients.emplace_back(column.data(), column.data() + column.size());
    }
  }
};

// One cost per channel and chunk of samples, each over every pole and its channel's
// coefficients. The costs are owned by the caller's vector or a Problem.
template <typename Add>
void ForEachChunk(const Eigen::MatrixXd& values, double tau, const Eigen::VectorXd& weights,
                  int modes, bool with_offset, Add&& add) {
  const int samples = static_cast<int>(values.rows());
  for (Eigen::Index c = 0; c < values.cols(); ++c) {
    for (int first = 0; first < samples; first += kChunkSamples) {
      const int count = std::min(kChunkSamples, samples - first);
      add(static_cast<int>(c),
          std::make_unique<ChannelChunkCost>(values.col(c).data(), first, count, tau, weights(c),
                                             modes, with_offset));
    }
  }
}

}  // namespace

RefinementSummary RefineModalModel(const Eigen::MatrixXd& values, double sample_interval_s,
                                   const Eigen::VectorXd& channel_weights,
                                   const ModalModel& initial, const RefinementOptions& options) {
  const int modes = static_cast<int>(initial.lambda.size());
  ParameterBlocks blocks(initial);
  // Ceres must start from an admissible point (VarProCost::Evaluate): poles are moved inside
  // the admissible range, and coincident poles (a rank-deficient basis) apart by 1e-6.
  const double record_s = values.rows() * sample_interval_s;
  for (size_t k = 0; k < blocks.poles.size(); ++k) {
    auto& [decay, omega] = blocks.poles[k];
    decay = std::clamp(decay, -0.5 / record_s, 0.5 / sample_interval_s);
    omega = std::clamp(omega, 1e-6 / sample_interval_s, (1 - 1e-6) * M_PI / sample_interval_s);
    for (size_t i = 0; i < k; ++i) {
      const auto& other = blocks.poles[i];
      if (std::hypot(other[0] - decay, other[1] - omega) < 1e-6 * std::hypot(decay, omega)) {
        omega *= 1 + 1e-6;
      }
    }
  }
  ceres::Problem problem;
  std::vector<double*> parameters;
  for (auto& pole : blocks.poles) parameters.push_back(pole.data());
  problem.AddResidualBlock(
      new VarProCost(values, sample_interval_s, channel_weights, modes, initial.with_offset),
      nullptr, parameters);
  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::DENSE_QR;
  solver_options.max_num_iterations = options.max_iterations;
  solver_options.function_tolerance = options.function_tolerance;
  solver_options.parameter_tolerance = options.parameter_tolerance;
  solver_options.gradient_tolerance = options.gradient_tolerance;
  solver_options.num_threads = 1;
  solver_options.logging_type = ceres::SILENT;
  StopWhenRequested stop;
  solver_options.callbacks = {&stop};
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem, &summary);
  ThrowIfStopRequested();

  RefinementSummary result;
  result.model.with_offset = initial.with_offset;
  for (const auto& pole : blocks.poles) result.model.lambda.emplace_back(-pole[0], pole[1]);
  result.model.coefficients =
      FitAmplitudes(values, sample_interval_s, result.model.lambda, initial.with_offset)
          .coefficients;
  result.iterations = static_cast<int>(summary.iterations.size()) - 1;
  result.initial_cost = summary.initial_cost;
  result.final_cost = summary.final_cost;
  result.message = summary.message;
  switch (summary.termination_type) {
    case ceres::CONVERGENCE:
      result.termination = "converged";
      break;
    case ceres::NO_CONVERGENCE:
      result.termination = "no_convergence";
      break;
    default:
      result.termination = "failure";
      break;
  }
  return result;
}

std::vector<Eigen::Matrix2d> CalcPoleCovariance(const Eigen::MatrixXd& values,
                                                double sample_interval_s,
                                                const Eigen::VectorXd& channel_weights,
                                                const ModalModel& model) {
  const int modes = static_cast<int>(model.lambda.size());
  const int channels = static_cast<int>(values.cols());
  const int coefficient_count = static_cast<int>(model.coefficients.rows());
  const int parameters = 2 * modes + channels * coefficient_count;
  ParameterBlocks blocks(model);

  // Fisher information J^T J accumulated chunk by chunk: memory O(parameters^2), not O(samples).
  Eigen::MatrixXd fisher = Eigen::MatrixXd::Zero(parameters, parameters);
  double residual_sum_of_squares = 0;
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  ForEachChunk(values, sample_interval_s, channel_weights, modes, model.with_offset,
               [&](int channel, std::unique_ptr<ChannelChunkCost> cost) {
                 const int count = cost->num_residuals();
                 std::vector<const double*> parameter_blocks;
                 for (const auto& pole : blocks.poles) parameter_blocks.push_back(pole.data());
                 parameter_blocks.push_back(blocks.coefficients[channel].data());
                 std::vector<RowMajor> pole_jacobians(modes, RowMajor(count, 2));
                 RowMajor coefficient_jacobian(count, coefficient_count);
                 std::vector<double*> jacobians;
                 for (auto& jacobian : pole_jacobians) jacobians.push_back(jacobian.data());
                 jacobians.push_back(coefficient_jacobian.data());
                 Eigen::VectorXd residuals(count);
                 cost->Evaluate(parameter_blocks.data(), residuals.data(), jacobians.data());
                 residual_sum_of_squares += residuals.squaredNorm();
                 Eigen::MatrixXd jacobian = Eigen::MatrixXd::Zero(count, parameters);
                 for (int k = 0; k < modes; ++k) jacobian.middleCols(2 * k, 2) = pole_jacobians[k];
                 jacobian.middleCols(2 * modes + channel * coefficient_count, coefficient_count) =
                     coefficient_jacobian;
                 fisher.selfadjointView<Eigen::Lower>().rankUpdate(jacobian.transpose());
               });
  fisher = fisher.selfadjointView<Eigen::Lower>();

  // Pseudo-inverse of the Jacobi-scaled matrix (amplitudes and rates differ by orders of
  // magnitude); directions below 1e-14 of the largest eigenvalue are treated as unidentifiable.
  const Eigen::VectorXd scale =
      fisher.diagonal().cwiseMax(std::numeric_limits<double>::min()).cwiseSqrt().cwiseInverse();
  const Eigen::MatrixXd scaled = scale.asDiagonal() * fisher * scale.asDiagonal();
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(scaled);
  const Eigen::VectorXd& d = eigen.eigenvalues();
  const double cutoff = 1e-14 * d.maxCoeff();
  const Eigen::VectorXd inverse_d = (d.array() > cutoff).select(d.cwiseInverse(), 0.0);
  const Eigen::MatrixXd covariance = scale.asDiagonal() * eigen.eigenvectors() *
                                     inverse_d.asDiagonal() * eigen.eigenvectors().transpose() *
                                     scale.asDiagonal();
  const double dof = std::max(1, static_cast<int>(values.size()) - parameters);
  const double residual_variance = residual_sum_of_squares / dof;

  std::vector<Eigen::Matrix2d> result;
  for (int k = 0; k < modes; ++k) {
    result.push_back(covariance.block<2, 2>(2 * k, 2 * k) * residual_variance);
  }
  return result;
}

}  // namespace mbid::identification
