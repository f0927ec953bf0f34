#include "mbid/updating/characteristic.h"

#include <ceres/ceres.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <sstream>

#include "characteristic_internal.h"
#include "mbid/common/stop.h"

namespace mbid::updating {
using internal::CalcCharacteristicMatrix;
using internal::CalcMismatch;
using internal::CalcShape;
using internal::Complex;
using internal::DistanceToReference;
using internal::FitAmplitudes;
using internal::FormatValue;
using internal::InadmissibleReason;
using internal::JudgeShapes;
using internal::kNaN;

namespace internal {

// A(lambda) = M lambda^2 + D lambda + C with D = diag(d), C = diag(c) + K_g.
Eigen::MatrixXcd CalcCharacteristicMatrix(const CharacteristicProblem& problem, Complex lambda,
                                          const Eigen::VectorXd& c, const Eigen::VectorXd& d) {
  Eigen::MatrixXcd A = problem.M.cast<Complex>() * (lambda * lambda) + problem.K_g.cast<Complex>();
  for (Eigen::Index i = 0; i < A.rows(); ++i) A(i, i) += c[i] + d[i] * lambda;
  return A;
}

}  // namespace internal

namespace {

// det(A) with A's row and column i removed: d det(A) / d A_ii, exact even where A is singular.
// Sizes 3 and 4 use Eigen's closed-form determinants and no heap: Route 1 evaluates these
// hundreds of thousands of times.
template <int N>
Complex CalcPrincipalMinor(const Eigen::Matrix<Complex, N, N>& A, Eigen::Index i) {
  const Eigen::Index n = A.rows();
  if (n == 1) return 1.0;
  constexpr int kMinor = N == Eigen::Dynamic ? Eigen::Dynamic : N - 1;
  Eigen::Matrix<Complex, kMinor, kMinor> minor(n - 1, n - 1);
  for (Eigen::Index r = 0, rr = 0; r < n; ++r) {
    if (r == i) continue;
    for (Eigen::Index s = 0, ss = 0; s < n; ++s) {
      if (s == i) continue;
      minor(rr, ss++) = A(r, s);
    }
    ++rr;
  }
  return minor.determinant();
}

// s_k: the size det(A(lambda_k)) has at the reference, so that the residuals are O(1).
Eigen::VectorXd CalcResidualScales(const CharacteristicProblem& problem) {
  const Eigen::Index n = problem.M.rows();
  Eigen::VectorXd scale(static_cast<Eigen::Index>(problem.lambda.size()));
  for (size_t k = 0; k < problem.lambda.size(); ++k) {
    const double magnitude = std::abs(problem.lambda[k]);
    double product = 1.0;
    for (Eigen::Index i = 0; i < n; ++i) {
      product *= std::abs(problem.M(i, i)) * magnitude * magnitude + problem.c_reference[i] +
                 problem.d_reference[i] * magnitude;
    }
    scale[static_cast<Eigen::Index>(k)] = product;
  }
  return scale;
}

// eq. 7 for Ceres in scaled unknowns x = [c / c_ref; d / d_ref]: per pole the real and imaginary
// part of det(A(lambda_k)) / s_k, with the exact derivatives d det / d c_i = minor_ii and
// d det / d d_i = lambda_k minor_ii (the determinant is affine in each diagonal entry).
class CharacteristicCost final : public ceres::CostFunction {
 public:
  CharacteristicCost(const CharacteristicProblem& problem, Eigen::VectorXd scale)
      : problem_(problem), scale_(std::move(scale)), n_(problem.M.rows()) {
    set_num_residuals(static_cast<int>(2 * problem.lambda.size()));
    mutable_parameter_block_sizes()->push_back(static_cast<int>(2 * n_));
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    switch (n_) {
      case 3:
        return EvaluateSized<3>(parameters[0], residuals, jacobians);
      case 4:
        return EvaluateSized<4>(parameters[0], residuals, jacobians);
      default:
        return EvaluateSized<Eigen::Dynamic>(parameters[0], residuals, jacobians);
    }
  }

 private:
  template <int N>
  bool EvaluateSized(const double* parameters, double* residuals, double** jacobians) const {
    const Eigen::Map<const Eigen::VectorXd> x(parameters, 2 * n_);
    const Eigen::Index columns = 2 * n_;
    Eigen::Matrix<Complex, N, N> A(n_, n_);
    for (size_t k = 0; k < problem_.lambda.size(); ++k) {
      const Complex lambda = problem_.lambda[k];
      // A(lambda) = M lambda^2 + D lambda + C, as CalcCharacteristicMatrix forms it.
      A = problem_.M.cast<Complex>() * (lambda * lambda) + problem_.K_g.cast<Complex>();
      for (Eigen::Index i = 0; i < n_; ++i) {
        A(i, i) += problem_.c_reference[i] * x[i] + problem_.d_reference[i] * x[n_ + i] * lambda;
      }
      const double scale = scale_[static_cast<Eigen::Index>(k)];
      const Complex det = A.determinant() / scale;
      residuals[2 * k] = det.real();
      residuals[2 * k + 1] = det.imag();
      if (jacobians == nullptr || jacobians[0] == nullptr) continue;
      for (Eigen::Index i = 0; i < n_; ++i) {
        const Complex minor = CalcPrincipalMinor<N>(A, i) / scale;
        const Complex by_c = minor * problem_.c_reference[i];
        const Complex by_d = minor * lambda * problem_.d_reference[i];
        jacobians[0][(2 * k) * columns + i] = by_c.real();
        jacobians[0][(2 * k + 1) * columns + i] = by_c.imag();
        jacobians[0][(2 * k) * columns + n_ + i] = by_d.real();
        jacobians[0][(2 * k + 1) * columns + n_ + i] = by_d.imag();
      }
    }
    return true;
  }

  const CharacteristicProblem& problem_;
  Eigen::VectorXd scale_;
  Eigen::Index n_;
};

void Validate(const CharacteristicProblem& problem) {
  const Eigen::Index n = problem.M.rows();
  auto fail = [](const std::string& field, const std::string& problem_text,
                 const std::string& expected) {
    throw InputError("characteristic equation", field, problem_text, expected);
  };
  if (n == 0 || problem.M.cols() != n || problem.K_g.rows() != n || problem.K_g.cols() != n ||
      problem.H.cols() != n || problem.H.rows() == 0) {
    fail("M, K_g, H", "inconsistent sizes", "M and K_g n x n, H m x n with n, m > 0");
  }
  if (static_cast<Eigen::Index>(problem.coordinates.size()) != n ||
      static_cast<Eigen::Index>(problem.outputs.size()) != problem.H.rows()) {
    fail("coordinates, outputs", "names do not match the matrices", "n coordinates, m outputs");
  }
  if (static_cast<Eigen::Index>(problem.lambda.size()) != n) {
    fail("lambda", std::to_string(problem.lambda.size()) + " poles",
         std::to_string(n) + " poles, one per mode (2n unknowns c, d need n complex equations)");
  }
  for (const Complex& lambda : problem.lambda) {
    if (!(lambda.imag() > 0) || !std::isfinite(lambda.real())) {
      fail("lambda",
           "pole " + FormatValue(lambda.real()) + " + " + FormatValue(lambda.imag()) + "i",
           "finite poles with Im > 0 (one member of each conjugate pair)");
    }
  }
  if (problem.c_reference.size() != n || problem.d_reference.size() != n ||
      !(problem.c_reference.array() > 0).all() || !(problem.d_reference.array() > 0).all() ||
      !problem.c_reference.allFinite() || !problem.d_reference.allFinite()) {
    fail("c_reference, d_reference", "missing or not positive", "n positive finite values each");
  }
}

// Whether two sets agree to `tolerance` relative to the reference values.
bool SameSet(const CharacteristicProblem& problem, const CharacteristicSolution& a,
             const CharacteristicSolution& b, double tolerance) {
  const double dc = ((a.c - b.c).cwiseQuotient(problem.c_reference)).lpNorm<Eigen::Infinity>();
  const double dd = ((a.d - b.d).cwiseQuotient(problem.d_reference)).lpNorm<Eigen::Infinity>();
  const double size = std::max({1.0, a.c.cwiseQuotient(problem.c_reference).cwiseAbs().maxCoeff(),
                                a.d.cwiseQuotient(problem.d_reference).cwiseAbs().maxCoeff()});
  return std::max(dc, dd) <= tolerance * size;
}

}  // namespace

bool CharacteristicOptions::IsValid(std::string* why) const {
  auto fail = [why](const std::string& reason) {
    if (why != nullptr) *why = reason;
    return false;
  };
  if (starts < 1) return fail("starts: " + std::to_string(starts) + "; expected >= 1");
  if (!(start_spread >= 1.0 && std::isfinite(start_spread))) {
    return fail("start_spread: " + FormatValue(start_spread) + "; expected a finite value >= 1");
  }
  if (max_iterations < 1) {
    return fail("max_iterations: " + std::to_string(max_iterations) + "; expected >= 1");
  }
  if (!(residual_tolerance > 0) || !(duplicate_tolerance > 0)) {
    return fail("residual_tolerance and duplicate_tolerance must be > 0");
  }
  if (!(ambiguity_ratio >= 1)) {
    return fail("ambiguity_ratio: " + FormatValue(ambiguity_ratio) + "; expected >= 1");
  }
  if (!(shape_significance > 0 && shape_significance < 1)) {
    return fail("shape_significance: " + FormatValue(shape_significance) + "; expected in (0, 1)");
  }
  return true;
}

std::string CharacteristicResult::status_name() const {
  switch (status) {
    case Status::kSolved:
      return "solved";
    case Status::kNoAdmissibleSet:
      return "no_admissible_set";
    case Status::kNoSolution:
      return "no_solution";
  }
  return "unknown";
}

Eigen::VectorXd CalcCharacteristicResiduals(const CharacteristicProblem& problem,
                                            const Eigen::VectorXd& c, const Eigen::VectorXd& d) {
  Validate(problem);
  const Eigen::VectorXd scale = CalcResidualScales(problem);
  Eigen::VectorXd residuals(static_cast<Eigen::Index>(2 * problem.lambda.size()));
  for (size_t k = 0; k < problem.lambda.size(); ++k) {
    const Complex det = CalcCharacteristicMatrix(problem, problem.lambda[k], c, d).determinant() /
                        scale[static_cast<Eigen::Index>(k)];
    residuals[static_cast<Eigen::Index>(2 * k)] = det.real();
    residuals[static_cast<Eigen::Index>(2 * k + 1)] = det.imag();
  }
  return residuals;
}

std::string FindFreeCoordinate(const model::MechanicalModel& model) {
  const std::vector<model::Parameter> parameters = model.parameters();
  for (const std::string& name : model.coordinate_names()) {
    if (std::none_of(parameters.begin(), parameters.end(),
                     [&](const model::Parameter& p) { return p.name == "c_" + name; })) {
      return name;
    }
  }
  return "";
}

CharacteristicProblem MakeCharacteristicProblem(
    const model::MechanicalModel& model, const std::vector<std::complex<double>>& lambda,
    const std::optional<Measurement>& record,
    const std::optional<simulation::Excitation>& excitation) {
  const model::LinearModel linear = model.Linearize();
  const int n = model.coordinate_count();
  CharacteristicProblem problem;
  problem.M = linear.M;
  problem.H = linear.H;
  problem.output_orders = linear.output_orders;
  problem.coordinates = linear.coordinates;
  problem.coordinate_units = linear.coordinate_units;
  problem.outputs = linear.outputs;
  problem.lambda = lambda;
  problem.record = record;
  problem.c_reference.resize(n);
  problem.d_reference.resize(n);
  problem.K_g = linear.C;
  const std::string free = FindFreeCoordinate(model);
  if (!free.empty()) {
    throw InputError(
        "characteristic equation", "coordinates",
        "coordinate '" + free + "' has no spring, and eq. 7 solves for c and d of every coordinate",
        "a spring on every coordinate for Route 1 (Route 2 tunes the sprung ones)");
  }
  for (int i = 0; i < n; ++i) {
    const std::string& name = linear.coordinates[static_cast<size_t>(i)];
    problem.c_reference[i] = model.GetParameter("c_" + name);
    problem.K_g(i, i) -= problem.c_reference[i];
    const double d = model.GetParameter("d_" + name);
    // An undamped design model still needs a damping scale: 5% of critical.
    problem.d_reference[i] =
        d > 0 ? d : 0.1 * std::sqrt(problem.c_reference[i] * std::abs(linear.M(i, i)));
  }
  if (excitation) {
    // A copy of the model carries each candidate set into the test's start: a free decay's
    // known state at rest, or a forced test's state where the forcing ends.
    std::shared_ptr<model::MechanicalModel> copy = model.Clone();
    const std::vector<std::string> coordinates = linear.coordinates;
    const auto carrying = [copy, coordinates](const Eigen::VectorXd& c,
                                              const Eigen::VectorXd& d) -> model::MechanicalModel& {
      for (size_t i = 0; i < coordinates.size(); ++i) {
        copy->SetParameter("c_" + coordinates[i], c[static_cast<Eigen::Index>(i)]);
        copy->SetParameter("d_" + coordinates[i], d[static_cast<Eigen::Index>(i)]);
      }
      return *copy;
    };
    const simulation::Excitation test = *excitation;
    if (test.CalcForcingEndTime() == 0.0) {
      problem.expected_initial_q = [carrying, test](const Eigen::VectorXd& c,
                                                    const Eigen::VectorXd& d) {
        return simulation::CalcInitialCoordinates(carrying(c, d), test);
      };
    } else {
      problem.expected_free_decay_start = [carrying, test](const Eigen::VectorXd& c,
                                                           const Eigen::VectorXd& d) {
        return simulation::CalcFreeDecayStart(carrying(c, d), test);
      };
    }
  }
  Validate(problem);
  return problem;
}

CharacteristicResult SolveCharacteristicEquation(const CharacteristicProblem& problem,
                                                 const CharacteristicOptions& options) {
  Validate(problem);
  std::string why;
  if (!options.IsValid(&why)) {
    throw InputError("characteristic equation", "options", why, "valid CharacteristicOptions");
  }
  const Eigen::Index n = problem.M.rows();
  CharacteristicResult result;
  result.lambda = problem.lambda;
  result.coordinates = problem.coordinates;
  result.coordinate_units = problem.coordinate_units;
  result.outputs = problem.outputs;
  result.c_reference = problem.c_reference;
  result.d_reference = problem.d_reference;
  result.starts = options.starts;
  result.best_residual = std::numeric_limits<double>::infinity();

  const Eigen::VectorXd scale = CalcResidualScales(problem);
  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::DENSE_QR;
  solver.max_num_iterations = options.max_iterations;
  solver.function_tolerance = 1e-20;
  solver.gradient_tolerance = 1e-24;
  solver.parameter_tolerance = 1e-15;
  solver.logging_type = ceres::SILENT;

  std::mt19937_64 random(options.seed);
  std::uniform_real_distribution<double> log_factor(-std::log(options.start_spread),
                                                    std::log(options.start_spread));
  std::vector<CharacteristicSolution> found;
  for (int start = 0; start < options.starts; ++start) {
    // The first start is the reference itself; the others log-uniform around it.
    Eigen::VectorXd x = Eigen::VectorXd::Ones(2 * n);
    if (start > 0) {
      for (Eigen::Index i = 0; i < 2 * n; ++i) x[i] = std::exp(log_factor(random));
    }
    ceres::Problem ceres_problem;
    ceres_problem.AddResidualBlock(new CharacteristicCost(problem, scale), nullptr, x.data());
    ceres::Solver::Summary summary;
    ceres::Solve(solver, &ceres_problem, &summary);
    ThrowIfStopRequested();
    CharacteristicSolution solution;
    solution.c = problem.c_reference.cwiseProduct(x.head(n));
    solution.d = problem.d_reference.cwiseProduct(x.tail(n));
    solution.residual =
        CalcCharacteristicResiduals(problem, solution.c, solution.d).lpNorm<Eigen::Infinity>();
    if (!std::isfinite(solution.residual)) continue;
    result.best_residual = std::min(result.best_residual, solution.residual);
    if (solution.residual > options.residual_tolerance) continue;
    ++result.converged_starts;
    bool duplicate = false;
    for (CharacteristicSolution& known : found) {
      if (SameSet(problem, known, solution, options.duplicate_tolerance)) {
        ++known.hits;
        if (solution.residual < known.residual) {
          solution.hits = known.hits;
          known = solution;
        }
        duplicate = true;
        break;
      }
    }
    if (!duplicate) {
      solution.hits = 1;
      found.push_back(solution);
    }
  }

  for (CharacteristicSolution& solution : found) {
    solution.reason = InadmissibleReason(problem, solution);
    solution.admissible = solution.reason.empty();
    if (!solution.admissible) continue;
    for (const Complex& lambda : problem.lambda) {
      solution.shapes.push_back(CalcShape(problem, lambda, solution.c, solution.d));
    }
    if (problem.record) {
      FitAmplitudes(problem, options, solution);
      CalcMismatch(problem, solution);
    } else {
      solution.displacement_mismatch = solution.velocity_mismatch = solution.mismatch = kNaN;
    }
  }
  JudgeShapes(problem, options, found);
  const bool by_mismatch = problem.record.has_value();
  std::stable_sort(found.begin(), found.end(),
                   [&](const CharacteristicSolution& a, const CharacteristicSolution& b) {
                     if (a.admissible != b.admissible) return a.admissible;
                     if (!a.admissible) return a.residual < b.residual;
                     if (a.fits_shapes != b.fits_shapes) return a.fits_shapes;
                     if (by_mismatch) return a.mismatch < b.mismatch;
                     return DistanceToReference(problem, a) < DistanceToReference(problem, b);
                   });
  result.solutions = std::move(found);
  const int admissible =
      static_cast<int>(std::count_if(result.solutions.begin(), result.solutions.end(),
                                     [](const CharacteristicSolution& s) { return s.admissible; }));
  std::ostringstream message;
  if (admissible > 0) {
    result.status = CharacteristicResult::Status::kSolved;
    result.chosen = 0;
    int misfits = 0;
    for (int s = 1; s < admissible && by_mismatch; ++s) {
      const CharacteristicSolution& set = result.solutions[static_cast<size_t>(s)];
      if (!set.fits_shapes) {
        ++misfits;
      } else if (set.mismatch < options.ambiguity_ratio * result.solutions[0].mismatch) {
        result.rivals.push_back(s);
      }
    }
    message << result.solutions.size() << " solution set(s) of eq. 7 from " << options.starts
            << " starts, " << admissible << " admissible; chose the one ";
    if (!by_mismatch) {
      message << "nearest the reference values (no record for eq. 8)";
    } else {
      if (misfits > 0) {
        message << "of the " << admissible - misfits
                << " whose mode shapes reproduce the record (eq. 8) ";
      }
      message << "whose initial state agrees best with the test (mismatch "
              << FormatValue(result.solutions[0].mismatch) << ")";
    }
    if (!result.rivals.empty()) {
      result.ambiguous = true;
      message << "; ambiguous: the next set's mismatch is "
              << FormatValue(result.solutions[static_cast<size_t>(result.rivals.front())].mismatch)
              << ", so the record does not single out one set";
    }
  } else if (!result.solutions.empty()) {
    result.status = CharacteristicResult::Status::kNoAdmissibleSet;
    message << "no admissible solution set of eq. 7: " << result.solutions.size()
            << " set(s) found from " << options.starts
            << " starts, each with a negative coefficient (first: " << result.solutions[0].reason
            << ")";
  } else {
    result.status = CharacteristicResult::Status::kNoSolution;
    message << "eq. 7 not solved from any of " << options.starts
            << " starts: smallest scaled residual " << FormatValue(result.best_residual)
            << " above the tolerance " << FormatValue(options.residual_tolerance);
  }
  result.message = message.str();
  return result;
}

}  // namespace mbid::updating
