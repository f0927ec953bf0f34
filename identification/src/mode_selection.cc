#include "mode_selection.h"

#include <fmt/format.h>

#include <algorithm>

#include "mbid/identification/significance.h"

namespace mbid::identification {
namespace {

// A noiseless record's residual is round-off, against which any component is "significant":
// poles found to 1e-10 leave components of about that relative size. A mode smaller than
// kRoundOffAmplitude of every channel's RMS carries nothing and gets significance 0.
constexpr double kRoundOffAmplitude = 1e-8;

void ZeroRoundOffModes(const AnalysisRecord& record, const AmplitudeFit& fit,
                       Eigen::VectorXd* significance) {
  const Eigen::VectorXd rms =
      (record.decimated.colwise().squaredNorm().transpose() / record.decimated.rows()).cwiseSqrt();
  for (Eigen::Index k = 0; k < significance->size(); ++k) {
    bool round_off = true;
    for (Eigen::Index c = 0; c < rms.size(); ++c) {
      round_off = round_off && fit.Amplitude(static_cast<int>(k), static_cast<int>(c)) <=
                                   kRoundOffAmplitude * rms(c);
    }
    if (round_off) (*significance)(k) = 0;
  }
}

}  // namespace

double SignificanceThreshold(const AnalysisRecord& record, const IdentificationOptions& options) {
  if (options.min_significance > 0) return options.min_significance;
  return CalcSignificanceThreshold(static_cast<int>(record.decimated.rows()),
                                   static_cast<int>(record.values.cols()),
                                   options.significance_false_alarm);
}

void SelectSignificant(const AnalysisRecord& record, const IdentificationOptions& options,
                       Estimate* estimate, const std::function<void(Estimate*)>& refit) {
  const bool with_offset = options.offset == OffsetRemoval::kFit;
  const double threshold = SignificanceThreshold(record, options);
  int dropped = 0;
  double largest_dropped = 0;
  const auto note_dropped = [&] {
    if (dropped > 0) {
      estimate->warnings.push_back(fmt::format(
          "dropped {} candidate mode(s) below the significance threshold {:.3g} (largest "
          "dropped: {:.3g})",
          dropped, threshold, largest_dropped));
    }
  };
  for (;;) {
    estimate->fit =
        FitAmplitudes(record.decimated, record.decimated_interval_s, estimate->lambda, with_offset);
    Eigen::VectorXd significance = CalcSignificance(estimate->fit);
    ZeroRoundOffModes(record, estimate->fit, &significance);
    estimate->significance.assign(significance.data(), significance.data() + significance.size());
    if (!options.drop_insignificant) {
      const int weak = static_cast<int>((significance.array() < threshold).count());
      if (weak > 0) {
        estimate->warnings.push_back(fmt::format(
            "{} mode(s) below the significance threshold {:.3g} kept and flagged significant = "
            "false",
            weak, threshold));
      }
      return;
    }
    // Drop the weakest insignificant mode only: two close poles that share one real mode are
    // each insignificant while together they are not.
    Eigen::Index weakest = 0;
    const double smallest = significance.minCoeff(&weakest);
    if (smallest >= threshold) {
      note_dropped();
      return;
    }
    if (estimate->lambda.size() == 1) {
      NoModes(fmt::format(
          "no candidate mode is significant (largest significance {:.3g}, threshold {:.3g}, "
          "significance_false_alarm {}): the record looks like noise",
          std::max(smallest, largest_dropped), threshold, options.significance_false_alarm));
    }
    ++dropped;
    largest_dropped = std::max(largest_dropped, smallest);
    DropModes(&estimate->lambda, [&](size_t k) { return static_cast<Eigen::Index>(k) != weakest; });
    refit(estimate);
  }
}

}  // namespace mbid::identification
