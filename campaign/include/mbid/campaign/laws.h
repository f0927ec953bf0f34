#pragma once

#include <Eigen/Core>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "mbid/common/hdf5_io.h"
#include "mbid/common/yaml_reader.h"

namespace mbid::campaign {

// `study: laws` (method.md, sub-problem 3): how stiffness and damping change with the operating
// condition. Each quantity (a summary column: updated.c_theta, truth.d_theta,
// identified.mode1.frequency_hz, ...) is fitted over the cases that have it as a polynomial of
// total degree <= `degree` in the variables (summary columns, normally swept keys such as
// model.configuration.boom_elevation_deg).
struct LawsSpec {
  std::vector<std::string> variables;
  std::vector<std::string> quantities;
  int degree = 1;
};

// The numeric summary columns a case of this scenario can have (docs/campaigns.md, "Steps of a
// case"): truth.<parameter>, exact.mode<k>.<quantity> (k up to twice the coordinates),
// exact.min_damping_ratio, simulation.*, updated.<parameter>[.std] and updated.* numbers,
// identified.modes and identified.correlation.<channel>; identified.mode<k>.* is matched by form
// (IsIdentifiedModeColumn), its count unknown before the run.
std::vector<std::string> NumericColumns(const std::vector<std::string>& parameters,
                                        const std::vector<std::string>& channels, int coordinates);
bool IsIdentifiedModeColumn(const std::string& column, const std::vector<std::string>& channels);

// Reads the `laws:` section. Variables must be swept keys, each once; quantities must name a
// numeric column the steps produce (`columns`, NumericColumns; updated.* needs update,
// identified.* needs identify), each once.
LawsSpec ReadLaws(const YamlReader& section, const std::vector<std::string>& swept_keys,
                  bool identify, bool update, const std::vector<std::string>& columns,
                  const std::vector<std::string>& channels);

// y = sum_j a_j prod_i x_i^e_ji over the monomials of total degree <= degree, fitted by least
// squares. The fit runs on the variables scaled to [-1, 1] over the data (for conditioning)
// and is expanded back to coefficients of the raw variables. Uncertainty: with s^2 = RSS /
// (N - P) the residual variance, Cov(a) = s^2 (A^T A)^-1 (ordinary least squares with
// independent errors of equal variance); with N = P the fit is exact and the std is NaN. With
// each case's std sigma_i (a fitted or identified value's), weighted least squares:
// Cov(a) = max(1, chi^2 / (N - P)) (A^T W A)^-1, W = diag(1 / sigma_i^2), the ratio a scatter
// beyond the cases' stds (the polynomial does not describe them).
struct PolynomialLaw {
  std::string quantity;
  std::string units;  // the quantity's unit (the model's, for c_ and d_ parameters)
  std::vector<std::string> variables;
  std::vector<std::vector<int>> exponents;  // per term, per variable; graded order
  Eigen::VectorXd coefficients;             // of the raw variables
  Eigen::VectorXd std;                      // one standard deviation of each coefficient
  Eigen::MatrixXd covariance;               // of the raw coefficients
  int samples = 0;
  double residual_std = 0;  // s, in the quantity's unit (NaN when N = P)
  double r_squared = 0;
  bool weighted = false;  // by the cases' stds
  // chi^2 / (N - P) of a weighted fit: about 1 when the law describes the cases within their
  // stds, far above when it does not (NaN unweighted or N = P).
  double chi_square_per_dof = std::numeric_limits<double>::quiet_NaN();
  bool lack_of_fit = false;       // chi^2 beyond its 99.9 % quantile: the law misses the cases
  int left_out_undetermined = 0;  // cases whose value their records do not determine
  std::string status = "ok";      // or why the law could not be fitted

  // Scaled form, used for evaluation: u_i = (x_i - center_i) / half_range_i.
  Eigen::VectorXd center, half_range;
  Eigen::VectorXd scaled_coefficients;
  Eigen::MatrixXd scaled_covariance;

  double Evaluate(const Eigen::VectorXd& x) const;
  // Standard deviation of the fitted value at x (the law's own uncertainty, not the scatter).
  double CalcStd(const Eigen::VectorXd& x) const;
  // "1", "x", "x^2*y" with the variables' names.
  std::string TermName(int term) const;
};

// Fits y (N) over x (N x variables). Too few points or variables that do not vary enough to
// determine the terms give a law with status saying so and NaN coefficients.
PolynomialLaw FitPolynomialLaw(const Eigen::MatrixXd& x, const Eigen::VectorXd& y, int degree,
                               const std::vector<std::string>& variables,
                               const std::string& quantity,
                               const Eigen::VectorXd& y_std = Eigen::VectorXd());

// The column of a quantity's std (updated.<parameter>.std, identified.mode<k>.std_<quantity>),
// or "" where the cases give none.
std::string StdColumnOf(const std::string& quantity);

// The laws of every quantity from the summary rows (cases with status ok and the values; a
// value its case marks undetermined is left out), weighted by the cases' stds where every case
// has one (StdColumnOf).
std::vector<PolynomialLaw> FitLaws(const LawsSpec& spec,
                                   const std::vector<nlohmann::ordered_json>& rows);

// /laws/<quantity>/: terms, coefficients, std, covariance, samples, residual_std, r_squared.
void WriteLaws(H5Writer& file, const std::vector<PolynomialLaw>& laws);

// The report section with one figure per quantity: the cases' values against the first
// variable, the law (one curve per value of the other variables when they take few values,
// otherwise at their mean) and its +-2 std band.
std::string LawsReport(const LawsSpec& spec, const std::vector<PolynomialLaw>& laws,
                       const std::vector<nlohmann::ordered_json>& rows, const std::string& folder,
                       std::vector<std::string>* figures);

}  // namespace mbid::campaign
