#include "mbid/updating/credibility.h"

#include <fmt/format.h>

#include <algorithm>
#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/distributions/normal.hpp>
#include <cmath>
#include <vector>

#include "distributions.h"
#include "mbid/common/channel_fault.h"
#include "statistics.h"

namespace mbid::updating {
namespace {

// Significance of the whiteness test and of a chi^2 above the noise's.
constexpr double kWhitenessLevel = 1e-3;
// chi^2/dof (and inflation) above which the standard deviations are not taken as they are: a
// residual rms 10% above the noise.
constexpr double kNoticeableExcess = 1.2;
// chi^2/dof above which a significant, non-white excess is signal left unexplained: a residual
// rms 2.5% above the records' noise, about what a noise level estimated from one record may be
// off. Wrong minima of the reference load drop (design model 25-35% off, 4.5-10 s) ended at
// 1.15-1.34, the true ones at 0.97-0.99.
constexpr double kStructuredExcess = 1.05;

// "; correlated -1 with c_qb: ..." for a parameter the records know only in a combination with
// another (two springs in series that one sensor sees as one: their series stiffness is
// determined, each spring not; a trial read only "relative std 0.71 above 0.3"), else "".
std::string PartnerInACombination(const UpdateResult& result, const ParameterEstimate& p) {
  const auto n = static_cast<Eigen::Index>(result.parameters.size());
  if (result.correlation.rows() != n || result.correlation.cols() != n) return "";
  for (Eigen::Index i = 0; i < n; ++i) {
    if (result.parameters[static_cast<size_t>(i)].name != p.name) continue;
    for (Eigen::Index j = 0; j < n; ++j) {
      const double rho = result.correlation(i, j);
      if (j == i || !(std::abs(rho) > kCombinationCorrelation)) continue;
      return fmt::format(
          "; correlated {:.3g} with {}: the records determine a combination of the two (as of "
          "two joints in series that the sensors see as one), not each",
          rho, result.parameters[static_cast<size_t>(j)].name);
    }
  }
  return "";
}

}  // namespace

void AssessCredibility(UpdateResult& result, const std::vector<TestRecord>& tests,
                       const UpdateOptions& options) {
  if (result.tests.size() != tests.size()) return;
  double residuals = 0, baseline_terms = 0;
  bool from_records = true;
  double worst_time = 1;
  std::string worst_channel;
  std::string offset_hint;
  // The least white residual (Ljung-Box), and the channel whose own excess over its noise is
  // significant and not white: an oscillating misfit (a model's mode a little off) has a
  // correlation time of 1, its autocorrelations alternating in sign, and one channel's misfit
  // can hide in the records' pooled chi^2.
  double least_white_p = kWhitenessLevel;
  std::string least_white_channel;
  double channel_excess = kStructuredExcess;
  std::string excess_channel;
  // The residual's largest sample over its spread, and where: a misfit a few samples hold (a
  // hammer blow 10 % off: 33 times the noise in one sample) barely moves chi^2 or the whiteness.
  double spike = 0;
  std::string spike_at;
  for (size_t t = 0; t < tests.size(); ++t) {
    TestFit& fit = result.tests[t];
    const Measurement& record = tests[t].record;
    const int m = record.channel_count();
    if (fit.simulated.values.rows() != record.samples() || fit.noise_std.size() != m) return;
    fit.whiteness_q.resize(m);
    fit.whiteness_p.resize(m);
    fit.correlation_time.resize(m);
    residuals += static_cast<double>(record.samples()) * m;
    baseline_terms += static_cast<double>(fit.offset.size() + fit.drift.size());
    for (int c = 0; c < m; ++c) {
      from_records = from_records && !fit.noise_estimated[static_cast<size_t>(c)];
      const Eigen::VectorXd r =
          (fit.simulated.values.col(c) - record.values.col(c)) / fit.noise_std[c];
      // Most of an unfitted channel's residual power in its mean: a sensor offset.
      const double mean = r.mean();
      if (fit.offset.size() == 0 && offset_hint.empty() && r.size() > 1 &&
          mean * mean > 0.5 * r.squaredNorm() / static_cast<double>(r.size()) &&
          std::abs(mean) > 3) {
        offset_hint = fmt::format(
            "; the residual of {} is mostly a constant ({:.3g} {}, {:.3g} times the noise): an "
            "offset of the sensor, which updating.fit_offsets: true fits",
            record.channels[static_cast<size_t>(c)], -mean * fit.noise_std[c],
            record.units[static_cast<size_t>(c)], std::abs(mean));
      }
      Whiteness(r, options.whiteness_lags, &fit.whiteness_q[c], &fit.whiteness_p[c],
                &fit.correlation_time[c]);
      const std::string channel = fit.channels[static_cast<size_t>(c)] + " of " + fit.name;
      // Against the residual's own spread (1.4826 median absolute values): a noise level stated
      // too low is the white excess below, not a spike.
      if (r.size() > 0) {
        Eigen::VectorXd magnitude = r.cwiseAbs();
        double* const middle = magnitude.data() + magnitude.size() / 2;
        std::nth_element(magnitude.data(), middle, magnitude.data() + magnitude.size());
        const double spread = 1.4826 * *middle;
        Eigen::VectorXd measured = r.cwiseAbs();
        for (const Eigen::Index j : tests[t].unmeasured_samples) {
          if (j >= 0 && j < measured.size()) measured[j] = 0;
        }
        Eigen::Index largest = 0;
        const double peak = measured.maxCoeff(&largest);
        if (spread > 0 && peak / spread > spike) {
          spike = peak / spread;
          spike_at = fmt::format("{} at {:.6g} s", channel,
                                 record.start_time_s + largest * record.sample_interval_s);
        }
      }
      // A residual white at the 0.1% level is not inflated for its sampling wiggle.
      if (fit.whiteness_p[c] < kWhitenessLevel && fit.correlation_time[c] > worst_time) {
        worst_time = fit.correlation_time[c];
        worst_channel = channel;
      }
      if (fit.whiteness_p[c] < least_white_p) {
        least_white_p = fit.whiteness_p[c];
        least_white_channel = channel;
      }
      const double samples = static_cast<double>(r.size());
      const double chi_square = r.squaredNorm();
      if (fit.whiteness_p[c] < kWhitenessLevel && chi_square / samples > channel_excess &&
          boost::math::cdf(boost::math::complement(
              boost::math::chi_squared_distribution<double, internal::DistributionPolicy>(samples),
              chi_square)) < kWhitenessLevel) {
        channel_excess = chi_square / samples;
        excess_channel = channel;
      }
    }
  }
  const double k = static_cast<double>(result.parameters.size()) + baseline_terms;
  const double dof = std::max(1.0, residuals - k);
  result.chi_square_per_dof = 2 * result.final_cost / dof;
  result.weights_from_records = from_records;
  const double excess = from_records ? std::max(1.0, result.chi_square_per_dof) : 1.0;
  result.std_inflation = std::sqrt(excess * worst_time);
  result.credibility.clear();
  const bool misfit = from_records && result.chi_square_per_dof > options.max_chi_square_per_dof;
  // Noise is white or coloured but has the records' level: a residual significantly above it
  // that is also not white holds signal the model does not reproduce (a local minimum, or a
  // model that lacks something); a white excess is a noise level stated too low.
  const bool pooled =
      from_records && result.chi_square_per_dof > kStructuredExcess &&
      !least_white_channel.empty() &&
      boost::math::cdf(boost::math::complement(
          boost::math::chi_squared_distribution<double, internal::DistributionPolicy>(dof),
          2 * result.final_cost)) < kWhitenessLevel;
  // Gaussian noise of the weights' level exceeds this in one of all the residual's samples with
  // probability 1e-3 (about 4.9 for 3000 samples, 5.7 for 1e5).
  const double spike_limit = boost::math::quantile(
      boost::math::complement(boost::math::normal(), 0.5 * kWhitenessLevel / residuals));
  const bool spiked = !misfit && spike > spike_limit;
  const bool structured =
      !misfit && (spiked || (from_records && (pooled || !excess_channel.empty())));
  if (misfit) {
    result.credibility.push_back(fmt::format(
        "the re-simulation misses the records by {:.3g} times their noise (chi^2/dof = {:.4g} > "
        "{}): a local minimum, or a model that lacks something; no parameter is determined by "
        "this fit{}",
        std::sqrt(result.chi_square_per_dof), result.chi_square_per_dof,
        options.max_chi_square_per_dof, offset_hint));
  } else if (spiked) {
    result.credibility.push_back(fmt::format(
        "the residual of {} is {:.3g} times its spread elsewhere, which Gaussian noise exceeds in "
        "none of the records' {:.0f} samples (beyond {:.2g} with probability {}): a feature the "
        "model does not reproduce there (an impulse's size or timing, a mass); no parameter is "
        "determined by this fit",
        spike_at, spike, residuals, spike_limit, kWhitenessLevel));
  } else if (structured) {
    const std::string where =
        pooled ? fmt::format(
                     "the residual is {:.3g} times the records' noise (chi^2/dof = {:.4g}) "
                     "and not white (Ljung-Box p = {:.2g} on {})",
                     std::sqrt(result.chi_square_per_dof), result.chi_square_per_dof, least_white_p,
                     least_white_channel)
               : fmt::format(
                     "the residual of {} is {:.3g} times its noise (chi^2 per sample "
                     "{:.4g}, {:.4g} over all records) and not white",
                     excess_channel, std::sqrt(channel_excess), channel_excess,
                     result.chi_square_per_dof);
    result.credibility.push_back(
        where +
        ": the excess is signal the model does not reproduce, a local minimum or a model that "
        "lacks something; no parameter is determined by this fit" +
        offset_hint);
  } else {
    if (excess > kNoticeableExcess) {
      result.credibility.push_back(fmt::format(
          "the residual is {:.3g} times the records' noise (chi^2/dof = {:.4g}): standard "
          "deviations scaled up by {:.3g}",
          std::sqrt(excess), result.chi_square_per_dof, std::sqrt(excess)));
    }
    if (worst_time > 1.2) {
      result.credibility.push_back(fmt::format(
          "the residual is not white (correlation time {:.3g} samples on {}): the Fisher "
          "standard deviations assume white noise and are scaled up by {:.3g}",
          worst_time, worst_channel, std::sqrt(worst_time)));
    }
  }
  if (!from_records) {
    result.credibility.push_back(
        "the noise was estimated from this fit's own residual: a misfit cannot be told from "
        "noise except by the residual's whiteness");
  }
  // Far below 1 (5 of chi^2/dof's sampling standard deviations sqrt(2 / dof)): the weights
  // overstate the noise, as an identification's residual does when its modes missed something
  // (chi^2/dof 0.25 on a boom whose identification left 16 times the noise). The standard
  // deviations are then too large; said, and left so (on the safe side).
  if (from_records && result.chi_square_per_dof < 1 - 5 * std::sqrt(2 / dof)) {
    result.credibility.push_back(fmt::format(
        "the residual is {:.3g} times the noise the fit was weighted with (chi^2/dof = {:.4g}): "
        "that noise is overstated, and the standard deviations are about {:.3g} times too large",
        std::sqrt(result.chi_square_per_dof), result.chi_square_per_dof,
        1 / std::sqrt(std::max(result.chi_square_per_dof, 1e-12))));
  }
  // A clipped channel holds its peaks at the rail, a glitch jumps off the motion: the fit takes
  // such samples as measured and leans towards them, whatever the residual says.
  std::string faulty;
  for (size_t t = 0; t < tests.size(); ++t) {
    const Measurement& record = tests[t].record;
    for (int c = 0; c < record.channel_count(); ++c) {
      const std::string& channel = record.channels[static_cast<size_t>(c)];
      // While a hammer blow or burst acts (and 2 samples of its edges), the record jumps as the
      // simulation does.
      const std::optional<ChannelFault> found =
          FindChannelFault(record.values.col(c), channel, record.units[static_cast<size_t>(c)],
                           record.sample_interval_s, record.start_time_s,
                           tests[t].excitation.CalcForcingEndTime() + 2 * record.sample_interval_s);
      if (!found) continue;
      const std::string& fault = found->reason;
      const char* what = found->kind == ChannelFault::Kind::kClipped
                             ? "is clipped (the sensor or logger at the end of its range)"
                             : "jumps off its course (a glitch or a knock)";
      result.credibility.push_back(
          fmt::format("test {}: {}; the fit takes those samples as measured values, so no "
                      "parameter is determined by it",
                      result.tests[t].name, fault));
      if (faulty.empty()) {
        faulty = fmt::format("channel {} of test {} {}", channel, result.tests[t].name, what);
      }
    }
  }
  result.credible =
      !misfit && !structured && faulty.empty() && result.std_inflation <= kNoticeableExcess;
  result.explains_records = from_records && !misfit && !structured && faulty.empty();

  result.undetermined.clear();
  for (ParameterEstimate& p : result.parameters) {
    SetInterval(p, result.std_inflation);
    if (result.termination == UpdateResult::Termination::kNoConvergence) {
      // Not at a minimum: the curvature there is no standard deviation of anything (a fit of two
      // springs in series stopped after 50 iterations with c_u1 16 of its stds off, unmarked).
      p.determined = false;
      p.why_undetermined =
          "the fit stopped before reaching a minimum (no convergence): its standard deviation "
          "does not hold";
    } else if (!faulty.empty() && p.test.empty()) {
      p.determined = false;
      p.why_undetermined = faulty;
    } else if (misfit && p.test.empty()) {
      p.determined = false;
      p.why_undetermined = "the fit does not explain the records (chi^2/dof too large)";
    } else if (structured && p.test.empty()) {
      p.determined = false;
      p.why_undetermined =
          spiked ? "the fit does not explain the records (a residual sample far beyond the noise)"
                 : "the fit does not explain the records (a residual above the noise, not white)";
    } else if (!result.credible && p.test.empty()) {
      // Not white or above the noise, though within what chi^2 lets pass: a model that lacks
      // something leaves such a residual too (a hanger's mass 30 % off: chi^2/dof 0.94 under an
      // identification's noise 20 % high, correlation time 5 samples, c_q1 3046 stds off).
      // Which of the two, in numbers: a trial's coloured sensor noise (chi^2/dof 0.99) read as
      // "above the noise".
      p.determined = false;
      p.why_undetermined =
          excess > kNoticeableExcess
              ? fmt::format(
                    "the fit is not credible: its residual is {:.3g} times the records' "
                    "noise (standard deviations scaled up by {:.3g}), as a model that "
                    "lacks something leaves it",
                    std::sqrt(excess), result.std_inflation)
              : fmt::format(
                    "the fit is not credible: its residual is at the records' noise (chi^2/dof "
                    "= {:.3g}) but not white (correlation time {:.3g} samples on {}; standard "
                    "deviations scaled up by {:.3g}): a model that lacks something leaves such a "
                    "residual, and so does coloured sensor noise (an oversampled record through "
                    "an anti-alias filter); the records cannot tell which",
                    result.chi_square_per_dof, worst_time, worst_channel, result.std_inflation);
    } else if (!MarkIfSpreadUndetermined(p, result.std_inflation, options.undetermined_relative_std,
                                         &result) &&
               !p.determined && p.why_undetermined.empty()) {
      p.why_undetermined = "marked by the caller";
    }
    if (!p.determined) result.undetermined.push_back(p.name);
  }
}

bool MarkIfSpreadUndetermined(ParameterEstimate& p, double std_inflation,
                              double undetermined_relative_std, const UpdateResult* within) {
  const double relative = p.relative_std * std_inflation;
  if (!std::isfinite(relative)) {
    p.why_undetermined = "no standard deviation: the records leave it in a flat direction";
  } else if (relative > undetermined_relative_std) {
    p.why_undetermined =
        fmt::format("relative std {:.3g}{} above {}{}", relative,
                    std_inflation > 1.01 ? " (inflated)" : "", undetermined_relative_std,
                    within != nullptr ? PartnerInACombination(*within, p) : std::string());
  } else if (p.lower < p.upper && (p.interval_lower <= p.lower || p.interval_upper >= p.upper)) {
    // The records allow values up to the bound (and maybe beyond): the bound, not the data,
    // decides where the estimate ends.
    const bool low = p.interval_lower <= p.lower;
    p.why_undetermined = fmt::format(
        "its interval [{:.4g}, {:.4g}] reaches the {} bound {:.4g}: the records do not bound it "
        "within the allowed range",
        p.interval_lower, p.interval_upper, low ? "lower" : "upper", low ? p.lower : p.upper);
  } else {
    return false;
  }
  p.determined = false;
  return true;
}

}  // namespace mbid::updating
