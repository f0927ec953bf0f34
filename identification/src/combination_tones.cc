// A quadratic nonlinearity (an accelerometer's centripetal term, a joint's geometry) multiplies
// two modes' terms: e^(lambda_a t) e^(lambda_b t) = e^((lambda_a + lambda_b) t), a component at
// the sum of their frequencies that decays at the sum of their decay rates (and the difference
// frequency, lambda_b + conj(lambda_a), at the same decay). Above the noise it is "significant",
// but it is no mode of the structure: a damper sized on it damps nothing.
#include "combination_tones.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <string>

namespace mbid::identification {
namespace {

// Frequency within 3 standard deviations plus 0.2 % (the tone's pole is refined beside its
// parents and shifted by their errors); decay within 3 standard deviations plus 25 % (a weak
// tone's decay is the least determined of its quantities: 21 % off on the excavator arm). Only
// where those 3 standard deviations are narrow (6 % of the frequency, the decay itself) does a
// match tell a sum from a coincidence: a mode known to +- 0.8 Hz matches some sum of any others.
bool Matches(const IdentifiedMode& tone, double frequency_hz, double decay_per_s,
             double variance_frequency, double variance_decay) {
  const double spread_frequency =
      3 * std::sqrt(variance_frequency + tone.std_frequency_hz * tone.std_frequency_hz);
  const double spread_decay =
      3 * std::sqrt(variance_decay + tone.std_decay_rate_per_s * tone.std_decay_rate_per_s);
  if (!(spread_frequency <= 0.06 * tone.frequency_hz && spread_decay <= decay_per_s)) {
    return false;
  }
  return std::abs(tone.frequency_hz - frequency_hz) <=
             spread_frequency + 2e-3 * tone.frequency_hz &&
         std::abs(tone.decay_rate_per_s - decay_per_s) <= spread_decay + 0.25 * decay_per_s;
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

}  // namespace

void MarkCombinationTones(ModalResult* result) {
  std::vector<IdentifiedMode>& modes = result->modes;
  const size_t n = modes.size();
  std::vector<double> largest(n);
  for (size_t k = 0; k < n; ++k) largest[k] = LargestAmplitude(*result, modes[k]);
  for (size_t m = 0; m < n; ++m) {
    IdentifiedMode& tone = modes[m];
    std::string too_strong;  // a sum the mode matches, too strong to be its tone
    for (size_t a = 0; a < n && tone.combination.empty(); ++a) {
      for (size_t b = a; b < n && tone.combination.empty(); ++b) {
        if (a == m || b == m || !(largest[m] < std::min(largest[a], largest[b]))) continue;
        const IdentifiedMode& low = modes[a];
        const IdentifiedMode& high = modes[b];
        if (!low.combination.empty() && !high.combination.empty()) continue;
        const double variance_frequency =
            Square(low.std_frequency_hz) + Square(high.std_frequency_hz);
        const double variance_decay =
            Square(low.std_decay_rate_per_s) + Square(high.std_decay_rate_per_s);
        const double decay = low.decay_rate_per_s + high.decay_rate_per_s;
        if (Matches(tone, low.frequency_hz + high.frequency_hz, decay, variance_frequency,
                    variance_decay)) {
          tone.combination =
              a == b ? fmt::format("2 f{}", a + 1) : fmt::format("f{} + f{}", a + 1, b + 1);
        } else if (a != b && Matches(tone, std::abs(high.frequency_hz - low.frequency_hz), decay,
                                     variance_frequency, variance_decay)) {
          tone.combination = fmt::format("f{} - f{}", std::max(a, b) + 1, std::min(a, b) + 1);
        }
        const double ratio = largest[m] / std::max(largest[a], largest[b]);
        if (!tone.combination.empty() && !(ratio <= kMaxToneRatio)) {
          if (too_strong.empty()) {
            too_strong = fmt::format("{} with {:.2g} % of f{}'s amplitude", tone.combination,
                                     100 * ratio, (largest[a] >= largest[b] ? a : b) + 1);
          }
          tone.combination.clear();
        }
      }
    }
    if (!too_strong.empty() && tone.combination.empty()) {
      result->warnings.push_back(fmt::format(
          "the mode at {:.4g} Hz lies where a combination tone would ({}), but a tone of small "
          "vibrations has under {} % of its stronger parent's amplitude: it is kept as a mode; "
          "if the test's vibrations were large (a tone grows with the product of its parents' "
          "amplitudes), it may be a tone",
          tone.frequency_hz, too_strong, 100 * kMaxToneRatio));
    }
    if (!tone.combination.empty()) {
      result->warnings.push_back(fmt::format(
          "the mode at {:.4g} Hz is a combination tone ({}): it matches the sum of those modes' "
          "poles in frequency and decay and is weaker than both; a quadratic nonlinearity "
          "(centripetal accelerations, joint geometry) makes such a component, not a mode of "
          "the structure",
          tone.frequency_hz, tone.combination));
    }
  }
}

}  // namespace mbid::identification
