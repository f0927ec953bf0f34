#include "mbid/updating/result_io.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <sstream>
#include <tuple>

#include "mbid/common/json_io.h"
#include "mbid/model/linear_model.h"

namespace mbid::updating {
namespace {

nlohmann::json PerName(const std::vector<std::string>& names, const Eigen::VectorXd& values) {
  nlohmann::json json = nlohmann::json::object();
  for (size_t i = 0; i < names.size() && static_cast<Eigen::Index>(i) < values.size(); ++i) {
    json[names[i]] = NumberOrNull(values[static_cast<Eigen::Index>(i)]);
  }
  return json;
}

std::string ObjectName(std::string name) {
  std::replace(name.begin(), name.end(), '/', '_');
  return name;
}

// The smallest K of each channel over the records.
std::map<std::string, double> WorstCorrelation(const UpdateResult& result) {
  std::map<std::string, double> worst;
  for (const TestFit& test : result.tests) {
    for (size_t c = 0; c < test.channels.size(); ++c) {
      if (test.correlation.size() <= static_cast<Eigen::Index>(c)) continue;
      const double k = test.correlation[static_cast<Eigen::Index>(c)];
      const auto found = worst.find(test.channels[c]);
      if (found == worst.end() || k < found->second) worst[test.channels[c]] = k;
    }
  }
  return worst;
}

// {"<channel>": {"value", "std", "units"}} of a fitted baseline term.
nlohmann::json BaselineTerm(const TestFit& test, const Eigen::VectorXd& value,
                            const Eigen::VectorXd& deviation, const std::string& per) {
  nlohmann::json json = nlohmann::json::object();
  for (size_t c = 0; c < test.channels.size() && static_cast<Eigen::Index>(c) < value.size(); ++c) {
    const Eigen::Index i = static_cast<Eigen::Index>(c);
    const std::string units = c < test.simulated.units.size() ? test.simulated.units[c] : "";
    json[test.channels[c]] = {{"value", NumberOrNull(value[i])},
                              {"std", NumberOrNull(deviation[i])},
                              {"units", units + per}};
  }
  return json;
}

}  // namespace

std::vector<std::string> DescribeBaseline(const TestFit& test) {
  std::vector<std::string> lines;
  for (const auto& [name, value, deviation, per] :
       {std::tuple<const char*, const Eigen::VectorXd*, const Eigen::VectorXd*, const char*>{
            "offset", &test.offset, &test.offset_std, ""},
        {"drift", &test.drift, &test.drift_std, "/s"}}) {
    for (size_t c = 0; c < test.channels.size() && static_cast<Eigen::Index>(c) < value->size();
         ++c) {
      const Eigen::Index i = static_cast<Eigen::Index>(c);
      const std::string units = c < test.simulated.units.size() ? test.simulated.units[c] : "";
      std::ostringstream line;
      line.precision(4);
      line << name << "(" << test.name << ", " << test.channels[c] << ") = " << (*value)[i]
           << " +- " << (*deviation)[i] << " " << units << per;
      lines.push_back(line.str());
    }
  }
  return lines;
}

nlohmann::json CharacteristicResultToJson(const CharacteristicResult& result) {
  nlohmann::json json;
  json["status"] = result.status_name();
  json["message"] = result.message;
  json["starts"] = result.starts;
  json["converged_starts"] = result.converged_starts;
  json["best_residual"] = NumberOrNull(result.best_residual);
  json["chosen"] = result.chosen;
  json["ambiguous"] = result.ambiguous;
  json["poles"] = nlohmann::json::array();
  for (const std::complex<double>& lambda : result.lambda) {
    json["poles"].push_back({{"re", lambda.real()},
                             {"im", lambda.imag()},
                             {"frequency_hz", lambda.imag() / (2 * M_PI)},
                             {"decay_rate_per_s", -lambda.real()}});
  }
  json["sets"] = nlohmann::json::array();
  for (const CharacteristicSolution& set : result.solutions) {
    nlohmann::json entry;
    entry["c"] = PerName(result.coordinates, set.c);
    entry["d"] = PerName(result.coordinates, set.d);
    entry["residual"] = NumberOrNull(set.residual);
    entry["hits"] = set.hits;
    entry["admissible"] = set.admissible;
    if (!set.reason.empty()) entry["reason"] = set.reason;
    if (set.admissible) {
      entry["mismatch"] = NumberOrNull(set.mismatch);
      entry["displacement_mismatch"] = NumberOrNull(set.displacement_mismatch);
      entry["velocity_mismatch"] = NumberOrNull(set.velocity_mismatch);
      if (set.initial_q.size() > 0) {
        entry["initial_q"] = PerName(result.coordinates, set.initial_q);
        entry["initial_u"] = PerName(result.coordinates, set.initial_u);
        entry["correlation"] = PerName(result.outputs, set.correlation);
        entry["shape_misfit"] = NumberOrNull(set.shape_misfit);
        entry["fits_shapes"] = set.fits_shapes;
      }
      if (set.expected_initial_q.size() > 0) {
        entry["expected_initial_q"] = PerName(result.coordinates, set.expected_initial_q);
      }
      if (set.expected_u.size() > 0) {
        // A forced test's: the state expected where its free decay starts.
        entry["expected_time_s"] = set.expected_time_s;
        entry["expected_u"] = PerName(result.coordinates, set.expected_u);
      }
    }
    json["sets"].push_back(entry);
  }
  return json;
}

namespace {

nlohmann::json ProfileToJson(const ParameterProfile& profile) {
  nlohmann::json points = nlohmann::json::array();
  for (size_t i = 0; i < profile.values.size(); ++i) {
    points.push_back({NumberOrNull(profile.values[i]), NumberOrNull(profile.cost_rises[i])});
  }
  nlohmann::json json = {{"interval", nlohmann::json::array({NumberOrNull(profile.lower),
                                                             NumberOrNull(profile.upper)})},
                         {"open", nlohmann::json::array({profile.lower_open, profile.upper_open})},
                         {"threshold", NumberOrNull(profile.threshold)},
                         {"better_minimum", profile.better_minimum},
                         {"points", points},
                         {"fits", profile.fits}};
  if (profile.better_minimum) json["better_value"] = NumberOrNull(profile.better_value);
  if (!profile.failure.empty()) json["failure"] = profile.failure;
  return json;
}

void WriteProfileGroup(H5Writer& file, const std::string& group, const ParameterProfile& profile,
                       const std::string& units) {
  file.WriteScalar(group, "lower", profile.lower, units);
  file.WriteScalar(group, "upper", profile.upper, units);
  file.WriteScalar(group, "threshold", profile.threshold, "1");
  file.WriteStringAttribute(group, "lower_open", profile.lower_open ? "true" : "false");
  file.WriteStringAttribute(group, "upper_open", profile.upper_open ? "true" : "false");
  file.WriteStringAttribute(group, "better_minimum", profile.better_minimum ? "true" : "false");
  file.WriteVector(group, "values",
                   Eigen::Map<const Eigen::VectorXd>(
                       profile.values.data(), static_cast<Eigen::Index>(profile.values.size())),
                   units);
  file.WriteVector(
      group, "cost_rises",
      Eigen::Map<const Eigen::VectorXd>(profile.cost_rises.data(),
                                        static_cast<Eigen::Index>(profile.cost_rises.size())),
      "1");
}

}  // namespace

nlohmann::json UpdateResultToJson(const UpdateResult& result,
                                  const CharacteristicResult* algebraic) {
  nlohmann::json json;
  nlohmann::json parameters = nlohmann::json::object();
  std::vector<std::string> names;
  for (const ParameterEstimate& p : result.parameters) {
    names.push_back(p.name);
    nlohmann::json entry = {{"value", NumberOrNull(p.value)},
                            {"initial", NumberOrNull(p.initial)},
                            {"lower", NumberOrNull(p.lower)},
                            {"upper", NumberOrNull(p.upper)},
                            {"std", NumberOrNull(p.std)},
                            {"units", p.units},
                            {"relative_std", NumberOrNull(p.relative_std)},
                            {"determined", p.determined},
                            {"at_bound", p.at_bound},
                            {"interval", nlohmann::json::array({NumberOrNull(p.interval_lower),
                                                                NumberOrNull(p.interval_upper)})}};
    if (!p.test.empty()) entry["test"] = p.test;
    if (!p.why_undetermined.empty()) entry["why_undetermined"] = p.why_undetermined;
    if (p.profile.computed) entry["profile"] = ProfileToJson(p.profile);
    if (p.std_widening != 1) entry["std_widening"] = NumberOrNull(p.std_widening);
    parameters[p.name] = entry;
  }
  json["parameters"] = parameters;
  json["termination"] = result.termination_name();
  json["iterations"] = result.iterations;
  json["cost"] = {{"initial", NumberOrNull(result.initial_cost)},
                  {"final", NumberOrNull(result.final_cost)}};
  nlohmann::json correlation = nlohmann::json::object();
  for (const auto& [channel, k] : WorstCorrelation(result)) correlation[channel] = NumberOrNull(k);
  json["correlation"] = correlation;

  json["message"] = result.message;
  json["jacobian"] = result.jacobian;
  json["undetermined"] = result.undetermined;
  json["rank"] = result.rank;
  json["singular_values"] = nlohmann::json::array();
  for (Eigen::Index i = 0; i < result.singular_values.size(); ++i) {
    json["singular_values"].push_back(NumberOrNull(result.singular_values[i]));
  }
  nlohmann::json matrix = nlohmann::json::array();
  for (Eigen::Index i = 0; i < result.correlation.rows(); ++i) {
    nlohmann::json row = nlohmann::json::array();
    for (Eigen::Index j = 0; j < result.correlation.cols(); ++j) {
      row.push_back(NumberOrNull(result.correlation(i, j)));
    }
    matrix.push_back(row);
  }
  json["parameter_correlation"] = {{"names", names}, {"matrix", matrix}};
  json["warnings"] = result.warnings;
  json["credibility"] = {{"credible", result.credible},
                         {"chi_square_per_dof", NumberOrNull(result.chi_square_per_dof)},
                         {"weights_from_records", result.weights_from_records},
                         {"explains_records", result.explains_records},
                         {"std_inflation", NumberOrNull(result.std_inflation)},
                         {"reasons", result.credibility}};
  json["tests"] = nlohmann::json::array();
  for (const TestFit& test : result.tests) {
    nlohmann::json estimated = nlohmann::json::object();
    for (size_t c = 0; c < test.channels.size() && c < test.noise_estimated.size(); ++c) {
      estimated[test.channels[c]] = static_cast<bool>(test.noise_estimated[c]);
    }
    nlohmann::json entry = {{"name", test.name},
                            {"correlation", PerName(test.channels, test.correlation)},
                            {"noise_std", PerName(test.channels, test.noise_std)},
                            {"noise_estimated", estimated},
                            {"residual_rms", PerName(test.channels, test.residual_rms)}};
    if (test.correlation_time.size() > 0) {
      entry["whiteness"] = {{"ljung_box_q", PerName(test.channels, test.whiteness_q)},
                            {"p_value", PerName(test.channels, test.whiteness_p)},
                            {"correlation_time", PerName(test.channels, test.correlation_time)}};
    }
    if (test.offset.size() > 0) {
      entry["offset"] = BaselineTerm(test, test.offset, test.offset_std, "");
    }
    if (test.drift.size() > 0)
      entry["drift"] = BaselineTerm(test, test.drift, test.drift_std, "/s");
    json["tests"].push_back(entry);
  }
  json["history"] = nlohmann::json::array();
  for (const IterationRecord& record : result.history) {
    json["history"].push_back({{"iteration", record.iteration},
                               {"cost", NumberOrNull(record.cost)},
                               {"step_norm", NumberOrNull(record.step_norm)},
                               {"gradient_max_norm", NumberOrNull(record.gradient_max_norm)},
                               {"successful", record.successful}});
  }
  json["work"] = {{"simulations", result.simulations},
                  {"sensitivity_simulations", result.sensitivity_simulations},
                  {"rhs_evaluations", result.rhs_evaluations},
                  {"wall_time_s", NumberOrNull(result.wall_time_s)}};
  if (algebraic != nullptr) json["algebraic"] = CharacteristicResultToJson(*algebraic);
  return json;
}

void WriteCharacteristicGroup(H5Writer& file, const CharacteristicResult& result,
                              const std::string& group) {
  file.WriteStringAttribute(group, "status", result.status_name());
  file.WriteStringAttribute(group, "message", result.message);
  file.WriteScalar(group, "chosen", result.chosen, "1");
  file.WriteScalar(group, "ambiguous", result.ambiguous ? 1.0 : 0.0, "1");
  file.WriteScalar(group, "starts", result.starts, "1");
  file.WriteScalar(group, "converged_starts", result.converged_starts, "1");
  file.WriteStrings(group, "coordinates", result.coordinates);
  Eigen::VectorXd re(static_cast<Eigen::Index>(result.lambda.size()));
  Eigen::VectorXd im(re.size());
  for (size_t k = 0; k < result.lambda.size(); ++k) {
    re[static_cast<Eigen::Index>(k)] = result.lambda[k].real();
    im[static_cast<Eigen::Index>(k)] = result.lambda[k].imag();
  }
  file.WriteVector(group, "lambda_re", re, "1/s");
  file.WriteVector(group, "lambda_im", im, "1/s");
  const Eigen::Index sets = static_cast<Eigen::Index>(result.solutions.size());
  const Eigen::Index n = static_cast<Eigen::Index>(result.coordinates.size());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  Eigen::MatrixXd c(sets, n), d(sets, n), q0 = Eigen::MatrixXd::Constant(sets, n, nan);
  Eigen::MatrixXd u0 = q0;
  Eigen::VectorXd residual(sets), admissible(sets), mismatch(sets), displacement(sets),
      velocity(sets), shape_misfit(sets), fits_shapes(sets);
  for (Eigen::Index s = 0; s < sets; ++s) {
    const CharacteristicSolution& set = result.solutions[static_cast<size_t>(s)];
    c.row(s) = set.c.transpose();
    d.row(s) = set.d.transpose();
    if (set.initial_q.size() == n) q0.row(s) = set.initial_q.transpose();
    if (set.initial_u.size() == n) u0.row(s) = set.initial_u.transpose();
    residual[s] = set.residual;
    admissible[s] = set.admissible ? 1.0 : 0.0;
    mismatch[s] = set.admissible ? set.mismatch : nan;
    displacement[s] = set.admissible ? set.displacement_mismatch : nan;
    velocity[s] = set.admissible ? set.velocity_mismatch : nan;
    const bool judged = set.admissible && set.residual_ss.size() > 0;
    shape_misfit[s] = judged ? set.shape_misfit : nan;
    fits_shapes[s] = judged ? (set.fits_shapes ? 1.0 : 0.0) : nan;
  }
  const std::vector<std::string>& units = result.coordinate_units;
  const bool lengths =
      std::any_of(units.begin(), units.end(), [](const std::string& unit) { return unit == "m"; });
  file.WriteMatrix(group, "c", c, model::StiffnessMatrixUnits(units));
  file.WriteMatrix(group, "d", d, model::DampingMatrixUnits(units));
  file.WriteMatrix(group, "initial_q", q0, lengths ? "SI, per coordinate" : "rad");
  file.WriteMatrix(group, "initial_u", u0, lengths ? "SI, per coordinate" : "rad/s");
  file.WriteVector(group, "residual", residual, "1");
  file.WriteVector(group, "admissible", admissible, "1");
  file.WriteVector(group, "mismatch", mismatch, "1");
  file.WriteVector(group, "displacement_mismatch", displacement, "1");
  file.WriteVector(group, "velocity_mismatch", velocity, "1");
  file.WriteVector(group, "shape_misfit", shape_misfit, "1");
  file.WriteVector(group, "fits_shapes", fits_shapes, "1");
}

void WriteUpdatingGroup(H5Writer& file, const UpdateResult& result,
                        const CharacteristicResult* algebraic, const std::string& root) {
  file.WriteStringAttribute(root, "termination", result.termination_name());
  file.WriteStringAttribute(root, "message", result.message);
  file.WriteStringAttribute(root, "jacobian", result.jacobian);
  file.WriteScalar(root, "iterations", result.iterations, "1");
  file.WriteScalar(root + "/cost", "initial", result.initial_cost, "1");
  file.WriteScalar(root + "/cost", "final", result.final_cost, "1");
  file.WriteScalar(root, "rank", result.rank, "1");
  file.WriteVector(root, "singular_values", result.singular_values, "1");
  file.WriteStrings(root, "undetermined", result.undetermined);
  file.WriteStrings(root, "warnings", result.warnings);
  std::vector<std::string> names;
  for (const ParameterEstimate& p : result.parameters) {
    names.push_back(p.name);
    const std::string group = root + "/parameters/" + ObjectName(p.name);
    file.WriteScalar(group, "value", p.value, p.units);
    file.WriteScalar(group, "initial", p.initial, p.units);
    file.WriteScalar(group, "lower", p.lower, p.units);
    file.WriteScalar(group, "upper", p.upper, p.units);
    file.WriteScalar(group, "std", p.std, p.units);
    file.WriteScalar(group, "relative_std", p.relative_std, "1");
    file.WriteScalar(group, "interval_lower", p.interval_lower, p.units);
    file.WriteScalar(group, "interval_upper", p.interval_upper, p.units);
    file.WriteStringAttribute(group, "determined", p.determined ? "true" : "false");
    if (p.profile.computed) WriteProfileGroup(file, group + "/profile", p.profile, p.units);
  }
  file.WriteStringAttribute(root, "credible", result.credible ? "true" : "false");
  file.WriteScalar(root, "chi_square_per_dof", result.chi_square_per_dof, "1");
  file.WriteScalar(root, "std_inflation", result.std_inflation, "1");
  file.WriteStrings(root, "credibility", result.credibility);
  file.WriteStrings(root, "parameter_names", names);
  file.WriteMatrix(root, "parameter_correlation", result.correlation, "1");
  file.WriteMatrix(root, "covariance", result.covariance, "1");
  for (const auto& [channel, k] : WorstCorrelation(result)) {
    file.WriteScalar(root + "/correlation", channel, k, "1");
  }
  const Eigen::Index iterations = static_cast<Eigen::Index>(result.history.size());
  Eigen::VectorXd iteration(iterations), cost(iterations), step(iterations), gradient(iterations),
      successful(iterations);
  for (Eigen::Index i = 0; i < iterations; ++i) {
    const IterationRecord& record = result.history[static_cast<size_t>(i)];
    iteration[i] = record.iteration;
    cost[i] = record.cost;
    step[i] = record.step_norm;
    gradient[i] = record.gradient_max_norm;
    successful[i] = record.successful ? 1.0 : 0.0;
  }
  file.WriteVector(root + "/history", "iteration", iteration, "1");
  file.WriteVector(root + "/history", "cost", cost, "1");
  file.WriteVector(root + "/history", "step_norm", step, "1");
  file.WriteVector(root + "/history", "gradient_max_norm", gradient, "1");
  file.WriteVector(root + "/history", "successful", successful, "1");
  for (const TestFit& test : result.tests) {
    const std::string group = root + "/tests/" + ObjectName(test.name);
    for (size_t c = 0; c < test.channels.size(); ++c) {
      const Eigen::Index column = static_cast<Eigen::Index>(c);
      const std::string& channel = test.channels[c];
      const std::string units =
          c < test.simulated.units.size() ? test.simulated.units[c] : std::string("rad");
      if (test.simulated.values.cols() > column) {
        file.WriteVector(group + "/simulated", channel, test.simulated.values.col(column), units);
      }
      if (test.noise_std.size() > column) {
        file.WriteScalar(group + "/noise_std", channel, test.noise_std[column], units);
      }
      if (test.correlation.size() > column) {
        file.WriteScalar(group + "/correlation", channel, test.correlation[column], "1");
      }
      if (test.residual_rms.size() > column) {
        file.WriteScalar(group + "/residual_rms", channel, test.residual_rms[column], units);
      }
      if (test.offset.size() > column) {
        file.WriteScalar(group + "/offset", channel, test.offset[column], units);
        file.WriteScalar(group + "/offset_std", channel, test.offset_std[column], units);
      }
      if (test.drift.size() > column) {
        file.WriteScalar(group + "/drift", channel, test.drift[column], units + "/s");
        file.WriteScalar(group + "/drift_std", channel, test.drift_std[column], units + "/s");
      }
    }
  }
  file.WriteScalar(root + "/work", "simulations", static_cast<double>(result.simulations), "1");
  file.WriteScalar(root + "/work", "sensitivity_simulations",
                   static_cast<double>(result.sensitivity_simulations), "1");
  file.WriteScalar(root + "/work", "rhs_evaluations", static_cast<double>(result.rhs_evaluations),
                   "1");
  file.WriteScalar(root + "/work", "wall_time_s", result.wall_time_s, "s");
  if (algebraic != nullptr) WriteCharacteristicGroup(file, *algebraic, root + "/algebraic");
}

namespace {

nlohmann::json MinimumToJson(const SearchMinimum& minimum) {
  nlohmann::json values = nlohmann::json::object();
  for (const ParameterEstimate& p : minimum.fit.parameters) values[p.name] = NumberOrNull(p.value);
  return {{"parameters", values},
          {"cost", NumberOrNull(minimum.cost)},
          {"initial_cost", NumberOrNull(minimum.fit.initial_cost)},
          {"f_statistic", NumberOrNull(minimum.f_statistic)},
          {"p_value", NumberOrNull(minimum.p_value)},
          {"starts", minimum.starts},
          {"differs_in", minimum.differs_in},
          {"alternative", minimum.alternative},
          {"iterations", minimum.fit.iterations},
          {"wall_time_s", NumberOrNull(minimum.fit.wall_time_s)}};
}

}  // namespace

void AddGlobalSearchToJson(const GlobalSearchResult& search, nlohmann::json& json) {
  json["non_unique"] = search.non_unique;
  json["alternatives"] = nlohmann::json::array();
  nlohmann::json minima = nlohmann::json::array();
  for (size_t m = 0; m < search.minima.size(); ++m) {
    nlohmann::json entry = MinimumToJson(search.minima[m]);
    if (m > 0 && search.minima[m].alternative) json["alternatives"].push_back(entry);
    minima.push_back(entry);
  }
  json["search"] = {{"starts", search.starts},
                    {"screened", search.screened},
                    {"full_fits", search.full_fits},
                    {"residual_count", search.residual_count},
                    {"wall_time_s", NumberOrNull(search.wall_time_s)},
                    {"screen_time_s", NumberOrNull(search.screen_time_s)},
                    {"differing", search.differing},
                    {"notes", search.notes},
                    {"minima", minima}};
}

void WriteGlobalSearchGroup(H5Writer& file, const GlobalSearchResult& search,
                            const std::string& group) {
  file.WriteStringAttribute(group, "non_unique", search.non_unique ? "true" : "false");
  file.WriteScalar(group, "starts", search.starts, "1");
  file.WriteScalar(group, "screened", search.screened, "1");
  file.WriteScalar(group, "full_fits", search.full_fits, "1");
  file.WriteStrings(group, "differing", search.differing);
  const Eigen::Index count = static_cast<Eigen::Index>(search.minima.size());
  if (count == 0) return;
  std::vector<std::string> names;
  for (const ParameterEstimate& p : search.minima.front().fit.parameters) names.push_back(p.name);
  Eigen::VectorXd cost(count), f(count), p_value(count), alternative(count);
  Eigen::MatrixXd values(count, static_cast<Eigen::Index>(names.size()));
  for (Eigen::Index m = 0; m < count; ++m) {
    const SearchMinimum& minimum = search.minima[static_cast<size_t>(m)];
    cost[m] = minimum.cost;
    f[m] = minimum.f_statistic;
    p_value[m] = minimum.p_value;
    alternative[m] = minimum.alternative ? 1.0 : 0.0;
    for (size_t k = 0; k < names.size(); ++k) {
      values(m, static_cast<Eigen::Index>(k)) = minimum.fit.Find(names[k]).value;
    }
  }
  file.WriteVector(group, "cost", cost, "1");
  file.WriteVector(group, "f_statistic", f, "1");
  file.WriteVector(group, "p_value", p_value, "1");
  file.WriteVector(group, "alternative", alternative, "1");
  file.WriteMatrix(group, "values", values, "1");
  file.WriteStrings(group, "parameter_names", names);
}

std::vector<std::string> DescribeGlobalSearch(const GlobalSearchResult& search) {
  std::vector<std::string> lines;
  if (search.minima.empty()) return lines;
  std::ostringstream line;
  line << "global search: " << search.starts << " starts, " << search.full_fits
       << " whole-record fits, " << search.minima.size() << " distinct minima; best from "
       << search.minima.front().starts.front();
  lines.push_back(line.str());
  for (size_t m = 1; m < search.minima.size(); ++m) {
    const SearchMinimum& minimum = search.minima[m];
    std::ostringstream text;
    text << (minimum.alternative ? "  alternative" : "  worse minimum") << " (from "
         << minimum.starts.front() << "): cost " << minimum.cost << ", F = " << minimum.f_statistic
         << ", p = " << minimum.p_value << "; differs in";
    for (const std::string& name : minimum.differs_in) text << " " << name;
    lines.push_back(text.str());
  }
  if (search.non_unique) {
    std::string list;
    for (const std::string& name : search.differing) list += (list.empty() ? "" : ", ") + name;
    lines.push_back("NON-UNIQUE: the records do not single out one minimum; undetermined: " + list);
  }
  return lines;
}

}  // namespace mbid::updating
