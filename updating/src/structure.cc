#include "mbid/updating/structure.h"

#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <functional>
#include <iostream>
#include <mutex>
#include <set>
#include <thread>

#include "baseline.h"
#include "mbid/common/error.h"
#include "mbid/simulation/sensor.h"
#include "mbid/simulation/simulate.h"
#include "nan.h"

namespace mbid::updating {
namespace {

using internal::kNaN;

// The candidate's options: only parameters its model has; starts from the reference's estimates
// where asked; one thread per fit (the ranking runs fits side by side instead).
UpdateOptions PrepareOptions(const StructureCandidate& candidate, const UpdateResult* reference) {
  UpdateOptions options = candidate.options;
  std::set<std::string> names;
  for (const model::Parameter& parameter : candidate.model->parameters()) {
    names.insert(parameter.name);
  }
  if (options.parameters.empty()) {
    for (const std::string& name : names) options.parameters.push_back({name});
  }
  std::vector<ParameterSetting> kept;
  for (ParameterSetting setting : options.parameters) {
    if (!names.count(setting.name)) continue;
    if (candidate.start_from_reference && reference != nullptr && std::isnan(setting.initial)) {
      for (const ParameterEstimate& estimate : reference->parameters) {
        if (estimate.test.empty() && estimate.name == setting.name) {
          // The reference's bounds too: bounds derived from the new start would let a parameter
          // the reference pushed to its bound run 100x further (a joint stiffened 1e4x makes
          // every simulation of the fit stiff and slow, and means nothing more).
          if (std::isnan(setting.lower)) setting.lower = estimate.lower;
          if (std::isnan(setting.upper)) setting.upper = estimate.upper;
          setting.initial = std::clamp(estimate.value, setting.lower, setting.upper);
        }
      }
    }
    kept.push_back(setting);
  }
  options.parameters = kept;
  options.threads = 1;
  options.quiet = true;
  return options;
}

// Empty if the model computes every channel of the records; else why not.
std::string MissingChannels(const model::MechanicalModel& model,
                            const std::vector<TestRecord>& tests) {
  std::vector<std::string> known = model.output_names();
  known.insert(known.end(), model.coordinate_names().begin(), model.coordinate_names().end());
  std::string missing;
  for (const TestRecord& test : tests) {
    for (const std::string& channel : test.record.channels) {
      if (std::find(known.begin(), known.end(), channel) != known.end()) continue;
      missing +=
          fmt::format("{}channel '{}' of {}", missing.empty() ? "" : ", ", channel, test.name);
    }
  }
  return missing.empty() ? "" : "the model does not compute " + missing;
}

long CountResiduals(const std::vector<TestRecord>& tests) {
  long count = 0;
  for (const TestRecord& test : tests) {
    count += static_cast<long>(test.record.samples()) * test.record.channel_count();
  }
  return count;
}

// Runs jobs 0..count-1 on up to `threads` threads; each job writes only its own slot.
void RunJobs(int count, int threads, const std::function<void(int)>& job) {
  std::atomic<int> next{0};
  const auto worker = [&] {
    for (int j = next++; j < count; j = next++) job(j);
  };
  std::vector<std::thread> pool;
  const int extra = std::max(0, std::min(threads, count) - 1);
  for (int t = 0; t < extra; ++t) pool.emplace_back(worker);
  worker();
  for (std::thread& thread : pool) thread.join();
}

std::string FitFailure(const UpdateResult& fit) {
  return fit.termination == UpdateResult::Termination::kFailure ? "the fit failed: " + fit.message
                                                                : std::string();
}

}  // namespace

std::vector<std::vector<std::string>> EnumerateRigidSets(const std::vector<std::string>& compliant,
                                                         int max_rigid) {
  std::vector<std::vector<std::string>> sets;
  const int n = static_cast<int>(compliant.size());
  for (int size = 1; size <= std::min(max_rigid, n); ++size) {
    // Index combinations in lexicographic order.
    std::vector<int> pick(static_cast<size_t>(size));
    for (int i = 0; i < size; ++i) pick[static_cast<size_t>(i)] = i;
    while (true) {
      std::vector<std::string> set;
      for (int i : pick) set.push_back(compliant[static_cast<size_t>(i)]);
      sets.push_back(set);
      int i = size - 1;
      while (i >= 0 && pick[static_cast<size_t>(i)] == n - size + i) --i;
      if (i < 0) break;
      ++pick[static_cast<size_t>(i)];
      for (int k = i + 1; k < size; ++k) {
        pick[static_cast<size_t>(k)] = pick[static_cast<size_t>(k - 1)] + 1;
      }
    }
  }
  return sets;
}

Eigen::MatrixXd CalcWeightedResidual(const model::MechanicalModel& model, const TestRecord& test,
                                     const simulation::IntegratorOptions& integrator) {
  const Measurement& record = test.record;
  // Sampled at the record's own times, as Route 2 does (output_error.cc, PrepareTest).
  const double tau = record.sample_interval_s;
  const double grid_index = std::round(record.start_time_s / tau);
  const bool whole =
      std::abs(record.start_time_s / tau - grid_index) <= simulation::kWholeSampleTolerance;
  simulation::SimulationOptions simulation;
  simulation.duration_s = whole ? (grid_index + record.samples() - 1) * tau
                                : record.start_time_s + (record.samples() - 1) * tau;
  simulation.integrator = integrator;
  simulation::SensorOptions sensors;
  sensors.sample_rate_hz = 1.0 / tau;
  sensors.start_time_s = record.start_time_s;
  sensors.channels = record.channels;
  const simulation::SimulationResult run =
      simulation::Simulate(model, test.excitation, simulation, sensors);
  if (run.exact.values.rows() != record.values.rows() ||
      run.exact.values.cols() != record.values.cols()) {
    throw NumericalError("prediction",
                         fmt::format("{}: the simulation gave {} samples, the "
                                     "record has {}",
                                     test.name, run.exact.values.rows(), record.values.rows()));
  }
  const Baseline baseline(record.CalcTime(), test.fit_offsets ? (test.fit_drift ? 2 : 1) : 0);
  Eigen::MatrixXd residual = run.exact.values - record.values;
  for (int c = 0; c < record.channel_count(); ++c) {
    const std::string& channel = record.channels[static_cast<size_t>(c)];
    const auto sigma = test.noise_std.find(channel);
    if (sigma == test.noise_std.end() || !(sigma->second > 0)) {
      throw InputError(test.name, "noise_std." + channel, "no noise level",
                       "a positive noise standard deviation per channel");
    }
    Eigen::VectorXd column = residual.col(c);
    if (baseline.terms() > 0) baseline.Project(column.data(), 1);
    residual.col(c) = column / sigma->second;
  }
  return residual;
}

StructureRanking RankStructures(const std::vector<StructureCandidate>& candidates,
                                const std::vector<TestRecord>& tests,
                                const StructureOptions& options) {
  const auto start_time = std::chrono::steady_clock::now();
  if (candidates.empty() || tests.empty()) {
    throw InputError("structure", candidates.empty() ? "candidates" : "records", "none",
                     "the scenario's model and at least one record");
  }
  std::mutex print_mutex;
  const auto report = [&](const std::string& line) {
    if (options.quiet) return;
    std::lock_guard<std::mutex> lock(print_mutex);
    std::cerr << "mbid: " << line << "\n";
  };

  const size_t count = candidates.size();
  std::vector<StructureFit> fits(count);
  for (size_t i = 0; i < count; ++i) {
    fits[i].name = candidates[i].name;
    fits[i].rigid = candidates[i].rigid;
    fits[i].description = candidates[i].description;
    fits[i].coordinates = candidates[i].model->coordinate_names();
    fits[i].residual_count = CountResiduals(tests);
  }

  // The reference first: its noise weights are every candidate's. Weights estimated per
  // candidate would put each cost on its own scale (a worse structure leaves a larger residual,
  // reads it as more noise and lowers its own cost); one sigma per channel keeps 2 cost a
  // -2 log L of the same likelihood for all.
  const std::string reference_missing = MissingChannels(*candidates[0].model, tests);
  if (!reference_missing.empty()) {
    throw InputError(candidates[0].name, "channels", reference_missing,
                     "records of the scenario model's outputs or coordinates");
  }
  StructureRanking ranking;
  const UpdateOptions reference_options = PrepareOptions(candidates[0], nullptr);
  ranking.reference_search =
      SearchGlobally(*candidates[0].model, tests, reference_options, options.reference_start,
                     options.reference_starts, options.search);
  std::vector<TestRecord> weighed = tests;
  if (options.after_reference &&
      ranking.reference_search.best.termination != UpdateResult::Termination::kFailure) {
    for (const std::string& line : options.after_reference(
             *candidates[0].model, &weighed, reference_options, &ranking.reference_search.best)) {
      report(line);
    }
    for (StructureFit& fit : fits) fit.residual_count = CountResiduals(weighed);
  }
  fits[0].fit = ranking.reference_search.best;
  report(fmt::format("structure {}: {} after {} iterations, cost {:.6g}", fits[0].name,
                     fits[0].fit.termination_name(), fits[0].fit.iterations,
                     fits[0].fit.final_cost));
  const UpdateResult& reference = fits[0].fit;
  if (reference.termination == UpdateResult::Termination::kFailure) {
    throw NumericalError("structure",
                         "the fit of " + fits[0].name +
                             " (whose noise weighs every candidate) failed: " + reference.message);
  }
  for (size_t t = 0; t < tests.size(); ++t) {
    const TestFit& fit = reference.tests[t];
    for (size_t c = 0; c < fit.channels.size(); ++c) {
      weighed[t].noise_std[fit.channels[c]] = fit.noise_std[static_cast<Eigen::Index>(c)];
    }
    ranking.noise_std.push_back(weighed[t].noise_std);
  }
  // The reference's cost in these weights: its own final cost, unless its weights were estimated
  // during the fit (then the final stage used them already: the same number).
  std::vector<UpdateOptions> prepared(count);
  for (size_t i = 0; i < count; ++i) prepared[i] = PrepareOptions(candidates[i], &reference);

  // Every other candidate on all records.
  RunJobs(static_cast<int>(count) - 1, options.threads, [&](int job) {
    const size_t i = static_cast<size_t>(job) + 1;
    StructureFit& fit = fits[i];
    fit.skipped = MissingChannels(*candidates[i].model, weighed);
    if (!fit.skipped.empty()) {
      report(fmt::format("structure {}: skipped: {}", fit.name, fit.skipped));
      return;
    }
    try {
      fit.fit = UpdateModel(*candidates[i].model, weighed, prepared[i]);
      fit.skipped = FitFailure(fit.fit);
    } catch (const InputError& error) {
      fit.skipped = error.what();
    }
    report(fmt::format("structure {}: {} after {} iterations, cost {:.6g}", fit.name,
                       fit.fit.termination_name(), fit.fit.iterations, fit.fit.final_cost));
  });

  for (StructureFit& fit : fits) {
    if (!fit.skipped.empty()) continue;
    fit.cost = fit.fit.final_cost;
    fit.parameter_count = static_cast<int>(fit.fit.parameters.size());
    const double k = fit.parameter_count;
    fit.aic = 2 * fit.cost + 2 * k;
    fit.bic = 2 * fit.cost + k * std::log(static_cast<double>(fit.residual_count));
  }

  // Leave-one-out: each candidate fitted to all records but i (starting at its all-record
  // estimates, which saves most iterations; the start only picks the minimum found), then
  // record i simulated with that fit.
  const size_t records = tests.size();
  if (options.leave_one_out && records >= 2) {
    std::vector<Eigen::MatrixXd> held_out(count * records);
    std::vector<std::string> failure(count * records);
    RunJobs(static_cast<int>(count * records), options.threads, [&](int job) {
      const size_t i = static_cast<size_t>(job) / records;
      const size_t r = static_cast<size_t>(job) % records;
      if (!fits[i].skipped.empty()) return;
      std::vector<TestRecord> others;
      for (size_t t = 0; t < records; ++t) {
        if (t != r) others.push_back(weighed[t]);
      }
      UpdateOptions loo = prepared[i];
      for (ParameterSetting& setting : loo.parameters) {
        for (const ParameterEstimate& estimate : fits[i].fit.parameters) {
          if (estimate.test.empty() && estimate.name == setting.name) {
            // Within the all-record fit's bounds (see PrepareOptions).
            setting.lower = estimate.lower;
            setting.upper = estimate.upper;
            setting.initial = std::clamp(estimate.value, estimate.lower, estimate.upper);
          }
        }
      }
      try {
        const UpdateResult fit = UpdateModel(*candidates[i].model, others, loo);
        if (fit.termination == UpdateResult::Termination::kFailure) {
          failure[static_cast<size_t>(job)] = fit.message;
          return;
        }
        std::unique_ptr<model::MechanicalModel> tuned = candidates[i].model->Clone();
        ApplyEstimates(fit, *tuned);
        held_out[static_cast<size_t>(job)] =
            CalcWeightedResidual(*tuned, weighed[r], loo.integrator);
        report(fmt::format(
            "structure {}: {} predicted with weighted rms {:.4g}", fits[i].name, tests[r].name,
            std::sqrt(held_out[static_cast<size_t>(job)].squaredNorm() /
                      static_cast<double>(held_out[static_cast<size_t>(job)].size()))));
      } catch (const std::exception& error) {
        failure[static_cast<size_t>(job)] = error.what();
      }
    });
    for (size_t i = 0; i < count; ++i) {
      if (!fits[i].skipped.empty()) continue;
      double sum = 0;
      long n = 0;
      bool complete = true;
      for (size_t r = 0; r < records; ++r) {
        const Eigen::MatrixXd& residual = held_out[i * records + r];
        if (residual.size() == 0) {
          complete = false;
          fits[i].prediction_error_per_record.push_back(kNaN);
          continue;
        }
        sum += residual.squaredNorm();
        n += static_cast<long>(residual.size());
        fits[i].prediction_error_per_record.push_back(
            std::sqrt(residual.squaredNorm() / static_cast<double>(residual.size())));
      }
      fits[i].prediction_error = complete ? std::sqrt(sum / static_cast<double>(n)) : kNaN;
    }
  }

  // Best first: the lowest BIC; candidates without one (skipped) last, in their given order.
  std::vector<size_t> order(count);
  for (size_t i = 0; i < count; ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    const bool a_ok = std::isfinite(fits[a].bic), b_ok = std::isfinite(fits[b].bic);
    if (a_ok != b_ok) return a_ok;
    return a_ok && fits[a].bic < fits[b].bic;
  });
  const double best = fits[order.front()].bic;
  for (size_t position = 0; position < count; ++position) {
    StructureFit fit = std::move(fits[order[position]]);
    fit.rank = static_cast<int>(position) + 1;
    fit.delta_bic = fit.bic - best;
    ranking.structures.push_back(std::move(fit));
  }
  ranking.wall_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_time).count();
  return ranking;
}

}  // namespace mbid::updating
