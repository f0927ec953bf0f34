// A quadratic nonlinearity (an accelerometer's centripetal term, a joint's geometry) multiplies
// two modes' terms: e^(lambda_a t) e^(lambda_b t) = e^((lambda_a + lambda_b) t), a component at
// the sum of their frequencies that decays at the sum of their decay rates (and the difference
// frequency, lambda_b + conj(lambda_a), at the same decay). Above the noise it is "significant",
// but it is no mode of the structure: a damper sized on it damps nothing.
#include "combination_tones.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <optional>
#include <string>
#include <vector>

#include "mbid/identification/modal_fit.h"
#include "mbid/identification/significance.h"

namespace mbid::identification {
namespace {

// 3 combined standard deviations of a mode and the sum of two others' poles.
struct Spread {
  double frequency_hz = 0;
  double decay_per_s = 0;
};

Spread CalcSpread(const IdentifiedMode& tone, double variance_frequency, double variance_decay) {
  return {3 * std::sqrt(variance_frequency + tone.std_frequency_hz * tone.std_frequency_hz),
          3 * std::sqrt(variance_decay + tone.std_decay_rate_per_s * tone.std_decay_rate_per_s)};
}

// Frequency within 3 standard deviations plus 0.2 % (the tone's pole is refined beside its
// parents and shifted by their errors); decay within 3 standard deviations plus 25 % (a weak
// tone's decay is the least determined of its quantities: 21 % off on the excavator arm). Only
// where those 3 standard deviations are narrow (6 % of the frequency, the decay itself) does a
// match tell a sum from a coincidence: a mode known to +- 0.8 Hz matches some sum of any others.
bool Matches(const IdentifiedMode& tone, double frequency_hz, double decay_per_s,
             const Spread& spread) {
  if (!(spread.frequency_hz <= 0.06 * tone.frequency_hz && spread.decay_per_s <= decay_per_s)) {
    return false;
  }
  return std::abs(tone.frequency_hz - frequency_hz) <=
             spread.frequency_hz + 2e-3 * tone.frequency_hz &&
         std::abs(tone.decay_rate_per_s - decay_per_s) <= spread.decay_per_s + 0.25 * decay_per_s;
}

// The largest amplitude of a mode over the channels, each in units of its noise: a product of
// two modes is weaker than either, and by far weaker than the stronger (kMaxToneRatio).
double LargestAmplitude(const ModalResult& result, const IdentifiedMode& mode) {
  double largest = 0;
  for (Eigen::Index c = 0; c < mode.amplitude.size(); ++c) {
    const double noise =
        c < result.noise_std.size() && result.noise_std(c) > 0 ? result.noise_std(c) : 1.0;
    largest = std::max(largest, std::abs(mode.amplitude(c)) / noise);
  }
  return largest;
}

double Square(double x) { return x * x; }

// A quadratic term's amplitude over its stronger parent's is about the weaker parent's amplitude
// in radians (or strain) times a geometry factor: well under 1 % in a vibration test (0.25-0.75 %
// on the excavator arm, the drill mast and the aerial platform). The reference crane's
// third mode, weak in its two angle channels, lies at f1 + f2 or f4 - f1 at some elevations
// with 5-18 % of the stronger one's amplitude: a mode.
constexpr double kMaxToneRatio = 0.02;

// At large test vibrations a tone grows past kMaxToneRatio (the excavator arm released from 10
// mrad instead of 2: f1 + f3 with 3.5 % of f1's amplitude). Up to kMaxLargeToneRatio a mode is
// still taken for a tone when its pole is the sum's to a precision no chance neighbour reaches:
// 3 combined standard deviations within kPreciseFrequency of the frequency and a quarter of the
// decay. The reference crane's third mode (5-18 %, heavily damped) is known to 3-4 % only.
constexpr double kMaxLargeToneRatio = 0.10;
constexpr double kPreciseFrequency = 0.01;

bool IsPrecise(const IdentifiedMode& tone, double decay_per_s, const Spread& spread) {
  return spread.frequency_hz <= kPreciseFrequency * tone.frequency_hz &&
         spread.decay_per_s <= 0.25 * decay_per_s;
}

// The difference of a mode with itself: lambda + conj(lambda) = -2 sigma, no frequency. A
// linkage's quadratic terms (centripetal, geometric) shift its mean by the square of a mode's
// amplitude, decaying twice as fast as the mode: fitted as a pole, a slow "mode" of less than a
// cycle (0.037 Hz, decay 0.48 1/s beside a 1.31 Hz mode of decay 0.27 1/s on a trial's two-link
// arm) that made every multi-link free decay unreliable as "a trend or drift". A pole whose
// frequency is within its own 3 standard deviations of 0 and below its bandwidth, and whose decay
// is twice a mode's (3 combined standard deviations plus 25 %, those narrower than the decay).
bool MatchesMeanShift(const IdentifiedMode& tone, double decay_per_s, const Spread& spread) {
  return tone.frequency_hz <= 3 * tone.std_frequency_hz &&
         2 * M_PI * tone.frequency_hz <= tone.decay_rate_per_s &&
         spread.decay_per_s <= decay_per_s &&
         std::abs(tone.decay_rate_per_s - decay_per_s) <= spread.decay_per_s + 0.25 * decay_per_s;
}

constexpr size_t kMaxParents = 6;
constexpr size_t kMaxProducts = 8;

// A product of the parents' poles: sum_i count_i lambda_i, a negative count taking the
// conjugate (the difference frequency).
struct Product {
  std::complex<double> lambda;
  std::string name;  // "2 f3", "f1 + f2 - f3", 1-based in `modes`
};

std::string ProductName(std::vector<std::pair<size_t, int>> terms) {
  // "f1 + 2 f2 - f3": added terms first, each group in the modes' order.
  std::sort(terms.begin(), terms.end(), [](const auto& a, const auto& b) {
    return (a.second > 0) != (b.second > 0) ? a.second > 0 : a.first < b.first;
  });
  std::string name;
  for (const auto& [mode, count] : terms) {
    if (count == 0) continue;
    const int size = std::abs(count);
    const std::string term =
        (size > 1 ? fmt::format("{} ", size) : "") + fmt::format("f{}", mode + 1);
    name += name.empty() ? (count < 0 ? "-" + term : term) : (count < 0 ? " - " : " + ") + term;
  }
  return name;
}

// Whether the half-power bands of a pole and a mode overlap: their frequencies differ by less
// than the sum of their half widths (decay / (2 pi) in Hz).
bool Overlap(std::complex<double> lambda, const IdentifiedMode& mode) {
  return std::abs(lambda.imag() / (2 * M_PI) - mode.frequency_hz) <=
         (mode.decay_rate_per_s - lambda.real()) / (2 * M_PI);
}

// The second- and third-order products of `parents` whose half-power band overlaps
// `candidate`'s (farther ones cannot be mistaken for it) and below the Nyquist frequency.
std::vector<Product> NearbyProducts(const std::vector<IdentifiedMode>& modes,
                                    const std::vector<size_t>& parents,
                                    const IdentifiedMode& candidate, double nyquist_hz) {
  std::vector<Product> products;
  const auto add = [&](std::vector<std::pair<size_t, int>> terms) {
    std::complex<double> lambda = 0;
    for (const auto& [mode, count] : terms) {
      const std::complex<double> pole = modes[mode].lambda;
      lambda += count > 0 ? double(count) * pole : double(-count) * std::conj(pole);
    }
    if (lambda.imag() < 0) {  // the conjugate pair's other member: name it by its positive one
      lambda = std::conj(lambda);
      for (auto& term : terms) term.second = -term.second;
    }
    const double frequency_hz = lambda.imag() / (2 * M_PI);
    if (frequency_hz <= 0 || frequency_hz >= nyquist_hz || !Overlap(lambda, candidate)) return;
    products.push_back({lambda, ProductName(terms)});
  };
  const size_t n = parents.size();
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = i; j < n; ++j) {
      const size_t a = parents[i];
      const size_t b = parents[j];
      if (a == b) {
        add({{a, 2}});
      } else {
        add({{a, 1}, {b, 1}});
        add({{b, 1}, {a, -1}});
      }
      for (size_t k = j; k < n; ++k) {
        const size_t c = parents[k];
        if (a == b && b == c) {
          add({{a, 3}});
        } else if (a == b || b == c) {
          const size_t twice = a == b ? a : c;
          const size_t once = a == b ? c : a;
          add({{twice, 2}, {once, 1}});
          add({{twice, 2}, {once, -1}});
        } else {
          add({{a, 1}, {b, 1}, {c, 1}});
          add({{a, 1}, {b, 1}, {c, -1}});
          add({{a, 1}, {c, 1}, {b, -1}});
          add({{b, 1}, {c, 1}, {a, -1}});
        }
      }
    }
  }
  return products;
}

// A weak mode that no single sum matches may still be products: at a few times the noise, the
// second- and third-order products of the modes (at 2 mrad on the excavator arm: 2 f3 = 14.83,
// 3 f2 = 14.45, 2 f1 + f3 = 13.50 Hz) overlap within their bandwidths, and one pole fitted to
// them lands between them with a standard deviation that knows nothing of its neighbours
// (14.05 +- 0.09 Hz). Fitted beside those products' poles (with free amplitudes: the
// nonlinearity is unknown) such a mode is no longer significant, and the record cannot tell it
// from them. A mode of the structure that weak and that near a product cannot be told from it
// either; one away from them (a bandwidth or more, or with its own decay) stays significant.
void MarkProductsOfModes(const AnalysisRecord& record, const IdentificationOptions& options,
                         const std::vector<double>& largest, ModalResult* result) {
  std::vector<IdentifiedMode>& modes = result->modes;
  const double nyquist_hz = 0.5 / record.decimated_interval_s;
  std::optional<AmplitudeFit> all;  // of every mode: fitted once, when a candidate needs it
  for (size_t m = 0; m < modes.size(); ++m) {
    IdentifiedMode& candidate = modes[m];
    if (!candidate.combination.empty() || !candidate.significant) continue;
    // The strongest modes only: a product's amplitude goes with its parents'. Bounded counts
    // keep a record of many spurious poles (a decay cut before its release) from a fit of
    // thousands.
    std::vector<size_t> parents;
    for (size_t k = 0; k < modes.size(); ++k) {
      if (k != m && modes[k].combination.empty() && largest[k] > largest[m]) parents.push_back(k);
    }
    std::sort(parents.begin(), parents.end(),
              [&largest](size_t a, size_t b) { return largest[a] > largest[b]; });
    if (parents.size() > kMaxParents) parents.resize(kMaxParents);
    if (parents.empty() || !(largest[m] <= kMaxToneRatio * largest[parents.front()])) continue;
    const double strongest = largest[parents.front()];
    std::sort(parents.begin(), parents.end());  // names in the modes' order
    std::vector<Product> products = NearbyProducts(modes, parents, candidate, nyquist_hz);
    if (products.empty()) continue;
    std::stable_sort(
        products.begin(), products.end(), [&candidate](const Product& a, const Product& b) {
          return std::abs(a.lambda - candidate.lambda) < std::abs(b.lambda - candidate.lambda);
        });
    if (products.size() > kMaxProducts) products.resize(kMaxProducts);
    if (!all) {
      std::vector<std::complex<double>> lambda;
      for (const IdentifiedMode& mode : modes) lambda.push_back(mode.lambda);
      all = FitAmplitudes(record.decimated, record.decimated_interval_s, lambda,
                          options.offset == OffsetRemoval::kFit);
    }
    // Locally: the record less the fitted modes outside the candidate's band (which hardly
    // overlap it), fitted with those inside, the products, and the candidate last; a fit of
    // all of them per candidate costs many times more on a record of many spurious poles.
    std::vector<size_t> local;  // the modes inside the band, then the candidate
    for (size_t k = 0; k < modes.size(); ++k) {
      if (k != m && Overlap(modes[k].lambda, candidate)) local.push_back(k);
    }
    local.push_back(m);
    std::vector<std::complex<double>> poles;
    Eigen::MatrixXd coefficients(2 * local.size(), record.decimated.cols());
    for (size_t i = 0; i < local.size(); ++i) {
      poles.push_back(modes[local[i]].lambda);
      coefficients.middleRows(2 * static_cast<Eigen::Index>(i), 2) =
          all->coefficients.middleRows(2 * static_cast<Eigen::Index>(local[i]), 2);
    }
    const Eigen::MatrixXd values =
        record.decimated - all->reconstruction +
        CalcDampedSinusoidBasis(poles, record.decimated_interval_s,
                                static_cast<int>(record.decimated.rows()), false) *
            coefficients;
    // The modes inside the band, the products, and the candidate last.
    std::vector<std::complex<double>> inside(poles.begin(), poles.end() - 1);
    for (const Product& product : products) inside.push_back(product.lambda);
    inside.push_back(candidate.lambda);
    const AmplitudeFit fit = FitAmplitudes(values, record.decimated_interval_s, inside, false);
    const double significance = CalcSignificance(fit)(static_cast<Eigen::Index>(inside.size()) - 1);
    if (significance >= result->significance_threshold) continue;
    const Product* nearest = &products.front();
    candidate.combination = nearest->name;
    result->warnings.push_back(fmt::format(
        "the mode at {:.4g} Hz ({:.2g} % of the strongest mode's amplitude) is no longer "
        "significant (significance {:.3g}, threshold {:.3g}) beside the products of the modes' "
        "poles within its bandwidth ({}, nearest {} at {:.4g} Hz): the record cannot tell it "
        "from such combination tones, and it is marked as one",
        candidate.frequency_hz, 100 * largest[m] / strongest, significance,
        result->significance_threshold, products.size(), nearest->name,
        nearest->lambda.imag() / (2 * M_PI)));
  }
}

}  // namespace

void MarkCombinationTones(const AnalysisRecord& record, const IdentificationOptions& options,
                          ModalResult* result) {
  std::vector<IdentifiedMode>& modes = result->modes;
  const size_t n = modes.size();
  std::vector<double> largest(n);
  for (size_t k = 0; k < n; ++k) largest[k] = LargestAmplitude(*result, modes[k]);
  std::vector<std::string> too_strong(n);  // per mode: a sum it matches, too strong for a tone
  for (size_t m = 0; m < n; ++m) {
    IdentifiedMode& tone = modes[m];
    std::string large;        // the amplitude of a precise tone above kMaxToneRatio
    bool mean_shift = false;  // the tone is a mode with itself (MatchesMeanShift)
    for (size_t a = 0; a < n && tone.combination.empty(); ++a) {
      for (size_t b = a; b < n && tone.combination.empty(); ++b) {
        if (a == m || b == m || !(largest[m] < std::min(largest[a], largest[b]))) continue;
        const IdentifiedMode& low = modes[a];
        const IdentifiedMode& high = modes[b];
        if (!low.combination.empty() && !high.combination.empty()) continue;
        const Spread spread =
            CalcSpread(tone, Square(low.std_frequency_hz) + Square(high.std_frequency_hz),
                       Square(low.std_decay_rate_per_s) + Square(high.std_decay_rate_per_s));
        const double decay = low.decay_rate_per_s + high.decay_rate_per_s;
        if (Matches(tone, low.frequency_hz + high.frequency_hz, decay, spread)) {
          tone.combination =
              a == b ? fmt::format("2 f{}", a + 1) : fmt::format("f{} + f{}", a + 1, b + 1);
        } else if (a != b &&
                   Matches(tone, std::abs(high.frequency_hz - low.frequency_hz), decay, spread)) {
          tone.combination = fmt::format("f{} - f{}", std::max(a, b) + 1, std::min(a, b) + 1);
        } else if (a == b && MatchesMeanShift(tone, decay, spread)) {
          tone.combination = fmt::format("f{} - f{}", a + 1, a + 1);
          mean_shift = true;
        }
        if (tone.combination.empty()) continue;
        const double ratio = largest[m] / std::max(largest[a], largest[b]);
        const std::string share = fmt::format("{:.2g} % of f{}'s amplitude", 100 * ratio,
                                              (largest[a] >= largest[b] ? a : b) + 1);
        // A mean shift is no oscillation whose frequency could be precise: its decay is.
        if (mean_shift && ratio <= kMaxLargeToneRatio && spread.decay_per_s <= 0.25 * decay) {
          if (ratio > kMaxToneRatio) large = share;
          continue;
        }
        if (ratio <= kMaxToneRatio) continue;
        if (ratio <= kMaxLargeToneRatio && IsPrecise(tone, decay, spread)) {
          large = share;
          continue;
        }
        if (too_strong[m].empty()) too_strong[m] = tone.combination + " with " + share;
        tone.combination.clear();
        mean_shift = false;
      }
    }
    if (!tone.combination.empty()) {
      result->warnings.push_back(fmt::format(
          "the mode at {:.4g} Hz is a combination tone ({}): it matches the sum of those modes' "
          "poles in frequency and decay and is weaker than both; a quadratic nonlinearity "
          "(centripetal accelerations, joint geometry) makes such a component, not a mode of "
          "the structure{}{}",
          tone.frequency_hz, tone.combination,
          mean_shift ? " (a mean shift: no frequency, twice the mode's decay)" : "",
          large.empty() ? ""
                        : fmt::format(". With {} it is stronger than a tone of small vibrations "
                                      "(under {} %), but its pole is the sum's to within {} % "
                                      "in frequency: the test's vibrations were large",
                                      large, 100 * kMaxToneRatio, 100 * kPreciseFrequency)));
    }
  }
  MarkProductsOfModes(record, options, largest, result);
  for (size_t m = 0; m < n; ++m) {
    if (too_strong[m].empty() || !modes[m].combination.empty()) continue;
    result->warnings.push_back(fmt::format(
        "the mode at {:.4g} Hz lies where a combination tone would ({}), but a tone of small "
        "vibrations has under {} % of its stronger parent's amplitude: it is kept as a mode; "
        "if the test's vibrations were large (a tone grows with the product of its parents' "
        "amplitudes), it may be a tone",
        modes[m].frequency_hz, too_strong[m], 100 * kMaxToneRatio));
  }
}

}  // namespace mbid::identification
