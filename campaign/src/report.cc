#include "report.h"

#include <fmt/format.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>

#include "mbid/campaign/campaign_case.h"
#include "mbid/common/atomic_file.h"
#include "mbid/report/gnuplot.h"
#include "units.h"

namespace mbid::campaign::internal {
using report::DrawFigure;
using report::Figure;
using report::GnuplotAvailable;
using report::PlotSeries;

namespace {

namespace fs = std::filesystem;

constexpr size_t kMaxFailuresListed = 20;
constexpr int kMaxModesPlotted = 8;

std::string TableCell(std::string text) {
  for (char& c : text) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  std::string escaped;
  for (char c : text) {
    if (c == '|') escaped += '\\';
    escaped += c;
  }
  return escaped;
}

// The first swept key with numbers in every ok case and at least two distinct values.
std::string NumericSweptKey(const Campaign& campaign,
                            const std::vector<nlohmann::ordered_json>& rows) {
  for (const std::string& key : campaign.swept_keys) {
    std::set<double> values;
    bool numeric = true;
    for (const auto& row : rows) {
      if (row["status"] != "ok") continue;
      const double value = RowNumber(row, key);
      if (!std::isfinite(value)) numeric = false;
      values.insert(value);
    }
    if (numeric && values.size() >= 2) return key;
  }
  return "";
}

// One series per mode: the cases' values of `<prefix>mode<k>.<quantity>` against `x_key`.
std::vector<PlotSeries> ModeSeries(const std::vector<nlohmann::ordered_json>& rows,
                                   const std::string& x_key, const std::string& prefix,
                                   const std::string& quantity, const std::string& label,
                                   const std::string& style) {
  std::vector<PlotSeries> series;
  for (int k = 1; k <= kMaxModesPlotted; ++k) {
    const std::string column = fmt::format("{}mode{}.{}", prefix, k, quantity);
    std::vector<double> x, y;
    for (const auto& row : rows) {
      if (row["status"] != "ok") continue;
      const double value = RowNumber(row, column);
      if (!std::isfinite(value)) continue;
      x.push_back(RowNumber(row, x_key));
      y.push_back(value);
    }
    if (x.empty()) continue;
    PlotSeries one;
    one.title = fmt::format("mode {} ({})", k, label);
    one.x = Eigen::Map<const Eigen::VectorXd>(x.data(), static_cast<Eigen::Index>(x.size()));
    one.y = Eigen::Map<const Eigen::VectorXd>(y.data(), static_cast<Eigen::Index>(y.size()));
    one.style = fmt::format(style, k);
    series.push_back(one);
  }
  return series;
}

}  // namespace

std::vector<std::string> WriteCampaignReport(const Campaign& campaign,
                                             const std::vector<nlohmann::ordered_json>& rows,
                                             const std::string& folder, const StudyReport& study) {
  report::FigureBatch batch;  // the figures in one gnuplot process, drawn before report.md
  std::map<std::string, int> by_status;
  std::vector<const nlohmann::ordered_json*> failures;
  for (const auto& row : rows) {
    const std::string status = row["status"].get<std::string>();
    ++by_status[status];
    if (status != "ok") failures.push_back(&row);
  }

  std::ostringstream md;
  md << "# Campaign " << campaign.name << "\n\n";
  if (!campaign.description.empty()) md << campaign.description << "\n\n";
  std::vector<std::string> steps{"modes"};
  if (campaign.steps.simulate) steps.push_back("simulate");
  if (campaign.steps.identify) steps.push_back("identify");
  if (campaign.steps.update) steps.push_back("update");
  md << fmt::format("Base scenario `{}`; {} cases; steps: {}; campaign seed {}.\n\n",
                    fs::path(campaign.base_source).filename().string(), rows.size(),
                    fmt::join(steps, ", "), campaign.seed);
  if (!campaign.swept_keys.empty()) {
    md << "Swept: `" << fmt::format("{}", fmt::join(campaign.swept_keys, "`, `")) << "`.\n\n";
  }
  md << "Results: `campaign.h5` (`/cases/<id>/...`, the groups of a run), `summary.csv` (one row "
        "per case).\n\n";
  md << "| status | cases |\n|---|---|\n";
  for (const auto& [status, count] : by_status) md << "| " << status << " | " << count << " |\n";
  md << "\n";
  if (!failures.empty()) {
    md << "## Cases that did not succeed\n\n| case | step | status | reason |\n|---|---|---|---|\n";
    for (size_t i = 0; i < failures.size() && i < kMaxFailuresListed; ++i) {
      const auto& row = *failures[i];
      md << fmt::format("| {} | {} | {} | {} |\n", row["case_id"].get<std::string>(),
                        row["step"].get<std::string>(), row["status"].get<std::string>(),
                        TableCell(row["reason"].get<std::string>()));
    }
    if (failures.size() > kMaxFailuresListed) {
      md << fmt::format("\n... and {} more (summary.csv).\n", failures.size() - kMaxFailuresListed);
    }
    md << "\n";
  }

  std::vector<std::string> figures = study.figures;
  const bool gnuplot = GnuplotAvailable();
  const std::string x_key = NumericSweptKey(campaign, rows);
  if ((!campaign.study || campaign.study->PlotsModesAcrossCases()) && !x_key.empty()) {
    md << "## Modes across the campaign\n\n";
    if (!gnuplot) {
      md << "gnuplot with pngcairo was not found: no figures.\n\n";
    } else {
      const std::string x_label = fmt::format("{}, {}", x_key, UnitOfColumn(x_key));
      const struct {
        std::string quantity, label, y_label, file;
      } plots[] = {
          {"frequency_hz", "Damped frequency of each mode", "damped frequency, Hz",
           "modes_frequency.png"},
          {"damping_ratio", "Damping ratio of each mode", "damping ratio, 1", "modes_damping.png"}};
      for (const auto& plot : plots) {
        Figure figure;
        figure.title = plot.label + " across the campaign";
        figure.x_label = x_label;
        figure.y_label = plot.y_label;
        figure.pad_x = true;
        figure.series =
            ModeSeries(rows, x_key, "exact.", plot.quantity, "exact", "points pt 7 ps 0.8 lc {}");
        // Identified modes need not match the exact ones index for index (a mode the record
        // does not show is missing): one series for all of them.
        PlotSeries identified{"identified (any mode)", {}, {}, "points pt 2 ps 1.3 lc rgb 'black'"};
        for (const PlotSeries& mode :
             ModeSeries(rows, x_key, "identified.", plot.quantity, "identified", "")) {
          Eigen::VectorXd x(identified.x.size() + mode.x.size());
          Eigen::VectorXd y(x.size());
          x << identified.x, mode.x;
          y << identified.y, mode.y;
          identified.x = x;
          identified.y = y;
        }
        if (identified.x.size() > 0) figure.series.push_back(identified);
        figure.key = "outside right top box";
        if (figure.series.empty()) continue;
        DrawFigure(figure, (fs::path(folder) / plot.file).string());
        figures.push_back(plot.file);
        md << "![" << plot.label << "](" << plot.file << ")\n\n";
      }
    }
  }
  md << study.markdown;
  batch.Draw();

  AtomicFile report((fs::path(folder) / "report.md").string());
  {
    std::ofstream out(report.temp_path());
    out << md.str();
    if (!out) throw std::runtime_error("cannot write " + report.path());
  }
  report.Commit();
  return figures;
}

}  // namespace mbid::campaign::internal
