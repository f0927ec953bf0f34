// Where the global search's fits start: space-filling design, start options, windows, eq. 7 sets.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "global_search_internal.h"
#include "mbid/model/linear_model.h"
#include "mbid/simulation/sensor.h"
#include "mbid/updating/characteristic.h"
#include "output_error_fit.h"

namespace mbid::updating::internal {
namespace {

// Radical inverse of i in `base` with the digits permuted by `permutation` (a scrambled Halton
// sequence: the plain one has correlated projections in the higher bases).
double ScrambledRadicalInverse(unsigned i, unsigned base,
                               const std::vector<unsigned>& permutation) {
  double value = 0, weight = 1.0 / base;
  for (; i > 0; i /= base, weight /= base) value += weight * permutation[i % base];
  return value;
}

}  // namespace

std::vector<std::vector<double>> SpaceFillingDesign(int count, int dimension, std::uint64_t seed) {
  static const unsigned kPrimes[] = {2,  3,  5,  7,  11, 13, 17, 19, 23, 29, 31, 37,  41, 43,
                                     47, 53, 59, 61, 67, 71, 73, 79, 83, 89, 97, 101, 103};
  const int available = static_cast<int>(sizeof(kPrimes) / sizeof(kPrimes[0]));
  std::mt19937_64 random(seed);
  std::vector<std::vector<unsigned>> permutations;
  std::vector<double> shift;
  for (int d = 0; d < dimension; ++d) {
    const unsigned base = kPrimes[d % available];
    std::vector<unsigned> permutation(base);
    for (unsigned k = 0; k < base; ++k) permutation[k] = k;
    // Zero stays zero: the sequence keeps its low-discrepancy structure.
    std::shuffle(permutation.begin() + 1, permutation.end(), random);
    permutations.push_back(permutation);
    // Beyond the primes, a random shift per dimension keeps repeated bases apart.
    shift.push_back(d < available ? 0.0 : std::uniform_real_distribution<double>(0, 1)(random));
  }
  std::vector<std::vector<double>> points;
  for (int i = 0; i < count; ++i) {
    std::vector<double> point;
    for (int d = 0; d < dimension; ++d) {
      const unsigned base = kPrimes[d % available];
      // Index from 1: point 0 of every Halton sequence is the corner.
      double u = ScrambledRadicalInverse(static_cast<unsigned>(i + 1), base, permutations[d]);
      u = std::fmod(u + shift[d], 1.0);
      point.push_back(u);
    }
    points.push_back(point);
  }
  return points;
}

std::vector<TestRecord> Window(const std::vector<TestRecord>& tests, double fraction) {
  std::vector<TestRecord> window = tests;
  for (TestRecord& test : window) {
    const int samples = test.record.samples();
    const int kept = std::min(samples, std::max(std::max(50, test.fit_drift ? 3 : 2),
                                                static_cast<int>(std::ceil(fraction * samples))));
    test.record.values = test.record.values.topRows(kept).eval();
  }
  return window;
}

void LoosenForScreening(double relative_tolerance, UpdateOptions& screen) {
  const double factor = relative_tolerance / screen.integrator.relative_tolerance;
  if (!(factor > 1)) return;
  screen.integrator.relative_tolerance *= factor;
  screen.integrator.absolute_tolerance *= factor;
  screen.sensitivity.relative_tolerance *= factor;
  screen.sensitivity.absolute_tolerance *= factor;
}

bool EveryNoiseGiven(const std::vector<TestRecord>& tests) {
  for (const TestRecord& test : tests) {
    for (const std::string& channel : test.record.channels) {
      if (test.noise_std.count(channel) == 0) return false;
    }
  }
  return true;
}

// With every channel's noise given and no baseline projected out, the cost is a sum of fixed
// squares over the samples, so the records' first tenth bounds it from below.
double CalcStartCostUpTo(const model::MechanicalModel& model, const std::vector<TestRecord>& tests,
                         const UpdateOptions& options, double limit) {
  const bool bounded =
      EveryNoiseGiven(tests) &&
      std::none_of(tests.begin(), tests.end(), [](const TestRecord& t) { return t.fit_offsets; });
  if (!bounded) return CalcStartCost(model, tests, options);
  const std::vector<TestRecord> prefix = Window(tests, kProbePrefix);
  bool whole = true;
  for (size_t i = 0; i < tests.size(); ++i) {
    whole = whole && prefix[i].record.samples() == tests[i].record.samples();
  }
  const double prefix_cost = CalcStartCost(model, prefix, options);
  return prefix_cost > limit || whole ? prefix_cost : CalcStartCost(model, tests, options);
}

UpdateOptions StartOptions(const UpdateOptions& options,
                           const std::vector<ParameterSetting>& settings,
                           const std::map<std::string, double>& values) {
  UpdateOptions start = options;
  start.parameters = settings;
  for (ParameterSetting& setting : start.parameters) {
    const auto found = values.find(setting.name);
    if (found != values.end() && std::isfinite(found->second)) {
      setting.initial = std::clamp(found->second, setting.lower, setting.upper);
    }
  }
  return start;
}

namespace {

// The tuned model of `fit` and its oscillating poles, where eq. 7 can give every joint set with
// such poles: every coordinate has a tuned spring and damper and every mode oscillates.
std::unique_ptr<model::MechanicalModel> TunedForEquation7(
    const model::MechanicalModel& model, const UpdateResult& fit,
    std::vector<std::complex<double>>* lambda) {
  if (!FindFreeCoordinate(model).empty()) return nullptr;
  // Checked before the linearization, which a payload's rest makes costly.
  for (const std::string& coordinate : model.coordinate_names()) {
    for (const std::string& name : {"c_" + coordinate, "d_" + coordinate}) {
      bool found = false;
      for (const ParameterEstimate& p : fit.parameters) found = found || p.name == name;
      if (!found) return nullptr;
    }
  }
  std::unique_ptr<model::MechanicalModel> tuned = model.Clone();
  ApplyEstimates(fit, *tuned);
  for (const model::Mode& mode : model::CalcModes(tuned->Linearize())) {
    if (mode.lambda.imag() > 0) lambda->push_back(mode.lambda);
  }
  if (static_cast<int>(lambda->size()) != tuned->coordinate_count()) return nullptr;
  return tuned;
}

std::vector<SearchStart> StartsWithPoles(const model::MechanicalModel& tuned,
                                         const std::vector<std::complex<double>>& lambda,
                                         const UpdateResult& fit, std::uint64_t seed,
                                         const std::string& label);

}  // namespace

std::vector<SearchStart> PoleEquivalentStarts(const model::MechanicalModel& model,
                                              const UpdateResult& fit, std::uint64_t seed) {
  std::vector<std::complex<double>> lambda;
  const std::unique_ptr<model::MechanicalModel> tuned = TunedForEquation7(model, fit, &lambda);
  if (!tuned) return {};
  return StartsWithPoles(*tuned, lambda, fit, seed, "pole-equivalent set");
}

std::vector<double> FrequenciesAbove(const model::MechanicalModel& model, const UpdateResult& fit,
                                     double nyquist_hz) {
  std::unique_ptr<model::MechanicalModel> tuned = model.Clone();
  ApplyEstimates(fit, *tuned);
  std::vector<double> above;
  for (const model::Mode& mode : model::CalcModes(tuned->Linearize())) {
    if (mode.frequency_hz() >= nyquist_hz) above.push_back(mode.frequency_hz());
  }
  return above;
}

std::vector<SearchStart> AliasStarts(const model::MechanicalModel& model, const UpdateResult& fit,
                                     std::uint64_t seed, double nyquist_hz,
                                     std::vector<std::string>* aliased) {
  std::vector<std::complex<double>> lambda;
  const std::unique_ptr<model::MechanicalModel> tuned = TunedForEquation7(model, fit, &lambda);
  if (!tuned || !(nyquist_hz > 0)) return {};
  bool moved = false;
  for (std::complex<double>& pole : lambda) {
    const double f = pole.imag() / (2 * M_PI);
    if (f < nyquist_hz) continue;
    const double alias = simulation::AliasFrequencyHz(f, 0.5 / nyquist_hz);
    if (!(alias > 0)) continue;  // at a multiple of the rate: no oscillation to move it to
    if (aliased != nullptr) aliased->push_back(fmt::format("{:.4g} Hz -> {:.4g} Hz", f, alias));
    pole = {pole.real(), 2 * M_PI * alias};
    moved = true;
  }
  if (!moved) return {};
  return StartsWithPoles(*tuned, lambda, fit, seed, "alias set");
}

namespace {

std::vector<SearchStart> StartsWithPoles(const model::MechanicalModel& tuned,
                                         const std::vector<std::complex<double>>& lambda,
                                         const UpdateResult& fit, std::uint64_t seed,
                                         const std::string& label) {
  std::vector<SearchStart> starts;
  CharacteristicOptions options;
  options.seed = seed;
  const CharacteristicResult sets = SolveCharacteristicEquation(
      MakeCharacteristicProblem(tuned, lambda, std::nullopt, std::nullopt), options);
  for (size_t s = 0; s < sets.solutions.size(); ++s) {
    const CharacteristicSolution& set = sets.solutions[s];
    if (!set.admissible) continue;
    SearchStart start;
    start.label = fmt::format("{} {}", label, s);
    bool same = true;  // the tuned set itself (to eq. 7's convergence)
    for (size_t i = 0; i < sets.coordinates.size(); ++i) {
      const Eigen::Index k = static_cast<Eigen::Index>(i);
      const std::string c = "c_" + sets.coordinates[i], d = "d_" + sets.coordinates[i];
      start.values[c] = set.c[k];
      start.values[d] = set.d[k];
      same = same && std::abs(set.c[k] / fit.Find(c).value - 1) < 1e-3 &&
             std::abs(set.d[k] / fit.Find(d).value - 1) < 1e-3;
    }
    if (!same) starts.push_back(start);
  }
  return starts;
}

}  // namespace

}  // namespace mbid::updating::internal
