#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>

#include "mbid/campaign/damper_sizing.h"
#include "mbid/report/gnuplot.h"
#include "vectors.h"

namespace mbid::campaign {
using report::DrawFigure;
using report::Figure;
using report::GnuplotAvailable;
using report::PlotSeries;

namespace {

namespace fs = std::filesystem;

using internal::ToVector;

// The x range of a joint's figures: its sweep, padded on a log axis.
std::string XRange(const DamperSizingSpec& spec, const JointSizing& joint) {
  const double d_low = joint.damping_Nms_per_rad.minCoeff();
  const double d_high = joint.damping_Nms_per_rad.maxCoeff();
  return spec.log_spacing ? fmt::format("[{}:{}]", d_low / 1.25, d_high * 1.25)
                          : fmt::format("[{}:{}]", d_low, d_high);
}

// The absolute bands, channel by channel in its unit's key.
std::string SettlingBands(const DamperSizingSpec& spec) {
  std::vector<std::string> bands;
  for (const auto& [channel, band] : spec.settling_bands) {
    bands.push_back(fmt::format("{} {} {}", channel, band, spec.settling_band_units.at(channel)));
  }
  return fmt::format("{}", fmt::join(bands, ", "));
}

// A vertical line at the smallest damping that meets `target`, if one does.
void AddSmallestMarker(const JointSizing& joint, const std::string& target, double y_low,
                       double y_high, std::vector<PlotSeries>* series) {
  for (size_t t = 0; t < joint.targets.size(); ++t) {
    if (joint.targets[t] != target || !std::isfinite(joint.smallest_Nms_per_rad[t])) continue;
    const double d = joint.smallest_Nms_per_rad[t];
    series->push_back({fmt::format("smallest d = {:.4g} N*m*s/rad", d), Eigen::Vector2d(d, d),
                       Eigen::Vector2d(y_low, y_high), "lines dt 2 lw 2 lc rgb '#2ca02c'"});
  }
}

// The damping ratio of every mode against d_joint; returns the PNG's name in `folder`.
// The axes both figures of a joint's damper sweep share: d_<joint> along x, `quantity` up.
Figure DampingSweepFigure(const DamperSizingSpec& spec, const JointSizing& joint,
                          const std::string& quantity, const std::string& y_label) {
  Figure figure;
  figure.title = fmt::format("{} vs d_{}", quantity, joint.joint);
  figure.x_label = fmt::format("d_{}, N*m*s/rad", joint.joint);
  figure.y_label = y_label;
  figure.log_x = spec.log_spacing;
  figure.x_range = XRange(spec, joint);
  figure.y_range = "[0:*]";
  figure.key = "outside right top box";
  return figure;
}

std::string DrawDampingRatioFigure(const DamperSizingSpec& spec, const JointSizing& joint,
                                   const std::string& folder) {
  const Eigen::Index n = joint.damping_Nms_per_rad.size();
  const double d_low = joint.damping_Nms_per_rad.minCoeff();
  const double d_high = joint.damping_Nms_per_rad.maxCoeff();
  Figure figure =
      DampingSweepFigure(spec, joint, "Damping ratio of every mode", "damping ratio, 1");
  for (Eigen::Index k = 0; k < joint.damping_ratio.cols(); ++k) {
    std::vector<double> x, y;
    for (Eigen::Index i = 0; i < n; ++i) {
      if (!std::isfinite(joint.damping_ratio(i, k))) continue;
      x.push_back(joint.damping_Nms_per_rad[i]);
      y.push_back(joint.damping_ratio(i, k));
    }
    if (x.empty()) continue;
    figure.series.push_back(
        {fmt::format("mode {}", k + 1), ToVector(x), ToVector(y), "linespoints pt 7 ps 0.6"});
  }
  if (spec.min_damping_ratio > 0) {
    figure.series.push_back(
        {fmt::format("target {}", spec.min_damping_ratio), Eigen::Vector2d(d_low, d_high),
         Eigen::Vector2d::Constant(spec.min_damping_ratio), "lines dt 3 lw 2 lc rgb 'black'"});
    double top = spec.min_damping_ratio;
    for (Eigen::Index i = 0; i < joint.damping_ratio.size(); ++i) {
      if (std::isfinite(joint.damping_ratio.data()[i])) {
        top = std::max(top, joint.damping_ratio.data()[i]);
      }
    }
    AddSmallestMarker(joint, "min_damping_ratio", 0.0, top, &figure.series);
  }
  const std::string name = fmt::format("damping_ratio_vs_d_{}.png", joint.joint);
  DrawFigure(figure, (fs::path(folder) / name).string());
  return name;
}

// The settling time against d_joint; returns the PNG's name in `folder`. `all_plotted` is false
// when some damping's outputs did not settle within the record (those points are left out).
std::string DrawSettlingTimeFigure(const DamperSizingSpec& spec, const JointSizing& joint,
                                   const std::string& folder, bool* all_plotted) {
  const Eigen::Index n = joint.damping_Nms_per_rad.size();
  const double d_low = joint.damping_Nms_per_rad.minCoeff();
  const double d_high = joint.damping_Nms_per_rad.maxCoeff();
  Figure figure =
      DampingSweepFigure(spec, joint, "Settling time of the outputs", "settling time, s");
  std::vector<double> x, y;
  double y_max = spec.max_settling_time_s;
  for (Eigen::Index i = 0; i < n; ++i) {
    if (!std::isfinite(joint.settling_time_s[i])) continue;
    x.push_back(joint.damping_Nms_per_rad[i]);
    y.push_back(joint.settling_time_s[i]);
    y_max = std::max(y_max, y.back());
  }
  figure.series.push_back({"settling time (cases)", ToVector(x), ToVector(y),
                           "linespoints pt 7 ps 0.6 lc rgb '#1f77b4'"});
  figure.series.push_back(
      {fmt::format("target {} s", spec.max_settling_time_s), Eigen::Vector2d(d_low, d_high),
       Eigen::Vector2d::Constant(spec.max_settling_time_s), "lines dt 3 lw 2 lc rgb 'black'"});
  AddSmallestMarker(joint, "max_settling_time_s", 0.0, y_max, &figure.series);
  const std::string name = fmt::format("settling_time_vs_d_{}.png", joint.joint);
  DrawFigure(figure, (fs::path(folder) / name).string());
  *all_plotted = static_cast<Eigen::Index>(x.size()) == n;
  return name;
}

}  // namespace

std::string DamperSizingReport(const DamperSizingSpec& spec, const DamperSizingResult& result,
                               const std::string& folder, std::vector<std::string>* figures) {
  std::ostringstream md;
  md << "## Damper sizing\n\n";
  md << "Each joint's damping `d_k` alone is swept over its range (the other joints keep the "
        "base scenario's values); the smallest admissible `d_k` is refined by bisection between "
        "the last sweep point that fails a target and the first that meets it, and so is the "
        "largest "
        "of the window of dampings that meet it from there; where no sweep point meets a target, "
        "the model is searched between the sweep's best points. A settling time counts only "
        "when the outputs stay in their band for a period of the slowest mode before the record "
        "ends.\n\nTargets: ";
  std::vector<std::string> targets;
  if (spec.min_damping_ratio > 0) {
    targets.push_back(fmt::format("smallest modal damping ratio >= {}", spec.min_damping_ratio));
  }
  if (spec.has_settling_target()) {
    targets.push_back(fmt::format(
        "settling time <= {} s (band: {})", spec.max_settling_time_s,
        spec.settling_bands.empty()
            ? fmt::format("{} of each output's peak deviation", spec.settling_band_fraction)
            : SettlingBands(spec)));
  }
  md << fmt::format("{}.\n\n", fmt::join(targets, "; "));
  md << "| joint | target | smallest d, N*m*s/rad | largest d, N*m*s/rad | how |\n"
        "|---|---|---|---|---|\n";
  for (const JointSizing& joint : result.joints) {
    for (size_t t = 0; t < joint.targets.size(); ++t) {
      const double d = joint.smallest_Nms_per_rad[t];
      const double up_to = joint.largest_Nms_per_rad[t];
      md << fmt::format("| {} | {} | {} | {} | {} |\n", joint.joint, joint.targets[t],
                        std::isfinite(d) ? fmt::format("{:.6g}", d) : "not met",
                        std::isfinite(up_to) ? fmt::format("{:.6g}", up_to) : "", joint.notes[t]);
    }
  }
  md << "\n";
  if (!GnuplotAvailable()) {
    md << "gnuplot with pngcairo was not found: no figures.\n\n";
    return md.str();
  }
  for (const JointSizing& joint : result.joints) {
    if (joint.damping_Nms_per_rad.size() == 0) continue;
    const std::string ratio = DrawDampingRatioFigure(spec, joint, folder);
    figures->push_back(ratio);
    md << "![Damping ratio vs d_" << joint.joint << "](" << ratio << ")\n\n";
    if (spec.has_settling_target()) {
      bool all_plotted = true;
      const std::string settling = DrawSettlingTimeFigure(spec, joint, folder, &all_plotted);
      figures->push_back(settling);
      md << "![Settling time vs d_" << joint.joint << "](" << settling << ")\n\n";
      if (!all_plotted) {
        md << "Dampings whose outputs did not settle within the record are not plotted.\n\n";
      }
    }
  }
  return md.str();
}

}  // namespace mbid::campaign
