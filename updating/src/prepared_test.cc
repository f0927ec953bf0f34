#include "prepared_test.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "mbid/common/error.h"
#include "nan.h"

namespace mbid::updating::internal {

PreparedTest PrepareTest(const model::MechanicalModel& model, const TestRecord& test, int index,
                         const std::vector<Unknown>& unknowns, const UpdateOptions& options) {
  const Measurement& record = test.record;
  record.Validate(test.name);
  PreparedTest prepared;
  prepared.test = &test;
  const double tau = record.sample_interval_s;
  if (!(record.start_time_s >= 0)) {
    throw InputError(test.name, "start time", FormatValue(record.start_time_s) + " s",
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
        throw InputError(test.name, "noise_std." + given->first, FormatValue(given->second),
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

}  // namespace mbid::updating::internal
