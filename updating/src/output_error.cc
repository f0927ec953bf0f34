#include "mbid/updating/output_error.h"

#include <ceres/ceres.h>

#include <Eigen/Dense>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "baseline.h"
#include "mbid/common/yaml_reader.h"
#include "mbid/simulation/sensitivity.h"
#include "mbid/simulation/simulate.h"
#include "mbid/updating/credibility.h"
#include "mbid/updating/global_search.h"
#include "statistics.h"

namespace mbid::updating {
namespace {

using simulation::Excitation;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string Format(double value) {
  std::ostringstream out;
  out.precision(4);
  out << value;
  return out.str();
}

// One unknown of the fit: a shared model parameter or a nuisance parameter of one test.
struct Unknown {
  enum class Kind { kModel, kPayloadMass, kDeflection };
  Kind kind = Kind::kModel;
  std::string name;  // model parameter name, or "<test>:payload_mass_kg" ...
  std::string units;
  int test = -1;           // owning test of a nuisance parameter
  std::string coordinate;  // kDeflection
  bool log_scale = true;
  double initial = 0, lower = 0, upper = 0;

  // Ceres' coordinate x and back.
  double ToInternal(double value) const { return log_scale ? std::log(value) : value; }
  double ToValue(double x) const { return log_scale ? std::exp(x) : x; }
};

// A record prepared for the fit: a simulation sampled at the record's own times.
struct PreparedTest {
  const TestRecord* test = nullptr;
  simulation::SimulationOptions simulation;
  simulation::SensorOptions sensors;         // rate, start and channels only
  std::shared_ptr<const Baseline> baseline;  // offsets (and drifts) eliminated, or 0 terms
  Eigen::VectorXd sigma;                     // weights in use, per channel
  std::vector<bool> sigma_given;
  std::vector<int> unknowns;  // indices of the unknowns that act on this test
};

// Counters shared by all cost functions (evaluated from several threads by Ceres).
struct Work {
  std::atomic<long> simulations{0};
  std::atomic<long> sensitivity_simulations{0};
  std::atomic<long> rhs_evaluations{0};
  std::mutex mutex;
  std::string last_error;

  void Count(const simulation::IntegratorStatistics& s) {
    rhs_evaluations +=
        s.rhs_evaluations + s.rhs_evaluations_for_jacobian + s.rhs_evaluations_for_sensitivities;
  }
  void Fail(const std::string& what) {
    std::lock_guard<std::mutex> lock(mutex);
    last_error = what;
  }
};

class TestEvaluator {
 public:
  TestEvaluator(const model::MechanicalModel& model, const std::vector<Unknown>& unknowns,
                const PreparedTest& test, const UpdateOptions& options, Work& work)
      : unknowns_(unknowns), test_(test), options_(options), work_(work) {
    const int groups =
        options.jacobian == UpdateOptions::Jacobian::kSensitivities
            ? std::max(1, std::min<int>(options.threads, static_cast<int>(test.unknowns.size())))
            : std::max(1, options.threads);
    for (int g = 0; g < groups; ++g) models_.push_back(model.Clone());
  }

  int residual_count() const {
    return test_.test->record.samples() * test_.test->record.channel_count();
  }

  // Residuals (and, if `jacobian` is not null, the row-major residuals x unknowns Jacobian in
  // Ceres' coordinates) at x. Two caches: Ceres asks for the Jacobian at a point whose residuals
  // it has just evaluated, and the covariance asks again at the solution after rejected trial
  // points.
  bool Evaluate(const double* x, double* residuals, double* jacobian) {
    const Eigen::Map<const Eigen::VectorXd> point(x, static_cast<Eigen::Index>(unknowns_.size()));
    const bool at_jacobian_point = jacobian_x_.size() == point.size() && jacobian_x_ == point;
    const bool at_residual_point = residual_x_.size() == point.size() && residual_x_ == point;
    try {
      if (jacobian != nullptr && !at_jacobian_point) {
        ComputeWithJacobian(point);
        jacobian_x_ = point;
      } else if (jacobian == nullptr && !at_jacobian_point && !at_residual_point) {
        residuals_ = ComputeResiduals(*models_[0], point);
        residual_x_ = point;
      }
    } catch (const std::exception& e) {
      Invalidate();
      work_.Fail(test_.test->name + ": " + e.what());
      return false;
    }
    const bool from_jacobian = jacobian != nullptr || at_jacobian_point;
    Eigen::Map<Eigen::VectorXd>(residuals, residual_count()) =
        from_jacobian ? jacobian_residuals_ : residuals_;
    if (jacobian != nullptr) {
      Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
          jacobian, residual_count(), static_cast<Eigen::Index>(unknowns_.size())) = jacobian_;
    }
    return true;
  }

  // The simulated record at x (channels x samples of the record) without weights.
  Measurement Simulate(const Eigen::VectorXd& x) {
    model::MechanicalModel& model = *models_[0];
    const Excitation excitation = Configure(model, x);
    const simulation::SimulationResult run =
        simulation::Simulate(model, excitation, test_.simulation, test_.sensors);
    ++work_.simulations;
    work_.Count(run.statistics);
    CheckSamples(run.exact.values);
    Measurement simulated = run.exact;
    simulated.start_time_s = test_.test->record.start_time_s;
    return simulated;
  }

  // d(baseline coefficients)/dx of each channel at the last Jacobian's point `x`: rows
  // terms * c .. terms * (c + 1) - 1 for channel c, one column per unknown; empty elsewhere.
  Eigen::MatrixXd CalcBaselineRegression(const Eigen::VectorXd& x) const {
    const Baseline& baseline = *test_.baseline;
    const int m = test_.test->record.channel_count();
    const int count = static_cast<int>(unknowns_.size());
    if (baseline.terms() == 0 || jacobian_x_.size() != x.size() || jacobian_x_ != x) {
      return Eigen::MatrixXd();
    }
    Eigen::MatrixXd regression(baseline.terms() * m, count);
    for (int c = 0; c < m; ++c) {
      // The Jacobian's rows are dy/dx / sigma_c.
      regression.middleRows(baseline.terms() * c, baseline.terms()) =
          test_.sigma[c] *
          baseline.CalcRegression(unprojected_jacobian_.data() + c, m, residual_count(), count);
    }
    return regression;
  }

  // Forgets the cached evaluation (the weights changed).
  void Invalidate() {
    jacobian_x_.resize(0);
    residual_x_.resize(0);
  }

 private:
  // Sets the shared parameters of `model` from x and returns the test's excitation with its
  // nuisance parameters.
  Excitation Configure(model::MechanicalModel& model, const Eigen::VectorXd& x) const {
    Excitation excitation = test_.test->excitation;
    for (int k : test_.unknowns) {
      const Unknown& unknown = unknowns_[static_cast<size_t>(k)];
      const double value = unknown.ToValue(x[k]);
      switch (unknown.kind) {
        case Unknown::Kind::kModel:
          model.SetParameter(unknown.name, value);
          break;
        case Unknown::Kind::kPayloadMass:
          excitation.get<simulation::LoadDrop>().payload_mass_kg = value;
          break;
        case Unknown::Kind::kDeflection:
          excitation.get<simulation::InitialDeflection>().deflection_rad[unknown.coordinate] =
              value;
          break;
      }
    }
    return excitation;
  }

  void CheckSamples(const Eigen::MatrixXd& simulated) const {
    if (simulated.rows() != test_.test->record.samples()) {
      throw std::logic_error("the simulation has " + std::to_string(simulated.rows()) +
                             " samples, the record " +
                             std::to_string(test_.test->record.samples()));
    }
  }

  // (simulated - measured) / sigma, sample-major: r[j * m + c].
  Eigen::VectorXd Weigh(const Eigen::MatrixXd& simulated) const {
    CheckSamples(simulated);
    const Measurement& record = test_.test->record;
    const int m = record.channel_count();
    Eigen::VectorXd r(residual_count());
    for (int j = 0; j < record.samples(); ++j) {
      for (int c = 0; c < m; ++c) {
        r[j * m + c] = (simulated(j, c) - record.values(j, c)) / test_.sigma[c];
      }
    }
    return r;
  }

  // Each channel's part of `v` (sample-major) orthogonal to its baseline.
  void Project(double* v) const {
    const int m = test_.test->record.channel_count();
    for (int c = 0; c < m; ++c) test_.baseline->Project(v + c, m);
  }

  // Residuals before the baseline's projection.
  Eigen::VectorXd ComputeRawResiduals(model::MechanicalModel& model, const Eigen::VectorXd& x) {
    const Excitation excitation = Configure(model, x);
    const simulation::SimulationResult run =
        simulation::Simulate(model, excitation, test_.simulation, test_.sensors);
    ++work_.simulations;
    work_.Count(run.statistics);
    return Weigh(run.exact.values);
  }

  Eigen::VectorXd ComputeResiduals(model::MechanicalModel& model, const Eigen::VectorXd& x) {
    Eigen::VectorXd r = ComputeRawResiduals(model, x);
    Project(r.data());
    return r;
  }

  void ComputeWithJacobian(const Eigen::VectorXd& x) {
    const int columns = static_cast<int>(unknowns_.size());
    jacobian_ = Eigen::MatrixXd::Zero(residual_count(), columns);
    if (options_.jacobian == UpdateOptions::Jacobian::kNumeric) {
      ComputeNumericJacobian(x);
    } else {
      ComputeSensitivityJacobian(x);
    }
    if (test_.baseline->terms() == 0) return;
    // Variable projection: the basis does not depend on x, so P J is the exact Jacobian of P r.
    unprojected_jacobian_ = jacobian_;
    Project(jacobian_residuals_.data());
    for (int k = 0; k < columns; ++k) Project(jacobian_.col(k).data());
  }

  // Central differences of whole simulations in Ceres' coordinates; the columns run in
  // parallel on the evaluator's model copies.
  void ComputeNumericJacobian(const Eigen::VectorXd& x) {
    const int groups = static_cast<int>(models_.size());
    std::vector<std::string> errors(static_cast<size_t>(groups));
    auto run_group = [&](int g) {
      try {
        if (g == 0) jacobian_residuals_ = ComputeRawResiduals(*models_[0], x);
        for (size_t i = static_cast<size_t>(g); i < test_.unknowns.size();
             i += static_cast<size_t>(groups)) {
          const int k = test_.unknowns[i];
          Eigen::VectorXd step = x;
          step[k] = x[k] + options_.numeric_step;
          const Eigen::VectorXd plus = ComputeRawResiduals(*models_[static_cast<size_t>(g)], step);
          step[k] = x[k] - options_.numeric_step;
          const Eigen::VectorXd minus = ComputeRawResiduals(*models_[static_cast<size_t>(g)], step);
          jacobian_.col(k) = (plus - minus) / (2 * options_.numeric_step);
        }
      } catch (const std::exception& e) {
        errors[static_cast<size_t>(g)] = e.what();
      }
    };
    RunGroups(groups, run_group);
    for (const std::string& error : errors) {
      if (!error.empty()) throw NumericalError("numeric Jacobian", error);
    }
  }

  // CVODES forward sensitivities; the unknowns are split over the model copies, each copy
  // integrating the state with its share of the sensitivities.
  void ComputeSensitivityJacobian(const Eigen::VectorXd& x) {
    const int groups = static_cast<int>(models_.size());
    const Measurement& record = test_.test->record;
    const int m = record.channel_count();
    std::vector<std::string> errors(static_cast<size_t>(groups));
    auto run_group = [&](int g) {
      try {
        model::MechanicalModel& model = *models_[static_cast<size_t>(g)];
        const Excitation excitation = Configure(model, x);
        std::vector<int> columns;
        std::vector<std::string> names;
        std::vector<simulation::InitialStateDirection> directions;
        std::vector<int> direction_columns;
        for (size_t i = static_cast<size_t>(g); i < test_.unknowns.size();
             i += static_cast<size_t>(groups)) {
          const int k = test_.unknowns[i];
          const Unknown& unknown = unknowns_[static_cast<size_t>(k)];
          if (unknown.kind == Unknown::Kind::kModel) {
            columns.push_back(k);
            names.push_back(unknown.name);
          } else {
            direction_columns.push_back(k);
            directions.push_back(MakeDirection(model, excitation, unknown, x[k]));
          }
        }
        columns.insert(columns.end(), direction_columns.begin(), direction_columns.end());
        const simulation::SensitivityResult run = simulation::SimulateWithSensitivities(
            model, excitation, test_.simulation, test_.sensors, names, directions,
            options_.sensitivity);
        ++work_.sensitivity_simulations;
        work_.Count(run.statistics);
        if (g == 0) jacobian_residuals_ = Weigh(run.exact.values);
        CheckSamples(run.exact.values);
        for (size_t i = 0; i < columns.size(); ++i) {
          const int k = columns[i];
          const Unknown& unknown = unknowns_[static_cast<size_t>(k)];
          // d r / d x = (dy/dp) (dp/dx) / sigma; dp/dx = p on the log scale.
          const double dp_dx = unknown.log_scale ? unknown.ToValue(x[k]) : 1.0;
          const Eigen::MatrixXd& dy = run.output_sensitivities[i];
          for (int j = 0; j < record.samples(); ++j) {
            for (int c = 0; c < m; ++c) {
              jacobian_(j * m + c, k) = dy(j, c) * dp_dx / test_.sigma[c];
            }
          }
        }
      } catch (const std::exception& e) {
        errors[static_cast<size_t>(g)] = e.what();
      }
    };
    RunGroups(groups, run_group);
    for (const std::string& error : errors) {
      if (!error.empty()) throw NumericalError("sensitivities", error);
    }
  }

  // dq(0)/dp of a nuisance parameter: e_i for a deflection; central differences of the loaded
  // equilibrium for the payload mass.
  simulation::InitialStateDirection MakeDirection(const model::MechanicalModel& model,
                                                  const Excitation& excitation,
                                                  const Unknown& unknown, double x) const {
    simulation::InitialStateDirection direction;
    direction.name = unknown.name;
    const int n = model.coordinate_count();
    direction.dq0_dp = Eigen::VectorXd::Zero(n);
    const double value = unknown.ToValue(x);
    if (unknown.kind == Unknown::Kind::kDeflection) {
      for (int i = 0; i < n; ++i) {
        if (model.coordinate_names()[static_cast<size_t>(i)] == unknown.coordinate) {
          direction.dq0_dp[i] = 1.0;
        }
      }
      direction.scale = std::max(std::abs(value), 1e-3);
    } else {
      const double h = 1e-4 * value;
      Excitation changed = excitation;
      double& mass = changed.get<simulation::LoadDrop>().payload_mass_kg;
      mass = value + h;
      const Eigen::VectorXd plus = simulation::CalcInitialCoordinates(model, changed);
      mass = value - h;
      const Eigen::VectorXd minus = simulation::CalcInitialCoordinates(model, changed);
      direction.dq0_dp = (plus - minus) / (2 * h);
      direction.scale = value;
    }
    return direction;
  }

  template <typename Function>
  static void RunGroups(int groups, Function& run_group) {
    std::vector<std::thread> threads;
    for (int g = 1; g < groups; ++g) threads.emplace_back(run_group, g);
    run_group(0);
    for (std::thread& thread : threads) thread.join();
  }

  const std::vector<Unknown>& unknowns_;
  const PreparedTest& test_;
  const UpdateOptions& options_;
  Work& work_;
  std::vector<std::unique_ptr<model::MechanicalModel>> models_;  // one per thread
  Eigen::VectorXd jacobian_x_;  // where jacobian_ and jacobian_residuals_ were computed
  Eigen::VectorXd jacobian_residuals_;
  Eigen::MatrixXd jacobian_;
  Eigen::MatrixXd unprojected_jacobian_;  // with a baseline: before the projection
  Eigen::VectorXd residual_x_;            // the last residual-only evaluation
  Eigen::VectorXd residuals_;
};

class TestCost final : public ceres::CostFunction {
 public:
  TestCost(TestEvaluator& evaluator, int unknown_count) : evaluator_(evaluator) {
    set_num_residuals(evaluator.residual_count());
    mutable_parameter_block_sizes()->push_back(unknown_count);
  }
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    return evaluator_.Evaluate(parameters[0], residuals,
                               jacobians != nullptr ? jacobians[0] : nullptr);
  }

 private:
  TestEvaluator& evaluator_;
};

class ProgressCallback final : public ceres::IterationCallback {
 public:
  ProgressCallback(std::vector<IterationRecord>& history, int stage, std::string label, bool quiet)
      : history_(history), stage_(stage), label_(std::move(label)), quiet_(quiet) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& summary) override {
    IterationRecord record;
    record.iteration = summary.iteration;
    record.cost = summary.cost;
    record.step_norm = summary.step_norm;
    record.gradient_max_norm = summary.gradient_max_norm;
    record.trust_region_radius = summary.trust_region_radius;
    record.successful = summary.step_is_successful;
    record.cumulative_time_s = summary.cumulative_time_in_seconds;
    record.stage = stage_;
    history_.push_back(record);
    if (!quiet_) {
      std::fprintf(stderr, "mbid: Route 2 (%s) iteration %3d  cost %.6e  step %.3e%s\n",
                   label_.c_str(), summary.iteration, summary.cost, summary.step_norm,
                   summary.iteration > 0 && !summary.step_is_successful ? " (rejected)" : "");
    }
    return ceres::SOLVER_CONTINUE;
  }

 private:
  std::vector<IterationRecord>& history_;
  int stage_;
  std::string label_;
  bool quiet_;
};

std::vector<Unknown> ResolveUnknowns(const model::MechanicalModel& model,
                                     const std::vector<TestRecord>& tests,
                                     const UpdateOptions& options) {
  const std::vector<model::Parameter> available = model.parameters();
  std::vector<ParameterSetting> settings = options.parameters;
  if (settings.empty()) {
    for (const model::Parameter& parameter : available) settings.push_back({parameter.name});
  }
  std::vector<std::string> names;
  for (const model::Parameter& parameter : available) names.push_back(parameter.name);
  std::vector<Unknown> unknowns;
  for (const ParameterSetting& setting : settings) {
    const auto found = std::find_if(
        available.begin(), available.end(),
        [&](const model::Parameter& parameter) { return parameter.name == setting.name; });
    if (found == available.end()) {
      throw InputError(
          "updating", "parameters", "unknown parameter '" + setting.name + "'",
          "a parameter of the model; did you mean '" + ClosestMatch(setting.name, names) + "'?");
    }
    for (const Unknown& known : unknowns) {
      if (known.name == setting.name) {
        throw InputError("updating", "parameters", "'" + setting.name + "' listed twice",
                         "each parameter once");
      }
    }
    Unknown unknown;
    unknown.name = setting.name;
    unknown.units = found->units;
    unknown.log_scale = setting.log_scale;
    unknown.initial = std::isnan(setting.initial) ? found->value : setting.initial;
    unknown.lower =
        std::isnan(setting.lower) ? std::max(unknown.initial / 100, found->lower) : setting.lower;
    unknown.upper =
        std::isnan(setting.upper) ? std::min(unknown.initial * 100, found->upper) : setting.upper;
    unknowns.push_back(unknown);
  }
  for (size_t t = 0; t < tests.size(); ++t) {
    const TestRecord& test = tests[t];
    if (test.fit_payload_mass) {
      const auto* drop = test.excitation.get_if<simulation::LoadDrop>();
      if (drop == nullptr) {
        throw InputError(test.name, "fit_payload_mass", "the test is not a load drop",
                         "payload mass as a nuisance parameter of load-drop tests only");
      }
      Unknown unknown;
      unknown.kind = Unknown::Kind::kPayloadMass;
      unknown.name = test.name + ":payload_mass_kg";
      unknown.units = "kg";
      unknown.test = static_cast<int>(t);
      unknown.initial = drop->payload_mass_kg;
      unknown.lower = unknown.initial / 100;
      unknown.upper = unknown.initial * 100;
      unknowns.push_back(unknown);
    }
    if (test.fit_initial_deflection) {
      const auto* deflection = test.excitation.get_if<simulation::InitialDeflection>();
      if (deflection == nullptr) {
        throw InputError(test.name, "fit_initial_deflection",
                         "the test is not an initial deflection",
                         "initial deflections as nuisance parameters of initial_deflection "
                         "tests only");
      }
      for (const auto& [coordinate, value] : deflection->deflection_rad) {
        Unknown unknown;
        unknown.kind = Unknown::Kind::kDeflection;
        unknown.name = test.name + ":deflection_" + coordinate;
        unknown.units = "rad";
        unknown.test = static_cast<int>(t);
        unknown.coordinate = coordinate;
        unknown.log_scale = false;
        unknown.initial = value;
        const double span = std::max(10 * std::abs(value), 0.01);
        unknown.lower = value - span;
        unknown.upper = value + span;
        unknowns.push_back(unknown);
      }
    }
  }
  for (const Unknown& unknown : unknowns) {
    const bool positive = !unknown.log_scale || (unknown.lower > 0 && unknown.initial > 0);
    if (!(unknown.lower <= unknown.initial && unknown.initial <= unknown.upper) ||
        !(unknown.lower < unknown.upper) || !positive || !std::isfinite(unknown.lower) ||
        !std::isfinite(unknown.upper)) {
      throw InputError("updating", unknown.name,
                       "start " + Format(unknown.initial) + " with bounds [" +
                           Format(unknown.lower) + ", " + Format(unknown.upper) + "]",
                       std::string("finite bounds lower < upper around the start") +
                           (unknown.log_scale ? ", all > 0 (log scale)" : ""));
    }
  }
  return unknowns;
}

PreparedTest PrepareTest(const model::MechanicalModel& model, const TestRecord& test, int index,
                         const std::vector<Unknown>& unknowns, const UpdateOptions& options) {
  const Measurement& record = test.record;
  record.Validate(test.name);
  PreparedTest prepared;
  prepared.test = &test;
  const double tau = record.sample_interval_s;
  if (!(record.start_time_s >= 0)) {
    throw InputError(test.name, "start time", Format(record.start_time_s) + " s",
                     "a record starting at or after the excitation's t = 0 (the release)");
  }
  std::vector<std::string> known = model.output_names();
  known.insert(known.end(), model.coordinate_names().begin(), model.coordinate_names().end());
  for (const std::string& channel : record.channels) {
    if (std::find(known.begin(), known.end(), channel) == known.end()) {
      throw InputError(test.name, channel, "channel not produced by the model",
                       "outputs or coordinates of the model");
    }
  }
  // The simulation samples at the record's times. A start on the whole-sample grid k tau is
  // sampled as (k + j) tau, bit for bit the rows of a simulation from t = 0 (the duration
  // computed the same way keeps the count); other starts at t0 + j tau.
  const double grid_index = std::round(record.start_time_s / tau);
  const bool whole =
      std::abs(record.start_time_s / tau - grid_index) <= simulation::kWholeSampleTolerance;
  prepared.simulation.duration_s = whole ? (grid_index + record.samples() - 1) * tau
                                         : record.start_time_s + (record.samples() - 1) * tau;
  prepared.simulation.integrator = options.integrator;
  prepared.sensors.sample_rate_hz = 1.0 / tau;
  prepared.sensors.start_time_s = record.start_time_s;
  prepared.sensors.channels = record.channels;
  if (test.fit_drift && !test.fit_offsets) {
    throw InputError(test.name, "fit_drift", "a drift without an offset",
                     "fit_offsets together with fit_drift");
  }
  const int terms = test.fit_offsets ? (test.fit_drift ? 2 : 1) : 0;
  if (record.samples() <= terms) {
    throw InputError(test.name, "samples", std::to_string(record.samples()) + " samples",
                     "more samples than baseline terms per channel");
  }
  prepared.baseline = std::make_shared<const Baseline>(record.CalcTime(), terms);
  const int m = record.channel_count();
  for (const auto& [channel, value] : test.noise_std) {
    if (record.FindChannel(channel) < 0) {
      throw InputError(test.name, "noise_std." + channel, "no such channel in the record",
                       "noise levels of the record's channels");
    }
  }
  prepared.sigma.resize(m);
  prepared.sigma_given.assign(static_cast<size_t>(m), false);
  for (int c = 0; c < m; ++c) {
    const auto given = test.noise_std.find(record.channels[static_cast<size_t>(c)]);
    if (given != test.noise_std.end()) {
      if (!(given->second > 0) || !std::isfinite(given->second)) {
        throw InputError(test.name, "noise_std." + given->first, Format(given->second),
                         "a positive noise standard deviation");
      }
      prepared.sigma[c] = given->second;
      prepared.sigma_given[static_cast<size_t>(c)] = true;
    } else {
      // Provisional weight until the residual tells the noise: 1% of the channel's spread.
      const Eigen::VectorXd column = record.values.col(c);
      const double spread = std::sqrt((column.array() - column.mean()).square().mean());
      prepared.sigma[c] = std::max(1e-2 * spread, 1e-300);
    }
  }
  for (size_t k = 0; k < unknowns.size(); ++k) {
    if (unknowns[k].test < 0 || unknowns[k].test == index) {
      prepared.unknowns.push_back(static_cast<int>(k));
    }
  }
  return prepared;
}

// The baseline of `test` fitted to the difference of record and `fit.simulated` (the model's
// re-simulation), added to it, with standard deviations from the block inverse of the full
// problem: Cov(a) = sigma^2 (B^T B)^-1 + G Cov(x) G^T, G = da/dx (`regression`).
void AddBaseline(const PreparedTest& test, const Eigen::MatrixXd& regression,
                 const Eigen::MatrixXd& covariance, TestFit& fit) {
  const Baseline& baseline = *test.baseline;
  const Measurement& record = test.test->record;
  const int m = record.channel_count();
  const int terms = baseline.terms();
  fit.offset = fit.offset_std = Eigen::VectorXd::Constant(m, kNaN);
  if (terms == 2) fit.drift = fit.drift_std = Eigen::VectorXd::Constant(m, kNaN);
  const Eigen::MatrixXd inverse_gram = baseline.CalcInverseGram();
  for (int c = 0; c < m; ++c) {
    const Eigen::VectorXd difference = record.values.col(c) - fit.simulated.values.col(c);
    const Eigen::VectorXd a = baseline.Fit(difference.data(), 1);
    fit.simulated.values.col(c) += baseline.Evaluate(a);
    Eigen::MatrixXd cov = test.sigma[c] * test.sigma[c] * inverse_gram;
    if (regression.rows() == terms * m) {
      // Only the unknowns acting on this test move its baseline (0 * NaN would spoil it).
      const int acting = static_cast<int>(test.unknowns.size());
      Eigen::MatrixXd g(terms, acting), sub(acting, acting);
      for (int i = 0; i < acting; ++i) {
        g.col(i) = regression.block(terms * c, test.unknowns[static_cast<size_t>(i)], terms, 1);
        for (int j = 0; j < acting; ++j) {
          sub(i, j) = covariance(test.unknowns[static_cast<size_t>(i)],
                                 test.unknowns[static_cast<size_t>(j)]);
        }
      }
      cov += g * sub * g.transpose();
    } else {
      cov.setConstant(kNaN);
    }
    fit.offset[c] = a[0];
    fit.offset_std[c] = cov(0, 0) >= 0 ? std::sqrt(cov(0, 0)) : kNaN;
    if (terms == 2) {
      fit.drift[c] = a[1];
      fit.drift_std[c] = cov(1, 1) >= 0 ? std::sqrt(cov(1, 1)) : kNaN;
    }
  }
}

UpdateResult::Termination ToTermination(ceres::TerminationType type) {
  switch (type) {
    case ceres::CONVERGENCE:
      return UpdateResult::Termination::kConverged;
    case ceres::NO_CONVERGENCE:
      return UpdateResult::Termination::kNoConvergence;
    default:
      return UpdateResult::Termination::kFailure;
  }
}

}  // namespace

bool UpdateOptions::IsValid(std::string* why) const {
  auto fail = [why](const std::string& reason) {
    if (why != nullptr) *why = reason;
    return false;
  };
  std::string inner;
  if (!integrator.IsValid(&inner)) return fail("integrator: " + inner);
  if (!sensitivity.IsValid(&inner)) return fail("sensitivity: " + inner);
  if (!(numeric_step > 0 && numeric_step < 1)) {
    return fail("numeric_step: " + Format(numeric_step) + "; expected a value in (0, 1)");
  }
  if (max_iterations < 1) {
    return fail("max_iterations: " + std::to_string(max_iterations) + "; expected >= 1");
  }
  if (!(function_tolerance > 0) || !(gradient_tolerance > 0) || !(parameter_tolerance > 0)) {
    return fail("function, gradient and parameter tolerances must be > 0");
  }
  if (!(undetermined_relative_std > 0)) {
    return fail("undetermined_relative_std: " + Format(undetermined_relative_std) +
                "; expected > 0");
  }
  if (!(max_chi_square_per_dof > 1)) {
    return fail("max_chi_square_per_dof must be > 1 (1 is a fit at the noise)");
  }
  if (whiteness_lags < 1) return fail("whiteness_lags must be >= 1");
  if (!(rank_tolerance > 0 && rank_tolerance < 1)) {
    return fail("rank_tolerance: " + Format(rank_tolerance) + "; expected a value in (0, 1)");
  }
  if (threads < 1) return fail("threads: " + std::to_string(threads) + "; expected >= 1");
  if (!(initial_trust_region_radius > 0) || !std::isfinite(initial_trust_region_radius)) {
    return fail("initial_trust_region_radius: " + Format(initial_trust_region_radius) +
                "; expected a finite value > 0");
  }
  double previous = 0;
  for (double fraction : continuation_fractions) {
    if (!(fraction > previous && fraction < 1)) {
      return fail("continuation_fractions: " + Format(fraction) +
                  "; expected ascending fractions in (0, 1)");
    }
    previous = fraction;
  }
  return true;
}

std::string UpdateResult::termination_name() const {
  switch (termination) {
    case Termination::kConverged:
      return "converged";
    case Termination::kNoConvergence:
      return "no_convergence";
    case Termination::kFailure:
      return "failure";
  }
  return "failure";
}

ExitCode UpdateResult::exit_code() const {
  return termination == Termination::kConverged ? ExitCode::kSuccess : ExitCode::kNumericalFailure;
}

const ParameterEstimate& UpdateResult::Find(const std::string& name) const {
  for (const ParameterEstimate& estimate : parameters) {
    if (estimate.name == name) return estimate;
  }
  throw std::out_of_range("UpdateResult::Find: no parameter '" + name + "'");
}

void ApplyEstimates(const UpdateResult& result, model::MechanicalModel& model) {
  for (const ParameterEstimate& estimate : result.parameters) {
    if (estimate.test.empty()) model.SetParameter(estimate.name, estimate.value);
  }
}

namespace {

// One fit of the whole problem (one continuation stage; with estimated noise two passes). The
// initial cost is reported at `report_start` (values of the unknowns) if given, else at the
// options' starts.
UpdateResult Fit(const model::MechanicalModel& model, const std::vector<TestRecord>& tests,
                 const UpdateOptions& options, int first_stage, const std::string& stage_label,
                 const std::vector<double>* report_start) {
  const auto start_time = std::chrono::steady_clock::now();
  const std::vector<Unknown> unknowns = ResolveUnknowns(model, tests, options);
  const int count = static_cast<int>(unknowns.size());
  std::vector<PreparedTest> prepared;
  for (size_t t = 0; t < tests.size(); ++t) {
    prepared.push_back(PrepareTest(model, tests[t], static_cast<int>(t), unknowns, options));
  }
  Work work;
  std::vector<std::unique_ptr<TestEvaluator>> evaluators;
  for (const PreparedTest& test : prepared) {
    evaluators.push_back(std::make_unique<TestEvaluator>(model, unknowns, test, options, work));
  }

  Eigen::VectorXd x(count), x_initial(count);
  for (int k = 0; k < count; ++k)
    x[k] = unknowns[static_cast<size_t>(k)].ToInternal(unknowns[static_cast<size_t>(k)].initial);
  x_initial = x;

  ceres::Problem::Options problem_options;
  problem_options.cost_function_ownership = ceres::TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  for (auto& evaluator : evaluators) {
    problem.AddResidualBlock(new TestCost(*evaluator, count), nullptr, x.data());
  }
  for (int k = 0; k < count; ++k) {
    const Unknown& unknown = unknowns[static_cast<size_t>(k)];
    problem.SetParameterLowerBound(x.data(), k, unknown.ToInternal(unknown.lower));
    problem.SetParameterUpperBound(x.data(), k, unknown.ToInternal(unknown.upper));
  }

  UpdateResult result;
  result.jacobian =
      options.jacobian == UpdateOptions::Jacobian::kSensitivities ? "sensitivities" : "numeric";
  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::DENSE_QR;
  solver.max_num_iterations = options.max_iterations;
  solver.function_tolerance = options.function_tolerance;
  solver.gradient_tolerance = options.gradient_tolerance;
  solver.parameter_tolerance = options.parameter_tolerance;
  solver.num_threads = std::min<int>(options.threads, static_cast<int>(tests.size()));
  solver.logging_type = ceres::SILENT;
  solver.minimizer_progress_to_stdout = false;
  // No projected line search at the bounds: it asks for the gradient (a sensitivity run) at
  // every trial point. Steps are projected onto the box instead.
  solver.max_num_line_search_step_size_iterations = 0;
  solver.initial_trust_region_radius = options.initial_trust_region_radius;

  bool any_estimated = false;
  for (const PreparedTest& test : prepared) {
    for (bool given : test.sigma_given) any_estimated = any_estimated || !given;
  }
  const int passes = any_estimated && options.refit_after_noise_estimate ? 2 : 1;
  ceres::Solver::Summary summary;
  double first_initial_cost = kNaN;
  std::vector<IterationRecord> all_history;
  for (int pass = 1; pass <= passes; ++pass) {
    std::vector<IterationRecord> history;
    ProgressCallback progress(history, first_stage + pass - 1,
                              stage_label + (pass > 1 ? " refit" : " fit"), options.quiet);
    solver.callbacks = {&progress};
    ceres::Solve(solver, &problem, &summary);
    if (pass == 1) first_initial_cost = summary.initial_cost;
    result.iterations += summary.num_successful_steps + summary.num_unsuccessful_steps;
    all_history.insert(all_history.end(), history.begin(), history.end());
    if (!any_estimated || summary.termination_type == ceres::FAILURE ||
        summary.termination_type == ceres::USER_FAILURE) {
      break;
    }
    // Noise from the residual at this fit: sigma_c^2 = SS_c / (N_c - B - P N_c / N), the
    // parameters' degrees of freedom shared out by sample count, B the channel's baseline terms.
    long total = 0;
    for (const PreparedTest& test : prepared)
      total += test.test->record.samples() * test.test->record.channel_count();
    for (size_t t = 0; t < prepared.size(); ++t) {
      PreparedTest& test = prepared[t];
      const Measurement simulated = evaluators[t]->Simulate(x);
      const Measurement& record = test.test->record;
      for (int c = 0; c < record.channel_count(); ++c) {
        if (test.sigma_given[static_cast<size_t>(c)]) continue;
        Eigen::VectorXd difference = simulated.values.col(c) - record.values.col(c);
        test.baseline->Project(difference.data(), 1);
        const double squares = difference.squaredNorm();
        const double samples = record.samples();
        const double dof = std::max(
            1.0, samples - test.baseline->terms() - count * samples / static_cast<double>(total));
        test.sigma[c] = std::max(std::sqrt(squares / dof), 1e-300);
      }
    }
    // New weights: the cached residuals no longer apply.
    for (auto& evaluator : evaluators) evaluator->Invalidate();
  }
  result.history = all_history;
  result.termination = ToTermination(summary.termination_type);
  result.message = summary.message;
  {
    std::lock_guard<std::mutex> lock(work.mutex);
    if (!work.last_error.empty() && result.termination != UpdateResult::Termination::kConverged) {
      result.message += "; last simulation failure: " + work.last_error;
    }
  }
  result.final_cost = summary.final_cost;
  result.initial_cost = first_initial_cost;

  // Jacobian at the estimate (cached by the evaluators) for the covariance and the rank.
  std::vector<double> residuals;
  ceres::CRSMatrix crs;
  ceres::Problem::EvaluateOptions evaluate;
  const bool have_jacobian = problem.Evaluate(evaluate, nullptr, &residuals, nullptr, &crs);
  // How each test's baseline moves with the unknowns, from the Jacobians just evaluated at x.
  std::vector<Eigen::MatrixXd> regressions;
  for (auto& evaluator : evaluators) regressions.push_back(evaluator->CalcBaselineRegression(x));
  Eigen::MatrixXd covariance = Eigen::MatrixXd::Constant(count, count, kNaN);
  if (have_jacobian) {
    Eigen::MatrixXd J = Eigen::MatrixXd::Zero(crs.num_rows, crs.num_cols);
    for (int r = 0; r < crs.num_rows; ++r) {
      for (int i = crs.rows[static_cast<size_t>(r)]; i < crs.rows[static_cast<size_t>(r) + 1];
           ++i) {
        J(r, crs.cols[static_cast<size_t>(i)]) = crs.values[static_cast<size_t>(i)];
      }
    }
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(J, Eigen::ComputeThinV);
    result.singular_values = svd.singularValues();
    const double largest = result.singular_values.size() > 0 ? result.singular_values[0] : 0.0;
    result.rank = 0;
    std::vector<bool> in_null_space(static_cast<size_t>(count), false);
    for (int i = 0; i < result.singular_values.size(); ++i) {
      if (result.singular_values[i] > options.rank_tolerance * largest) {
        ++result.rank;
        continue;
      }
      for (int k = 0; k < count; ++k) {
        if (std::abs(svd.matrixV()(k, i)) > 0.1) in_null_space[static_cast<size_t>(k)] = true;
      }
    }
    ceres::Covariance::Options covariance_options;
    covariance_options.algorithm_type = ceres::DENSE_SVD;
    // A rank-deficient Jacobian: the pseudo-inverse without the null space, whose parameters
    // are marked undefined below, gives the others their std (with the null space fixed).
    covariance_options.null_space_rank = count - result.rank;
    ceres::Covariance ceres_covariance(covariance_options);
    const std::vector<std::pair<const double*, const double*>> blocks{{x.data(), x.data()}};
    if (ceres_covariance.Compute(blocks, &problem)) {
      ceres_covariance.GetCovarianceBlock(x.data(), x.data(), covariance.data());
      covariance = covariance.transpose().eval();  // Ceres fills row-major
    }
    for (int k = 0; k < count; ++k) {
      if (in_null_space[static_cast<size_t>(k)]) covariance.row(k).setConstant(kNaN);
    }
  } else {
    result.warnings.push_back("no Jacobian at the estimate: " + work.last_error);
  }
  result.covariance = covariance;
  result.correlation = Eigen::MatrixXd::Constant(count, count, kNaN);
  for (int i = 0; i < count; ++i) {
    for (int j = 0; j < count; ++j) {
      const double denominator = std::sqrt(covariance(i, i) * covariance(j, j));
      if (denominator > 0 && std::isfinite(denominator)) {
        result.correlation(i, j) = covariance(i, j) / denominator;
      }
    }
  }

  for (int k = 0; k < count; ++k) {
    const Unknown& unknown = unknowns[static_cast<size_t>(k)];
    ParameterEstimate estimate;
    estimate.name = unknown.name;
    estimate.units = unknown.units;
    estimate.test = unknown.test >= 0 ? tests[static_cast<size_t>(unknown.test)].name : "";
    estimate.log_scale = unknown.log_scale;
    estimate.value = unknown.ToValue(x[k]);
    estimate.initial = unknown.initial;
    estimate.lower = unknown.lower;
    estimate.upper = unknown.upper;
    const double variance = covariance(k, k);
    if (variance >= 0 && std::isfinite(variance)) {
      const double std_internal = std::sqrt(variance);
      estimate.std = unknown.log_scale ? estimate.value * std_internal : std_internal;
      estimate.relative_std = unknown.log_scale
                                  ? std_internal
                                  : std_internal / std::max(std::abs(estimate.value), 1e-6);
    }
    estimate.determined = estimate.relative_std <= options.undetermined_relative_std;
    const double x_lower = unknown.ToInternal(unknown.lower);
    const double x_upper = unknown.ToInternal(unknown.upper);
    const double margin = 1e-6 * std::max(1.0, std::abs(x[k]));
    estimate.at_bound = x[k] - x_lower <= margin || x_upper - x[k] <= margin;
    if (!estimate.determined) result.undetermined.push_back(estimate.name);
    if (estimate.at_bound) {
      result.warnings.push_back(estimate.name + " ends at a bound (" + Format(estimate.value) +
                                " " + estimate.units + ")");
    }
    result.parameters.push_back(estimate);
  }
  if (!result.undetermined.empty()) {
    std::string list;
    for (const std::string& name : result.undetermined) list += (list.empty() ? "" : ", ") + name;
    result.warnings.push_back("the records leave undetermined: " + list + " (rank " +
                              std::to_string(result.rank) + " of " + std::to_string(count) + ")");
  }
  for (int i = 0; i < count; ++i) {
    for (int j = i + 1; j < count; ++j) {
      if (std::abs(result.correlation(i, j)) > 0.99) {
        result.warnings.push_back(unknowns[static_cast<size_t>(i)].name + " and " +
                                  unknowns[static_cast<size_t>(j)].name + " are correlated " +
                                  Format(result.correlation(i, j)));
      }
    }
  }

  // The tuned model re-simulated against each record.
  for (size_t t = 0; t < prepared.size(); ++t) {
    const PreparedTest& test = prepared[t];
    const Measurement& record = test.test->record;
    TestFit fit;
    fit.name = test.test->name;
    fit.channels = record.channels;
    fit.noise_std = test.sigma;
    for (bool given : test.sigma_given) fit.noise_estimated.push_back(!given);
    try {
      fit.simulated = evaluators[t]->Simulate(x);
      if (test.baseline->terms() > 0) AddBaseline(test, regressions[t], covariance, fit);
      fit.residual_rms.resize(record.channel_count());
      fit.correlation.resize(record.channel_count());
      for (int c = 0; c < record.channel_count(); ++c) {
        const Eigen::VectorXd difference = fit.simulated.values.col(c) - record.values.col(c);
        fit.residual_rms[c] = std::sqrt(difference.squaredNorm() / record.samples());
        fit.correlation[c] = CalcPearson(record.values.col(c), fit.simulated.values.col(c));
      }
    } catch (const std::exception& e) {
      result.warnings.push_back(fit.name + ": re-simulation failed: " + e.what());
    }
    result.tests.push_back(fit);
  }
  if (passes > 1 || report_start != nullptr) {
    // The initial cost in the final weights (the noise estimate changed them after pass 1), at
    // the first stage's start. Copies keep the buffer Ceres points to.
    const Eigen::VectorXd estimate = x;
    x = x_initial;
    if (report_start != nullptr) {
      for (int k = 0; k < count; ++k) {
        x[k] = unknowns[static_cast<size_t>(k)].ToInternal((*report_start)[static_cast<size_t>(k)]);
      }
    }
    double cost = 0;
    result.initial_cost =
        problem.Evaluate(ceres::Problem::EvaluateOptions(), &cost, nullptr, nullptr, nullptr)
            ? cost
            : kNaN;
    x = estimate;
  }
  result.simulations = work.simulations;
  result.sensitivity_simulations = work.sensitivity_simulations;
  result.rhs_evaluations = work.rhs_evaluations;
  result.wall_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_time).count();
  return result;
}

// UpdateModel before its credibility check.
UpdateResult FitStages(const model::MechanicalModel& model, const std::vector<TestRecord>& tests,
                       const UpdateOptions& options) {
  const auto start_time = std::chrono::steady_clock::now();
  std::string why;
  if (!options.IsValid(&why)) {
    throw InputError("updating", "options", why, "valid updating options (docs/scenarios.md)");
  }
  if (tests.empty()) {
    throw InputError("updating", "records", "no test record", "at least one record");
  }
  if (options.continuation_fractions.empty()) {
    return Fit(model, tests, options, 1, "update", nullptr);
  }
  // Continuation: the starts and bounds made explicit once, so that every stage keeps the
  // original bounds while its start moves.
  const std::vector<Unknown> unknowns = ResolveUnknowns(model, tests, options);
  std::vector<double> original_start;
  for (const Unknown& unknown : unknowns) original_start.push_back(unknown.initial);
  UpdateOptions staged = options;
  staged.continuation_fractions.clear();
  staged.parameters.clear();
  for (const Unknown& unknown : unknowns) {
    if (unknown.kind != Unknown::Kind::kModel) continue;
    staged.parameters.push_back(
        {unknown.name, unknown.initial, unknown.lower, unknown.upper, unknown.log_scale});
  }
  std::vector<TestRecord> current = tests;
  std::vector<IterationRecord> history;
  int iterations = 0;
  long simulations = 0, sensitivity_simulations = 0, rhs_evaluations = 0;
  int stage = 1;
  for (double fraction : options.continuation_fractions) {
    std::vector<TestRecord> window = current;
    for (TestRecord& test : window) {
      const int samples = std::max(test.fit_drift ? 3 : 2,
                                   static_cast<int>(std::ceil(fraction * test.record.samples())));
      test.record.values = test.record.values.topRows(samples).eval();
    }
    std::ostringstream label;
    label << "window " << std::lround(100 * fraction) << "%";
    const UpdateResult part = Fit(model, window, staged, stage, label.str(), nullptr);
    history.insert(history.end(), part.history.begin(), part.history.end());
    iterations += part.iterations;
    simulations += part.simulations;
    sensitivity_simulations += part.sensitivity_simulations;
    rhs_evaluations += part.rhs_evaluations;
    stage = (part.history.empty() ? stage : part.history.back().stage) + 1;
    if (part.termination == UpdateResult::Termination::kFailure) continue;
    for (ParameterSetting& setting : staged.parameters) {
      setting.initial = std::clamp(part.Find(setting.name).value, setting.lower, setting.upper);
    }
    for (const ParameterEstimate& estimate : part.parameters) {
      if (estimate.test.empty()) continue;
      for (TestRecord& test : current) {
        if (test.name != estimate.test) continue;
        const std::string prefix = test.name + ":deflection_";
        if (estimate.name == test.name + ":payload_mass_kg") {
          test.excitation.get<simulation::LoadDrop>().payload_mass_kg = estimate.value;
        } else if (estimate.name.compare(0, prefix.size(), prefix) == 0) {
          test.excitation.get<simulation::InitialDeflection>()
              .deflection_rad[estimate.name.substr(prefix.size())] = estimate.value;
        }
      }
    }
  }
  UpdateResult result = Fit(model, current, staged, stage, "update", &original_start);
  history.insert(history.end(), result.history.begin(), result.history.end());
  result.history = history;
  result.iterations += iterations;
  result.simulations += simulations;
  result.sensitivity_simulations += sensitivity_simulations;
  result.rhs_evaluations += rhs_evaluations;
  for (size_t k = 0; k < result.parameters.size(); ++k) {
    result.parameters[k].initial = original_start[k];
  }
  result.wall_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_time).count();
  return result;
}

}  // namespace

UpdateResult UpdateModel(const model::MechanicalModel& model, const std::vector<TestRecord>& tests,
                         const UpdateOptions& options) {
  UpdateResult result = FitStages(model, tests, options);
  AssessCredibility(result, tests, options);
  return result;
}

std::vector<ParameterSetting> ResolveParameterSettings(const model::MechanicalModel& model,
                                                       const UpdateOptions& options) {
  std::vector<ParameterSetting> settings;
  for (const Unknown& unknown : ResolveUnknowns(model, {}, options)) {
    settings.push_back(
        {unknown.name, unknown.initial, unknown.lower, unknown.upper, unknown.log_scale});
  }
  return settings;
}

}  // namespace mbid::updating
