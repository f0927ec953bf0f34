#include "mbid/report/structure_report.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "mbid/common/atomic_file.h"
#include "mbid/common/error.h"
#include "mbid/common/hdf5_io.h"
#include "mbid/common/json_io.h"
#include "mbid/report/gnuplot.h"

namespace mbid::report {
namespace {

namespace fs = std::filesystem;

// The first line of every structure report: how mbid tells its own report from a user's file.
constexpr const char* kReportMarker = "<!-- mbid structure report -->";

std::string Cell(double value, const char* format = "{:.6g}") {
  return std::isfinite(value) ? fmt::format(fmt::runtime(format), value) : std::string("-");
}

std::string Rigid(const updating::StructureFit& fit) {
  if (!fit.description.empty())
    return "alternative " + fs::path(fit.description).filename().string();
  return fit.rigid.empty() ? std::string("none (full model)")
                           : fmt::format("{}", fmt::join(fit.rigid, ", "));
}

bool IsOurReport(const fs::path& markdown) {
  std::ifstream in(markdown);
  std::string first;
  return in && std::getline(in, first) && first == kReportMarker;
}

}  // namespace

nlohmann::json StructureRankingToJson(const updating::StructureRanking& ranking,
                                      const std::vector<std::string>& records) {
  nlohmann::json structures = nlohmann::json::array();
  for (const updating::StructureFit& fit : ranking.structures) {
    nlohmann::json item;
    item["rank"] = fit.rank;
    item["name"] = fit.name;
    item["rigid"] = fit.rigid;
    if (!fit.description.empty()) item["description"] = fit.description;
    item["coordinates"] = fit.coordinates;
    nlohmann::json parameters = nlohmann::json::object();
    nlohmann::json parameter_std = nlohmann::json::object();
    for (const updating::ParameterEstimate& p : fit.fit.parameters) {
      // A nuisance parameter's name already carries its test ("<test>:payload_mass_kg").
      const std::string& name = p.name;
      parameters[name] = NumberOrNull(p.value);
      parameter_std[name] = NumberOrNull(p.std);
    }
    item["parameters"] = parameters;
    item["parameter_std"] = parameter_std;
    item["undetermined"] = fit.fit.undetermined;
    item["parameter_count"] = fit.parameter_count;
    item["residual_count"] = fit.residual_count;
    item["cost"] = NumberOrNull(fit.cost);
    item["aic"] = NumberOrNull(fit.aic);
    item["bic"] = NumberOrNull(fit.bic);
    item["delta_bic"] = NumberOrNull(fit.delta_bic);
    item["prediction_error"] = NumberOrNull(fit.prediction_error);
    nlohmann::json per_record = nlohmann::json::array();
    for (double value : fit.prediction_error_per_record) per_record.push_back(NumberOrNull(value));
    item["prediction_error_per_record"] = per_record;
    item["termination"] = fit.skipped.empty() ? fit.fit.termination_name() : "skipped";
    if (!fit.skipped.empty()) item["skipped"] = fit.skipped;
    nlohmann::json correlation = nlohmann::json::object();
    for (const updating::TestFit& test : fit.fit.tests) {
      for (size_t c = 0; c < test.channels.size(); ++c) {
        correlation[test.name][test.channels[c]] =
            NumberOrNull(test.correlation[static_cast<Eigen::Index>(c)]);
      }
    }
    item["correlation"] = correlation;
    structures.push_back(item);
  }
  nlohmann::json noise = nlohmann::json::array();
  for (const auto& channels : ranking.noise_std) noise.push_back(channels);
  const updating::GlobalSearchResult& search = ranking.reference_search;
  return {{"structures", structures},
          {"criterion", "bic"},
          {"records", records},
          {"noise_std", noise},
          {"reference_search",
           {{"starts", search.starts},
            {"screened", search.screened},
            {"full_fits", search.full_fits},
            {"non_unique", search.non_unique},
            {"notes", search.notes}}},
          {"wall_time_s", ranking.wall_time_s}};
}

std::string StructureTable(const updating::StructureRanking& ranking) {
  std::string table =
      "| rank | rigid | coordinates | k | cost | AIC | BIC | delta BIC | prediction error |\n"
      "|---:|---|---|---:|---:|---:|---:|---:|---:|\n";
  for (const updating::StructureFit& fit : ranking.structures) {
    table += fmt::format("| {} | {} | {} | {} | {} | {} | {} | {} | {} |\n", fit.rank, Rigid(fit),
                         fmt::join(fit.coordinates, ", "), fit.parameter_count, Cell(fit.cost),
                         Cell(fit.aic), Cell(fit.bic), Cell(fit.delta_bic, "{:.4g}"),
                         Cell(fit.prediction_error, "{:.4g}"));
  }
  for (const updating::StructureFit& fit : ranking.structures) {
    if (!fit.skipped.empty()) {
      table += fmt::format("\n- {}: not ranked: {}\n", fit.name, fit.skipped);
    } else if (fit.fit.termination != updating::UpdateResult::Termination::kConverged) {
      // Its cost is where the fit stopped, not its minimum: an upper bound of what it can reach.
      table += fmt::format(
          "\n- {}: its fit stopped before converging ({} after {} iterations): its cost and "
          "criteria are upper bounds, its rank may be too low\n",
          fit.name, fit.fit.termination_name(), fit.fit.iterations);
    }
  }
  if (!ranking.structures.empty() && ranking.structures.front().skipped.empty() &&
      !ranking.structures.front().fit.undetermined.empty()) {
    // The records barely move those joints: the winner is the structure with fewest parameters
    // they leave free, which says nothing of whether the joints are rigid or compliant.
    const updating::StructureFit& best = ranking.structures.front();
    table += fmt::format(
        "\n- {} (ranked first): its fit leaves {} undetermined: the records hardly move those "
        "joints, so the ranking does not show whether they are compliant or rigid; a test that "
        "moves them decides it (mbid plan)\n",
        best.name, fmt::join(best.fit.undetermined, ", "));
  }
  return table;
}

StructureReportPaths ReportPathsBeside(const std::string& h5_path) {
  fs::path stem(h5_path);
  stem.replace_extension();
  return {stem.string() + ".md", stem.string() + "-criteria.png"};
}

void CheckReportPaths(const StructureReportPaths& paths) {
  // The markdown file is ours when it starts with the marker; the figure when the markdown
  // beside it is ours (an earlier run wrote both).
  const bool markdown_exists = fs::exists(fs::symlink_status(paths.markdown));
  const bool ours =
      markdown_exists && fs::is_regular_file(paths.markdown) && IsOurReport(paths.markdown);
  if (markdown_exists && !ours) {
    throw InputError(paths.markdown, "", "exists and is not a structure report of mbid",
                     "another -o name, or move the file away (mbid does not overwrite it)");
  }
  if (fs::exists(fs::symlink_status(paths.figure)) &&
      (!ours || !fs::is_regular_file(paths.figure))) {
    throw InputError(paths.figure, "", "exists and is not a figure of an earlier structure report",
                     "another -o name, or move the file away (mbid does not overwrite it)");
  }
}

void WriteStructureReport(const updating::StructureRanking& ranking,
                          const std::string& scenario_name, const std::vector<std::string>& records,
                          const StructureReportPaths& paths) {
  std::string note;
  if (GnuplotAvailable()) {
    Figure figure;
    figure.title = "Structures ranked: information criteria above the best";
    figure.x_label = "rank (table of the report)";
    figure.y_label = "criterion - best + 1";
    figure.log_y = true;
    figure.key = "bottom right box opaque";
    figure.pad_x = true;
    const Eigen::Index n = static_cast<Eigen::Index>(ranking.structures.size());
    double best_aic = INFINITY;
    for (const auto& fit : ranking.structures) {
      if (std::isfinite(fit.aic)) best_aic = std::min(best_aic, fit.aic);
    }
    PlotSeries bic{"BIC", {}, {}, "linespoints pt 7 ps 1.2"};
    PlotSeries aic{"AIC", {}, {}, "linespoints pt 5 ps 0.9"};
    std::vector<double> xs, bs, as;
    for (Eigen::Index i = 0; i < n; ++i) {
      const auto& fit = ranking.structures[static_cast<size_t>(i)];
      if (!std::isfinite(fit.bic)) continue;
      xs.push_back(fit.rank);
      bs.push_back(fit.delta_bic + 1);
      as.push_back(fit.aic - best_aic + 1);
    }
    bic.x = aic.x =
        Eigen::Map<const Eigen::VectorXd>(xs.data(), static_cast<Eigen::Index>(xs.size()));
    bic.y = Eigen::Map<const Eigen::VectorXd>(bs.data(), static_cast<Eigen::Index>(bs.size()));
    aic.y = Eigen::Map<const Eigen::VectorXd>(as.data(), static_cast<Eigen::Index>(as.size()));
    figure.series = {bic, aic};
    figure.x_range = fmt::format("[0.5:{}]", static_cast<double>(n) + 0.5);
    figure.pad_x = false;
    DrawFigure(figure, paths.figure);
  } else {
    note = "(The figure was not drawn: gnuplot with the pngcairo terminal is not installed.)\n\n";
  }

  std::string text = std::string(kReportMarker) + "\n";
  text += fmt::format("# Structural identification: {}\n\n", scenario_name);
  text += fmt::format(
      "Records: {}. Every candidate fitted by Route 2 with the noise weights of the "
      "full model's fit; ranked by BIC = 2 cost + k ln N (lower is better), AIC = "
      "2 cost + 2 k beside it.{}\n\n",
      fmt::join(records, ", "),
      records.size() > 1 ? " Prediction error: weighted rms residual of each record predicted by "
                           "a fit to the others (about 1 = the noise level)."
                         : " Prediction error needs two or more records.");
  text += StructureTable(ranking);
  if (!ranking.structures.empty()) {
    const auto& best = ranking.structures.front();
    text += fmt::format("\nBest: rigid {}, degrees of freedom {}.", Rigid(best),
                        fmt::join(best.coordinates, ", "));
    if (ranking.structures.size() > 1 && std::isfinite(ranking.structures[1].delta_bic)) {
      text += fmt::format(" The runner-up's BIC is {:.3g} higher ({}).",
                          ranking.structures[1].delta_bic,
                          ranking.structures[1].delta_bic > 10  ? "very strong evidence"
                          : ranking.structures[1].delta_bic > 6 ? "strong evidence"
                          : ranking.structures[1].delta_bic > 2 ? "positive evidence"
                                                                : "not decisive");
    }
    text += "\n\n";
  }
  text += note;
  if (note.empty()) {
    text += fmt::format("![criteria]({})\n", fs::path(paths.figure).filename().string());
  }
  AtomicFile markdown(paths.markdown);
  {
    std::ofstream out(markdown.temp_path());
    out << text;
  }
  markdown.Commit();
}

}  // namespace mbid::report

namespace mbid::report {

void WriteStructureGroup(H5Writer& file, const updating::StructureRanking& ranking) {
  const Eigen::Index n = static_cast<Eigen::Index>(ranking.structures.size());
  Eigen::VectorXd rank(n), cost(n), aic(n), bic(n), delta_bic(n), prediction(n), k(n), N(n);
  std::vector<std::string> name, rigid, coordinates, termination, skipped;
  for (Eigen::Index i = 0; i < n; ++i) {
    const updating::StructureFit& fit = ranking.structures[static_cast<size_t>(i)];
    rank[i] = fit.rank;
    cost[i] = fit.cost;
    aic[i] = fit.aic;
    bic[i] = fit.bic;
    delta_bic[i] = fit.delta_bic;
    prediction[i] = fit.prediction_error;
    k[i] = fit.parameter_count;
    N[i] = static_cast<double>(fit.residual_count);
    name.push_back(fit.name);
    rigid.push_back(fmt::format("{}", fmt::join(fit.rigid, ",")));
    coordinates.push_back(fmt::format("{}", fmt::join(fit.coordinates, ",")));
    termination.push_back(fit.skipped.empty() ? fit.fit.termination_name() : "skipped");
    skipped.push_back(fit.skipped);

    const std::string group = fmt::format("/structure/candidates/{}", fit.rank);
    std::vector<std::string> parameters;
    Eigen::VectorXd values(static_cast<Eigen::Index>(fit.fit.parameters.size()));
    Eigen::VectorXd stds(values.size());
    for (size_t p = 0; p < fit.fit.parameters.size(); ++p) {
      const updating::ParameterEstimate& estimate = fit.fit.parameters[p];
      parameters.push_back(estimate.name);  // a nuisance one's name carries its test
      values[static_cast<Eigen::Index>(p)] = estimate.value;
      stds[static_cast<Eigen::Index>(p)] = estimate.std;
    }
    file.WriteStringAttribute(group, "name", fit.name);
    file.WriteStrings(group, "parameter", parameters);
    // Units differ per parameter (N*m/rad, N*m*s/rad, N/m, kg): listed beside the names.
    std::vector<std::string> units;
    for (const auto& estimate : fit.fit.parameters) units.push_back(estimate.units);
    file.WriteStrings(group, "parameter_units", units);
    file.WriteVector(group, "value", values, "see parameter_units");
    file.WriteVector(group, "std", stds, "see parameter_units");
    if (!fit.prediction_error_per_record.empty()) {
      file.WriteVector(group, "prediction_error_per_record",
                       Eigen::Map<const Eigen::VectorXd>(
                           fit.prediction_error_per_record.data(),
                           static_cast<Eigen::Index>(fit.prediction_error_per_record.size())),
                       "1");
    }
  }
  file.WriteStringAttribute("/structure", "criterion", "bic");
  file.WriteVector("/structure", "rank", rank, "1");
  file.WriteStrings("/structure", "name", name);
  file.WriteStrings("/structure", "rigid", rigid);
  file.WriteStrings("/structure", "coordinates", coordinates);
  file.WriteStrings("/structure", "termination", termination);
  file.WriteStrings("/structure", "skipped", skipped);
  file.WriteVector("/structure", "cost", cost, "1");
  file.WriteVector("/structure", "aic", aic, "1");
  file.WriteVector("/structure", "bic", bic, "1");
  file.WriteVector("/structure", "delta_bic", delta_bic, "1");
  file.WriteVector("/structure", "prediction_error", prediction, "1");
  file.WriteVector("/structure", "parameter_count", k, "1");
  file.WriteVector("/structure", "residual_count", N, "1");
}

}  // namespace mbid::report
