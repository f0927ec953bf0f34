#include "mbid/campaign/laws.h"

#include <fmt/format.h>

#include <algorithm>
#include <boost/math/distributions/chi_squared.hpp>
#include <cctype>
#include <cmath>
#include <functional>
#include <limits>
#include <map>

#include "mbid/campaign/campaign_case.h"
#include "mbid/common/eigen_decompositions.h"
#include "mbid/common/yaml_reader.h"
#include "units.h"
#include "vectors.h"

namespace mbid::campaign {
namespace {

// A weighted law misses its cases beyond their stds when chi^2 exceeds its 99.9 % quantile.
constexpr double kLackOfFitP = 1e-3;

using internal::kNaN;
constexpr int kMaxDegree = 4;
// Singular values of the scaled design matrix below this fraction of the largest mean the
// cases do not determine the terms (variables that do not vary, too few distinct values).
constexpr double kRankTolerance = 1e-10;

// Monomials of total degree <= degree in `variables` variables: by total degree, then by
// decreasing exponent of the first variable (1, x, y, x^2, x*y, y^2).
std::vector<std::vector<int>> Monomials(int variables, int degree) {
  std::vector<std::vector<int>> terms;
  std::vector<int> exponents(static_cast<size_t>(variables), 0);
  std::function<void(int, int)> fill = [&](int variable, int left) {
    if (variable == variables - 1) {
      exponents[static_cast<size_t>(variable)] = left;
      terms.push_back(exponents);
      return;
    }
    for (int e = left; e >= 0; --e) {
      exponents[static_cast<size_t>(variable)] = e;
      fill(variable + 1, left - e);
    }
  };
  for (int total = 0; total <= degree; ++total) fill(0, total);
  return terms;
}

double Monomial(const std::vector<int>& exponents, const Eigen::VectorXd& u) {
  double value = 1;
  for (size_t i = 0; i < exponents.size(); ++i) {
    value *= std::pow(u[static_cast<Eigen::Index>(i)], exponents[i]);
  }
  return value;
}

double Binomial(int n, int k) {
  double value = 1;
  for (int i = 1; i <= k; ++i) value = value * (n - k + i) / i;
  return value;
}

// T with raw = T * scaled: expands each prod_i ((x_i - c_i) / h_i)^e_i by the binomial theorem.
Eigen::MatrixXd ScaledToRaw(const std::vector<std::vector<int>>& terms,
                            const Eigen::VectorXd& center, const Eigen::VectorXd& half_range) {
  const Eigen::Index p = static_cast<Eigen::Index>(terms.size());
  Eigen::MatrixXd transform = Eigen::MatrixXd::Zero(p, p);
  std::map<std::vector<int>, Eigen::Index> index;
  for (Eigen::Index j = 0; j < p; ++j) index[terms[static_cast<size_t>(j)]] = j;
  for (Eigen::Index j = 0; j < p; ++j) {
    const std::vector<int>& e = terms[static_cast<size_t>(j)];
    std::vector<int> k(e.size(), 0);
    while (true) {
      double coefficient = 1;
      for (size_t i = 0; i < e.size(); ++i) {
        const double a = 1.0 / half_range[static_cast<Eigen::Index>(i)];
        const double b = -center[static_cast<Eigen::Index>(i)] * a;
        coefficient *= Binomial(e[i], k[i]) * std::pow(a, k[i]) * std::pow(b, e[i] - k[i]);
      }
      transform(index.at(k), j) += coefficient;
      size_t i = 0;
      while (i < k.size() && k[i] == e[i]) k[i++] = 0;
      if (i == k.size()) break;
      ++k[i];
    }
  }
  return transform;
}

PolynomialLaw Unfitted(PolynomialLaw law, const std::string& why) {
  law.status = why;
  const Eigen::Index p = static_cast<Eigen::Index>(law.exponents.size());
  law.coefficients = law.std = law.scaled_coefficients = Eigen::VectorXd::Constant(p, kNaN);
  law.covariance = law.scaled_covariance = Eigen::MatrixXd::Constant(p, p, kNaN);
  law.residual_std = law.r_squared = kNaN;
  return law;
}

using internal::ToVector;

// Why the cases cannot determine a law's terms: a variable that does not vary, one with fewer
// distinct values than the degree needs (a quadratic needs three), or variables that vary
// together.
std::string WhyUndetermined(const Eigen::MatrixXd& x, int degree,
                            const std::vector<std::string>& variables) {
  std::vector<std::string> reasons;
  for (Eigen::Index i = 0; i < x.cols(); ++i) {
    std::vector<double> values(x.col(i).data(), x.col(i).data() + x.rows());
    std::sort(values.begin(), values.end());
    const auto distinct = std::unique(values.begin(), values.end()) - values.begin();
    const std::string name = internal::ShortName(variables[static_cast<size_t>(i)]);
    if (distinct <= 1) {
      reasons.push_back(name + " does not vary");
    } else if (distinct <= degree) {
      reasons.push_back(fmt::format("{} takes {} distinct values, a degree {} needs {}", name,
                                    distinct, degree, degree + 1));
    }
  }
  if (reasons.empty()) {
    return "the cases do not determine the terms: the variables vary together (each alone has "
           "values enough for the degree)";
  }
  return fmt::format("the cases do not determine the terms: {}", fmt::join(reasons, "; "));
}

}  // namespace

double PolynomialLaw::Evaluate(const Eigen::VectorXd& x) const {
  const Eigen::VectorXd u = (x - center).cwiseQuotient(half_range);
  double value = 0;
  for (size_t j = 0; j < exponents.size(); ++j) {
    value += scaled_coefficients[static_cast<Eigen::Index>(j)] * Monomial(exponents[j], u);
  }
  return value;
}

double PolynomialLaw::CalcStd(const Eigen::VectorXd& x) const {
  const Eigen::VectorXd u = (x - center).cwiseQuotient(half_range);
  Eigen::VectorXd phi(static_cast<Eigen::Index>(exponents.size()));
  for (size_t j = 0; j < exponents.size(); ++j) {
    phi[static_cast<Eigen::Index>(j)] = Monomial(exponents[j], u);
  }
  return std::sqrt(phi.dot(scaled_covariance * phi));
}

std::string PolynomialLaw::TermName(int term) const {
  std::vector<std::string> factors;
  const std::vector<int>& e = exponents[static_cast<size_t>(term)];
  for (size_t i = 0; i < e.size(); ++i) {
    if (e[i] == 0) continue;
    const std::string name = internal::ShortName(variables[i]);
    factors.push_back(e[i] == 1 ? name : fmt::format("{}^{}", name, e[i]));
  }
  return factors.empty() ? "1" : fmt::format("{}", fmt::join(factors, "*"));
}

PolynomialLaw FitPolynomialLaw(const Eigen::MatrixXd& x, const Eigen::VectorXd& y, int degree,
                               const std::vector<std::string>& variables,
                               const std::string& quantity, const Eigen::VectorXd& y_std) {
  PolynomialLaw law;
  law.quantity = quantity;
  law.variables = variables;
  law.exponents = Monomials(static_cast<int>(variables.size()), degree);
  law.samples = static_cast<int>(y.size());
  const Eigen::Index n = y.size();
  const Eigen::Index p = static_cast<Eigen::Index>(law.exponents.size());
  if (n < p) {
    return Unfitted(law, fmt::format("{} cases with values, fewer than the {} terms", n, p));
  }
  law.center = 0.5 * (x.colwise().maxCoeff() + x.colwise().minCoeff()).transpose();
  law.half_range = 0.5 * (x.colwise().maxCoeff() - x.colwise().minCoeff()).transpose();
  for (Eigen::Index i = 0; i < law.half_range.size(); ++i) {
    if (!(law.half_range[i] > 0)) law.half_range[i] = 1;  // caught by the rank test below
  }
  Eigen::MatrixXd design(n, p);
  for (Eigen::Index r = 0; r < n; ++r) {
    const Eigen::VectorXd u = (x.row(r).transpose() - law.center).cwiseQuotient(law.half_range);
    for (Eigen::Index j = 0; j < p; ++j) {
      design(r, j) = Monomial(law.exponents[static_cast<size_t>(j)], u);
    }
  }
  // With each case's std, rows weighted by 1 / std (weighted least squares).
  law.weighted = y_std.size() == n;
  const Eigen::VectorXd weight =
      law.weighted ? y_std.cwiseInverse().eval() : Eigen::VectorXd::Ones(n).eval();
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(weight.asDiagonal() * design,
                                              Eigen::ComputeThinU | Eigen::ComputeThinV);
  const Eigen::VectorXd& s = svd.singularValues();
  if (!(s[p - 1] > kRankTolerance * s[0])) {
    return Unfitted(law, WhyUndetermined(x, degree, variables));
  }
  law.scaled_coefficients = svd.solve(weight.cwiseProduct(y));
  const Eigen::VectorXd residual = y - design * law.scaled_coefficients;
  const double rss = residual.squaredNorm();
  const double tss = (y.array() - y.mean()).matrix().squaredNorm();
  law.r_squared = tss > 0 ? 1 - rss / tss : kNaN;
  const Eigen::MatrixXd inverse_normal =
      svd.matrixV() * s.cwiseInverse().cwiseAbs2().asDiagonal() * svd.matrixV().transpose();
  const double variance = n > p ? rss / static_cast<double>(n - p) : kNaN;
  law.residual_std = std::sqrt(variance);
  if (law.weighted) {
    // The cases' stds give the covariance; a scatter beyond them (chi^2 per degree of freedom
    // above 1: the polynomial does not describe the cases) inflates it by that ratio.
    law.chi_square_per_dof =
        n > p ? weight.cwiseProduct(residual).squaredNorm() / static_cast<double>(n - p) : kNaN;
    law.scaled_covariance = (n > p ? std::max(1.0, law.chi_square_per_dof) : kNaN) * inverse_normal;
    if (n > p) {
      const boost::math::chi_squared chi2(static_cast<double>(n - p));
      law.lack_of_fit =
          boost::math::cdf(boost::math::complement(
              chi2, law.chi_square_per_dof * static_cast<double>(n - p))) < kLackOfFitP;
    }
  } else {
    law.scaled_covariance = variance * inverse_normal;
  }
  const Eigen::MatrixXd transform = ScaledToRaw(law.exponents, law.center, law.half_range);
  law.coefficients = transform * law.scaled_coefficients;
  law.covariance = transform * law.scaled_covariance * transform.transpose();
  law.std = law.covariance.diagonal().cwiseSqrt();
  return law;
}

std::vector<std::string> NumericColumns(const std::vector<std::string>& parameters,
                                        const std::vector<std::string>& channels, int coordinates) {
  std::vector<std::string> columns{"exact.min_damping_ratio", "simulation.samples",
                                   "simulation.cvodes_steps", "simulation.rhs_evaluations",
                                   "identified.modes"};
  for (int k = 1; k <= 2 * coordinates; ++k) {
    for (const char* quantity : {"frequency_hz", "decay_rate_per_s", "damping_ratio"}) {
      columns.push_back(fmt::format("exact.mode{}.{}", k, quantity));
    }
  }
  for (const std::string& parameter : parameters) {
    columns.push_back("truth." + parameter);
    columns.push_back("updated." + parameter);
    columns.push_back("updated." + parameter + ".std");
  }
  for (const char* name : {"cost_initial", "cost_final", "iterations", "minima", "rank"}) {
    columns.push_back(std::string("updated.") + name);
  }
  for (const std::string& channel : channels) {
    columns.push_back("identified.correlation." + channel);
    columns.push_back("updated.correlation." + channel);
  }
  return columns;
}

bool IsIdentifiedModeColumn(const std::string& column, const std::vector<std::string>& channels) {
  const std::string prefix = "identified.mode";
  if (column.rfind(prefix, 0) != 0) return false;
  size_t end = prefix.size();
  while (end < column.size() && std::isdigit(static_cast<unsigned char>(column[end]))) ++end;
  if (end == prefix.size() || column[prefix.size()] == '0' || end >= column.size() ||
      column[end] != '.') {
    return false;
  }
  const std::string quantity = column.substr(end + 1);
  for (const char* name : {"frequency_hz", "decay_rate_per_s", "damping_ratio", "std_frequency_hz",
                           "std_decay_rate_per_s"}) {
    if (quantity == name) return true;
  }
  return quantity.rfind("amplitude.", 0) == 0 &&
         std::find(channels.begin(), channels.end(), quantity.substr(10)) != channels.end();
}

LawsSpec ReadLaws(const YamlReader& section, const std::vector<std::string>& swept_keys,
                  bool identify, bool update, const std::vector<std::string>& columns,
                  const std::vector<std::string>& channels) {
  section.ExpectMap({"variables", "quantities", "degree"});
  LawsSpec spec;
  spec.variables = section.StringList("variables");
  if (spec.variables.empty()) section.FailAt("variables", "empty list", "swept keys");
  const auto once = [&](const std::vector<std::string>& names, const char* key) {
    for (size_t i = 0; i < names.size(); ++i) {
      if (std::find(names.begin(), names.begin() + static_cast<long>(i), names[i]) !=
          names.begin() + static_cast<long>(i)) {
        section.FailAt(key, "'" + names[i] + "' twice", "each once");
      }
    }
  };
  once(spec.variables, "variables");
  for (const std::string& variable : spec.variables) {
    if (std::find(swept_keys.begin(), swept_keys.end(), variable) == swept_keys.end()) {
      section.FailAt("variables", "'" + variable + "' is not swept",
                     swept_keys.empty()
                         ? std::string("a sweep: the laws' variables are swept keys")
                         : fmt::format("one of the swept keys: {}", fmt::join(swept_keys, ", ")));
    }
  }
  spec.quantities = section.StringList("quantities");
  if (spec.quantities.empty()) {
    section.FailAt("quantities", "empty list", "summary columns such as updated.c_theta");
  }
  once(spec.quantities, "quantities");
  for (const std::string& quantity : spec.quantities) {
    const auto starts = [&](const char* prefix) { return quantity.rfind(prefix, 0) == 0; };
    if (!starts("truth.") && !starts("exact.") && !starts("identified.") && !starts("updated.") &&
        !starts("simulation.")) {
      section.FailAt("quantities", "'" + quantity + "' is not a result column",
                     "a summary column: truth.<parameter>, exact.mode<k>.<quantity>, "
                     "identified.mode<k>.<quantity>, updated.<parameter>");
    }
    if (starts("identified.") && !identify) {
      section.FailAt("quantities", "'" + quantity + "' needs the identify step",
                     "steps: [identify] (or all)");
    }
    if (starts("updated.") && !update) {
      section.FailAt("quantities", "'" + quantity + "' needs the update step",
                     "steps: [update] (or all)");
    }
    if (std::find(columns.begin(), columns.end(), quantity) == columns.end() &&
        !IsIdentifiedModeColumn(quantity, channels)) {
      section.FailAt("quantities", "'" + quantity + "' is no numeric column of the cases",
                     fmt::format("a numeric summary column such as '{}' (docs/campaigns.md, "
                                 "\"Steps of a case\")",
                                 ClosestMatch(quantity, columns)));
    }
  }
  spec.degree = section.Int("degree", 1);
  if (spec.degree < 0 || spec.degree > kMaxDegree) {
    section.FailAt("degree", std::to_string(spec.degree), "an integer from 0 to 4");
  }
  return spec;
}

std::string StdColumnOf(const std::string& quantity) {
  // A parameter's (the other updated.* columns have no .std: their laws are unweighted).
  if (quantity.rfind("updated.", 0) == 0) {
    return quantity.find('.', 8) == std::string::npos ? quantity + ".std" : "";
  }
  for (const char* value : {"frequency_hz", "decay_rate_per_s"}) {
    const std::string suffix = std::string(".") + value;
    if (quantity.rfind("identified.mode", 0) == 0 && quantity.size() > suffix.size() &&
        quantity.compare(quantity.size() - suffix.size(), suffix.size(), suffix) == 0) {
      return quantity.substr(0, quantity.size() - suffix.size()) + ".std_" + value;
    }
  }
  return "";
}

std::vector<PolynomialLaw> FitLaws(const LawsSpec& spec,
                                   const std::vector<nlohmann::ordered_json>& rows) {
  std::vector<PolynomialLaw> laws;
  for (const std::string& quantity : spec.quantities) {
    const std::string std_column = StdColumnOf(quantity);
    std::vector<Eigen::VectorXd> xs;
    std::vector<double> ys, stds;
    int left_out = 0;
    for (const auto& row : rows) {
      if (row["status"] != "ok") continue;
      Eigen::VectorXd x(static_cast<Eigen::Index>(spec.variables.size()));
      for (size_t i = 0; i < spec.variables.size(); ++i) {
        x[static_cast<Eigen::Index>(i)] = RowNumber(row, spec.variables[i]);
      }
      const double y = RowNumber(row, quantity);
      if (!x.allFinite() || !std::isfinite(y)) continue;
      // A value the case's records do not determine is no point of the law (its value is where
      // its fit stopped).
      const auto determined = row.find(quantity + ".determined");
      if (determined != row.end() && determined->is_boolean() && !determined->get<bool>()) {
        ++left_out;
        continue;
      }
      xs.push_back(x);
      ys.push_back(y);
      stds.push_back(std_column.empty() ? kNaN : RowNumber(row, std_column));
    }
    Eigen::MatrixXd x(static_cast<Eigen::Index>(xs.size()),
                      static_cast<Eigen::Index>(spec.variables.size()));
    for (size_t r = 0; r < xs.size(); ++r) x.row(static_cast<Eigen::Index>(r)) = xs[r];
    const Eigen::VectorXd y_std = ToVector(stds);
    const bool weighted = !stds.empty() && y_std.allFinite() && (y_std.array() > 0).all();
    PolynomialLaw law = FitPolynomialLaw(x, ToVector(ys), spec.degree, spec.variables, quantity,
                                         weighted ? y_std : Eigen::VectorXd());
    law.left_out_undetermined = left_out;
    laws.push_back(std::move(law));
  }
  return laws;
}

void WriteLaws(H5Writer& file, const std::vector<PolynomialLaw>& laws) {
  for (const PolynomialLaw& law : laws) {
    const std::string group = "/laws/" + law.quantity;
    const std::string unit = law.units.empty() ? internal::UnitOfColumn(law.quantity) : law.units;
    file.WriteStringAttribute(group, "status", law.status);
    file.WriteStrings(group, "variables", law.variables);
    std::vector<std::string> terms, units;
    Eigen::MatrixXd exponents(static_cast<Eigen::Index>(law.exponents.size()),
                              static_cast<Eigen::Index>(law.variables.size()));
    for (size_t j = 0; j < law.exponents.size(); ++j) {
      terms.push_back(law.TermName(static_cast<int>(j)));
      std::string term_unit = unit;
      for (size_t i = 0; i < law.variables.size(); ++i) {
        exponents(static_cast<Eigen::Index>(j), static_cast<Eigen::Index>(i)) = law.exponents[j][i];
        const int e = law.exponents[j][i];
        if (e > 0) {
          term_unit +=
              "/" + internal::UnitOfColumn(law.variables[i]) + (e > 1 ? fmt::format("^{}", e) : "");
        }
      }
      units.push_back(term_unit);
    }
    file.WriteStrings(group, "terms", terms);
    file.WriteStrings(group, "coefficient_units", units);
    file.WriteMatrix(group, "exponents", exponents, "1");
    file.WriteVector(group, "coefficients", law.coefficients, "see coefficient_units");
    file.WriteVector(group, "std", law.std, "see coefficient_units");
    file.WriteMatrix(group, "covariance", law.covariance, "products of coefficient_units");
    file.WriteScalar(group, "samples", law.samples, "1");
    file.WriteScalar(group, "residual_std", law.residual_std, unit);
    file.WriteScalar(group, "r_squared", law.r_squared, "1");
    file.WriteScalar(group, "chi_square_per_dof", law.chi_square_per_dof, "1");
    file.WriteScalar(group, "left_out_undetermined", law.left_out_undetermined, "1");
    file.WriteStringAttribute(group, "lack_of_fit", law.lack_of_fit ? "yes" : "no");
  }
}

}  // namespace mbid::campaign
