#include "mbid/updating/fisher.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "baseline.h"
#include "format_value.h"
#include "mbid/common/eigen_decompositions.h"
#include "mbid/common/error.h"
#include "mbid/common/yaml_reader.h"
#include "mbid/simulation/sensitivity.h"

namespace mbid::updating {

TestDesign MakeRecordedDesign(const TestRecord& test, const Eigen::VectorXd& noise_std,
                              const simulation::IntegratorOptions& integrator) {
  const Measurement& record = test.record;
  if (noise_std.size() != record.channel_count()) {
    throw InputError(test.name, "noise_std",
                     std::to_string(noise_std.size()) + " noise levels for " +
                         std::to_string(record.channel_count()) + " channels",
                     "one noise level per channel of the record");
  }
  TestDesign design;
  design.name = test.name;
  design.excitation = test.excitation;
  design.fit_offsets = test.fit_offsets;
  design.fit_drift = test.fit_drift;
  // The record's times, as UpdateModel samples them: a start on the whole-sample grid k tau
  // as (k + j) tau, other starts at start + j tau.
  const double tau = record.sample_interval_s;
  const double grid_index = std::round(record.start_time_s / tau);
  const bool whole =
      std::abs(record.start_time_s / tau - grid_index) <= simulation::kWholeSampleTolerance;
  design.simulation.duration_s = whole ? (grid_index + record.samples() - 1) * tau
                                       : record.start_time_s + (record.samples() - 1) * tau;
  design.simulation.integrator = integrator;
  design.sensors.sample_rate_hz = 1.0 / tau;
  design.sensors.start_time_s = record.start_time_s;
  design.sensors.channels = record.channels;
  for (int c = 0; c < record.channel_count(); ++c) {
    design.sensors.noise_std[record.channels[static_cast<size_t>(c)]] = noise_std[c];
  }
  return design;
}

FisherInformation CalcFisherInformation(const model::MechanicalModel& model, const TestDesign& test,
                                        const std::vector<std::string>& parameters,
                                        const simulation::SensitivityOptions& sensitivity) {
  const std::vector<std::string>& channels = test.sensors.channels;
  const int m = static_cast<int>(channels.size());
  Eigen::VectorXd sigma(m);
  for (int c = 0; c < m; ++c) {
    const auto found = test.sensors.noise_std.find(channels[static_cast<size_t>(c)]);
    const double value = found == test.sensors.noise_std.end() ? 0.0 : found->second;
    if (!(value > 0) || !std::isfinite(value)) {
      throw InputError(
          test.name, "noise_std." + channels[static_cast<size_t>(c)],
          found == test.sensors.noise_std.end() ? "no noise level" : internal::FormatValue(value),
          "a positive noise standard deviation per channel (the weights)");
    }
    sigma[c] = value;
  }
  std::vector<double> values;
  for (const std::string& name : parameters) {
    const double value = model.GetParameter(name);  // InputError for an unknown name
    if (!(value > 0)) {
      throw InputError(test.name, name, internal::FormatValue(value),
                       "a positive parameter value (information in log coordinates)");
    }
    values.push_back(value);
  }
  if (test.fit_drift && !test.fit_offsets) {
    throw InputError(test.name, "fit_drift", "a drift without an offset",
                     "fit_offsets together with fit_drift");
  }
  // The sensitivity run samples without sensor effects.
  simulation::SensorOptions sampling;
  sampling.sample_rate_hz = test.sensors.sample_rate_hz;
  sampling.start_time_s = test.sensors.start_time_s;
  sampling.channels = channels;
  const simulation::SensitivityResult run = simulation::SimulateWithSensitivities(
      model, test.excitation, test.simulation, sampling, parameters, {}, sensitivity);
  const int samples = run.exact.samples();
  const int count = static_cast<int>(parameters.size());
  Eigen::MatrixXd jacobian(static_cast<Eigen::Index>(samples) * m, count);
  for (int k = 0; k < count; ++k) {
    const Eigen::MatrixXd& dy = run.output_sensitivities[static_cast<size_t>(k)];
    for (int j = 0; j < samples; ++j) {
      for (int c = 0; c < m; ++c) {
        // d y / d log p = p dy/dp.
        jacobian(static_cast<Eigen::Index>(j) * m + c, k) =
            dy(j, c) * values[static_cast<size_t>(k)] / sigma[c];
      }
    }
  }
  const int terms = test.fit_offsets ? (test.fit_drift ? 2 : 1) : 0;
  if (terms > 0) {
    if (samples <= terms) {
      throw InputError(test.name, "samples", std::to_string(samples) + " samples",
                       "more samples than baseline terms per channel");
    }
    const Baseline baseline(run.exact.CalcTime(), terms);
    for (int k = 0; k < count; ++k) {
      for (int c = 0; c < m; ++c) baseline.Project(jacobian.col(k).data() + c, m);
    }
  }
  FisherInformation information;
  information.parameters = parameters;
  information.matrix = jacobian.transpose() * jacobian;
  information.residuals = static_cast<long>(samples) * m;
  for (int c = 0; c < m && samples > 0; ++c) {
    const auto y = run.exact.values.col(c);
    information.largest_swing_to_noise =
        std::max(information.largest_swing_to_noise, (y.maxCoeff() - y.minCoeff()) / sigma[c]);
  }
  information.statistics = run.statistics;
  return information;
}

ExpectedUncertainty CalcExpectedUncertainty(const Eigen::MatrixXd& fisher, double rank_tolerance) {
  const Eigen::Index n = fisher.rows();
  ExpectedUncertainty result;
  result.relative_std = Eigen::VectorXd::Constant(n, std::numeric_limits<double>::infinity());
  if (n == 0) return result;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(fisher);
  const Eigen::VectorXd& lambda = eigen.eigenvalues();  // ascending
  const Eigen::MatrixXd& v = eigen.eigenvectors();
  const double largest = std::max(lambda[n - 1], 0.0);
  const double threshold = rank_tolerance * rank_tolerance * largest;
  std::vector<bool> in_null_space(static_cast<size_t>(n), largest <= 0);
  Eigen::MatrixXd covariance = Eigen::MatrixXd::Zero(n, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    if (largest > 0 && lambda[i] > threshold) {
      ++result.rank;
      covariance += v.col(i) * v.col(i).transpose() / lambda[i];
      continue;
    }
    for (Eigen::Index k = 0; k < n; ++k) {
      if (std::abs(v(k, i)) > 0.1) in_null_space[static_cast<size_t>(k)] = true;
    }
  }
  for (Eigen::Index k = 0; k < n; ++k) {
    if (!in_null_space[static_cast<size_t>(k)]) {
      result.relative_std[k] = std::sqrt(std::max(covariance(k, k), 0.0));
    }
  }
  return result;
}

}  // namespace mbid::updating
