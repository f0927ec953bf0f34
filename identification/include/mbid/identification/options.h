#pragma once

#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace mbid::identification {

// The estimator of the poles, by the name it is registered under (src/methods/, one file per
// method; adding one: docs/extending.md). The built-in ones have constants.
class Method {
 public:
  // Default: block-Hankel SVD (matrix pencil) initialization with the order from the noise
  // floor and stability across orders, then a Ceres refinement of all poles and amplitudes.
  static const Method kHankelNls;
  // The paper's method, steps 2-5 of method.md (vector AR with constant term, eq. 3-4).
  static const Method kPronySvd;

  // Any name; Identify rejects one that no method is registered under (ParseMethod checks).
  explicit Method(std::string name) : name_(std::move(name)) {}

  const std::string& name() const { return name_; }
  friend bool operator==(const Method& a, const Method& b) { return a.name_ == b.name_; }
  friend bool operator!=(const Method& a, const Method& b) { return !(a == b); }

 private:
  std::string name_;
};

inline const Method Method::kHankelNls{"hankel-nls"};
inline const Method Method::kPronySvd{"prony-svd"};

// "hankel-nls" or "prony-svd", as in the JSON field `method` and the `--method` flag.
std::string MethodName(const Method& method);
// Parses a method name; false (and `method` unchanged) for a name no method is registered under.
bool ParseMethod(const std::string& name, Method* method);
// The registered methods' names, in the order the choices are listed.
std::vector<std::string> MethodNames();

enum class SpectrumWindow { kNone, kHann };

// How a constant offset (a new static equilibrium after the load drop) is handled.
enum class OffsetRemoval {
  kNone,  // the record decays to zero
  kMean,  // the mean of the window is subtracted (biased for short, strongly decaying records)
  kFit,   // a constant per channel is estimated with the modes (the paper's B0 of eq. 3)
};

// Step 1 of method.md: the amplitude spectrum and its peaks.
struct SpectrumOptions {
  SpectrumWindow window = SpectrumWindow::kHann;
  // The FFT length is at least this factor times the samples, rounded up to a power of 2;
  // padding interpolates the spectrum so that peaks of short records are placed finely.
  int zero_padding_factor = 4;
  // A local maximum is a peak if its topographic prominence (its height above the higher of
  // the lowest points that separate it from a higher peak, or from the spectrum's ends) is at
  // least this fraction of the channel's largest amplitude.
  double min_peak_prominence = 0.05;
};

// Steps 2-4 of method.md.
struct PronySvdOptions {
  int order = 40;  // p of eq. 3, chosen generously (more poles than spectral peaks)
  // Effective rank k of step 3, "a threshold that reflects the data's accuracy": singular
  // values of the regression matrix (channels scaled to unit noise, prony_svd.h) whose square is
  // above noise_floor_factor times the largest that white noise gives count; so do only those
  // above rank_tolerance times the largest (round-off, for noiseless records). The rank then
  // indicates the model order (2 x modes + 1), and the truncated solution is Kumaresan and
  // Tufts' low-bias predictor. noise_floor_factor = 0 keeps every singular value above
  // round-off: plain least squares, the method as usually applied (biased under noise).
  double noise_floor_factor = 1.5;
  double rank_tolerance = 1e-9;
};

// The block-Hankel SVD (matrix pencil) initialization of the default method.
struct HankelOptions {
  // Columns of each channel's Hankel matrix: min(samples / 3, max_columns). More columns
  // detect weak modes and separate close ones better but cost O(columns^3); the refinement
  // removes the estimation error that fewer columns leave. On the paper's record at 20 dB,
  // 80 columns miss a mode in 12 % of the records, 100 in none of 200.
  int max_columns = 100;
  // A singular value is signal if its square exceeds this factor times the largest that white
  // noise gives: the noise floor (median of the trailing squared singular values of the
  // noise-normalized matrix) times the Marchenko-Pastur edge (1 + sqrt(columns / rows))^2.
  // Hankel structure spreads noise a little beyond that edge (about 1.3x); 1.5 leaves a margin.
  double noise_floor_factor = 1.5;
  // Singular values below this fraction of the largest are round-off (noiseless records).
  double min_relative_singular_value = 1e-7;
  // A pole is stable if it reappears, within stability_tolerance * |lambda|, at each of this
  // many higher orders (order + 2, order + 4, ...); 0 turns the check off.
  int stability_orders = 2;
  double stability_tolerance = 0.1;
  // Restarts from every pole at orders + 2, ..., + 2 * extra_orders above the signal order:
  // refine, drop insignificant modes, keep the result if it has more significant modes. For
  // low-SNR records, where the singular values of weak modes sink into the noise edge although
  // the whole record still determines them: the paper's Table 1 at 4.5 % noise gives four modes
  // in 12 of 12 records with 4, in 9 of 12 without. Off by default: it costs about 60x the time
  // and, at 30 dB, a spurious mode in 1.5 % of the records (docs/performance.md).
  int extra_orders = 0;
};

// The Ceres refinement of the default method.
struct RefinementOptions {
  int max_iterations = 100;
  // Ceres: relative change of the cost. At 1e-10 the parameters stop within about
  // 1e-5 sqrt(samples * channels) of their standard deviation from the optimum (5e-4 for
  // 2 x 1000 samples).
  double function_tolerance = 1e-10;
  double parameter_tolerance = 1e-10;  // Ceres: relative change of the parameters
  double gradient_tolerance = 1e-14;   // Ceres: max norm of the projected gradient
  // Weigh each channel by the inverse of its noise standard deviation (maximum likelihood for
  // white Gaussian noise of different levels per channel).
  bool weight_channels_by_noise = true;
};

// Where the analysed free decay starts (release.h).
enum class ReleaseMode {
  kDetect,  // found in the record: the end of a segment at rest (default)
  kGiven,   // IdentificationOptions::release_time_s
  kNone,    // the record's start (the record is the free decay)
  // IdentificationOptions::release_time_s, where the test's forcing (an impulse, a burst) ends
  // and its free decay starts (reported as "forcing end").
  kForcingEnd,
};

// Which modes carry a backbone, their frequency and damping ratio against amplitude (backbone.h).
enum class BackboneMode {
  kClusters,  // only a cluster of close poles that is one mode drifting with amplitude (default)
  kAlways,    // every mode; clusters are merged as with kClusters
  kNever,     // none: close poles stay separate modes (flagged as too close to separate)
};

// "clusters", "always" or "never", as the option `backbone` and the `--backbone` flag.
std::string BackboneModeName(BackboneMode mode);
// Parses a backbone mode's name; false (and `mode` unchanged) for any other word.
bool ParseBackboneMode(const std::string& name, BackboneMode* mode);

// Everything the identification of a free-decay record can be told. Defaults are meant for
// records like the paper's (a few modes, damping ratio up to 0.8, 10-40 dB SNR).
struct IdentificationOptions {
  Method method = Method::kHankelNls;

  // The free decay starts at the release; the analysis window never starts before it.
  ReleaseMode release = ReleaseMode::kDetect;
  double release_time_s = 0.0;  // kGiven, kForcingEnd: in the record's own time

  // The part of the record that is analysed, in the record's own time (s), inclusive.
  double window_start_s = -std::numeric_limits<double>::infinity();
  double window_end_s = std::numeric_limits<double>::infinity();
  std::vector<std::string> channels;  // empty: all, in the record's order
  OffsetRemoval offset = OffsetRemoval::kFit;
  // Poles are estimated on the record low-pass filtered (zero-phase FIR, cutoff 0.9 of the new
  // Nyquist frequency, flat to 0.76 of it) and downsampled by this factor; amplitudes, phases
  // and the reconstruction always use the full-rate record. The filter loses the first and last
  // 20 * decimation samples for the pole estimate. 0 (default): chosen from the spectrum, so
  // that the highest mode (and max_frequency_hz, if given) lies in the flat part of the filter
  // with a margin, keeping at least 500 samples; a record that is not oversampled keeps 1.
  int decimation = 0;

  // Step 5 of method.md: poles outside these limits are dropped. Modes are oscillatory:
  // frequency_hz > min_frequency_hz >= 0.
  double min_frequency_hz = 0.0;
  // 0: up to the Nyquist frequency of the (decimated) record; a larger value than that
  // Nyquist frequency is an input error.
  double max_frequency_hz = 0.0;
  // Slightly negative: a lightly damped mode may be estimated with a tiny negative decay.
  double min_damping_ratio = -0.01;
  // Keeps heavily damped modes (the paper's mode 1 has 0.68); 1 would admit real-pole pairs.
  double max_damping_ratio = 0.95;
  double max_decay_rate_per_s = std::numeric_limits<double>::infinity();
  int max_modes = 20;

  // Significance of a mode (significance.h): a chi-square statistic of "the mode is absent".
  // A mode is significant if it exceeds the threshold that pure white noise exceeds with this
  // probability per record (CalcSignificanceThreshold: about 38 for 2 x 1000 samples).
  double significance_false_alarm = 1e-3;
  // If > 0, this threshold is used instead of the one derived from significance_false_alarm.
  double min_significance = 0.0;
  // true: modes below the threshold are dropped (and the fit repeated without them);
  // false: they are kept with significant = false.
  bool drop_insignificant = true;

  // A result whose reconstruction explains less of the analysed band than this (Pearson's K in
  // any channel) is flagged unreliable.
  double min_correlation = 0.9;

  bool compute_spectrum = true;
  bool compute_stabilization = true;
  // Highest order of the stabilization data; 0: automatic (max(2 * effective rank + 10, 20),
  // at most what the method can compute).
  int stabilization_max_order = 0;
  bool compute_uncertainty = true;
  // Which modes get a backbone: sliding-window fits and the Hilbert transform's instantaneous
  // frequency and damping against amplitude (backbone.h, hilbert_backbone.h).
  BackboneMode backbone = BackboneMode::kClusters;
  // Fit and subtract a linear drift per channel with the modes (drift_removal.h): for records
  // whose sensors drift (a thermal drift, an integrating amplifier). The constant part stays with
  // `offset`.
  bool remove_drift = false;
  // A record clipped at its start (its first swings beyond a sensor's or logger's range) is
  // analysed from the sample after its last clipped one, if that leaves half the window or more
  // and nothing later is clipped (clipped_start.h); false: the window as given, and a clipped
  // record is unreliable.
  bool skip_clipped = true;

  SpectrumOptions spectrum;
  PronySvdOptions prony;
  HankelOptions hankel;
  RefinementOptions refinement;

  // Ceres style: true if every option is in range; otherwise false with `error` (if given)
  // naming the option, its value and what was expected.
  bool IsValid(std::string* error = nullptr) const;
  // The same as an InputError "<source>:<option>: <problem>; expected <range>", for callers
  // whose options come from a file or a command line.
  void Validate(const std::string& source) const;
};

}  // namespace mbid::identification
