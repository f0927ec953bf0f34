#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>

#include "mbid/campaign/campaign_case.h"
#include "mbid/campaign/laws.h"
#include "mbid/report/gnuplot.h"
#include "units.h"
#include "vectors.h"

namespace mbid::campaign {
using report::DrawFigure;
using report::Figure;
using report::GnuplotAvailable;

namespace {

namespace fs = std::filesystem;

constexpr int kMaxCurves = 4;  // curves per figure for the other variables' values
constexpr int kCurvePoints = 101;

using internal::ToVector;

// The cases' values of the law's quantity against its first variable, the law and its
// +-2 std band, drawn into `path`.
void DrawLawFigure(const LawsSpec& spec, const PolynomialLaw& law, const std::string& unit,
                   const std::vector<nlohmann::ordered_json>& rows, const std::string& path) {
  // Data against the first variable; curves for the other variables' values.
  const std::string& x_key = law.variables.front();
  std::vector<double> data_x, data_y;
  std::vector<Eigen::VectorXd> others;  // distinct values of the other variables
  for (const auto& row : rows) {
    if (row["status"] != "ok") continue;
    Eigen::VectorXd x(static_cast<Eigen::Index>(law.variables.size()));
    for (size_t i = 0; i < law.variables.size(); ++i) {
      x[static_cast<Eigen::Index>(i)] = RowNumber(row, law.variables[i]);
    }
    const double y = RowNumber(row, law.quantity);
    if (!x.allFinite() || !std::isfinite(y)) continue;
    data_x.push_back(x[0]);
    data_y.push_back(y);
    const Eigen::VectorXd rest = x.tail(x.size() - 1);
    const bool seen = std::any_of(others.begin(), others.end(),
                                  [&](const Eigen::VectorXd& o) { return o == rest; });
    if (!seen) others.push_back(rest);
  }
  if (others.size() > static_cast<size_t>(kMaxCurves)) {
    Eigen::VectorXd mean = Eigen::VectorXd::Zero(others.front().size());
    for (const auto& o : others) mean += o / static_cast<double>(others.size());
    others = {mean};
  }
  Figure figure;
  figure.title = fmt::format("{} vs {}: cases and fitted law (degree {})", law.quantity,
                             internal::ShortName(x_key), spec.degree);
  figure.x_label = fmt::format("{}, {}", x_key, internal::UnitOfColumn(x_key));
  figure.y_label = fmt::format("{}, {}", law.quantity, unit);
  figure.pad_x = true;
  figure.series.push_back(
      {"cases", ToVector(data_x), ToVector(data_y), "points pt 7 ps 0.8 lc rgb '#1f77b4'"});
  const double low = *std::min_element(data_x.begin(), data_x.end());
  const double high = *std::max_element(data_x.begin(), data_x.end());
  for (const Eigen::VectorXd& rest : others) {
    Eigen::VectorXd xs(kCurvePoints), fit(kCurvePoints), lower(kCurvePoints), upper(kCurvePoints);
    for (int i = 0; i < kCurvePoints; ++i) {
      Eigen::VectorXd x(static_cast<Eigen::Index>(law.variables.size()));
      x[0] = low + (high - low) * i / (kCurvePoints - 1);
      x.tail(x.size() - 1) = rest;
      xs[i] = x[0];
      fit[i] = law.Evaluate(x);
      const double std = law.CalcStd(x);
      lower[i] = fit[i] - 2 * std;
      upper[i] = fit[i] + 2 * std;
    }
    std::string label = "law";
    for (Eigen::Index i = 0; i < rest.size(); ++i) {
      label += fmt::format(" at {} = {:.4g}",
                           internal::ShortName(law.variables[static_cast<size_t>(i + 1)]), rest[i]);
    }
    figure.series.push_back({label, xs, fit, "lines lw 2"});
    if (others.size() == 1 && std::isfinite(upper[0])) {
      figure.series.push_back({"law +- 2 std", xs, lower, "lines dt 2 lc rgb 'gray40'"});
      figure.series.push_back({"", xs, upper, "lines dt 2 lc rgb 'gray40'"});
    }
  }
  DrawFigure(figure, path);
}

}  // namespace

std::string LawsReport(const LawsSpec& spec, const std::vector<PolynomialLaw>& laws,
                       const std::vector<nlohmann::ordered_json>& rows, const std::string& folder,
                       std::vector<std::string>* figures) {
  std::ostringstream md;
  md << "## Laws: how the parameters change with the operating condition\n\n";
  md << fmt::format(
      "Each quantity is fitted over the successful cases as a polynomial of total degree {} in "
      "`{}` by least squares. Where the cases give their own standard deviations (fitted and "
      "identified values) each case is weighted by them and the coefficients' standard "
      "deviations follow from them (inflated by chi^2 per degree of freedom above 1); "
      "otherwise the errors are taken as independent and of equal variance, estimated from the "
      "residuals (s^2 = RSS / (N - P)).\n\n",
      spec.degree, fmt::join(spec.variables, "`, `"));
  const bool gnuplot = GnuplotAvailable();
  for (size_t q = 0; q < laws.size(); ++q) {
    const PolynomialLaw& law = laws[q];
    const std::string unit = law.units.empty() ? internal::UnitOfColumn(law.quantity) : law.units;
    md << "### " << law.quantity << " (" << unit << ")\n\n";
    if (law.status != "ok") {
      md << "Not fitted: " << law.status << ".\n\n";
      continue;
    }
    md << "| term | coefficient | std |\n|---|---|---|\n";
    for (Eigen::Index j = 0; j < law.coefficients.size(); ++j) {
      md << fmt::format("| {} | {:.6g} | {:.3g} |\n", law.TermName(static_cast<int>(j)),
                        law.coefficients[j], law.std[j]);
    }
    md << fmt::format("\n{} cases; residual std {:.4g} {}; R^2 = {:.6f}.", law.samples,
                      law.residual_std, unit, law.r_squared);
    if (law.left_out_undetermined > 0) {
      md << fmt::format(" {} case(s) left out: their records do not determine the value.",
                        law.left_out_undetermined);
    }
    if (law.weighted) {
      md << fmt::format(
          " Weighted by the cases' standard deviations: chi^2 per degree of "
          "freedom {:.3g}",
          law.chi_square_per_dof);
      md << (law.lack_of_fit
                 ? fmt::format("; **the law misses the cases by {:.2g} times their standard "
                               "deviations: a polynomial of degree {} in these variables does "
                               "not describe them** (the coefficients' stds are inflated by it)",
                               std::sqrt(law.chi_square_per_dof), spec.degree)
                 : std::string())
         << ".";
    }
    md << "\n\n";
    if (!gnuplot) continue;

    const std::string name = fmt::format("law_{}.png", q + 1);
    DrawLawFigure(spec, law, unit, rows, (fs::path(folder) / name).string());
    figures->push_back(name);
    md << "![" << law.quantity << "](" << name << ")\n\n";
  }
  return md.str();
}

}  // namespace mbid::campaign
