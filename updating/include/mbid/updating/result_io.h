#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "mbid/common/hdf5_io.h"
#include "mbid/updating/characteristic.h"
#include "mbid/updating/global_search.h"
#include "mbid/updating/output_error.h"

namespace mbid::updating {

// The `update` JSON of docs/interfaces.md:
//   {"parameters": {"c_alpha": {"value", "initial", "lower", "upper", "std", "units"}, ...},
//    "termination": "converged" | "no_convergence" | "failure", "iterations",
//    "cost": {"initial", "final"}, "correlation": {"psi": K, ...}}
// with the contract's optional extensions: per parameter "relative_std", "determined",
// "at_bound" and, for nuisance parameters, "test"; top level "message", "jacobian",
// "undetermined", "rank", "singular_values", "parameter_correlation" {"names", "matrix"},
// "warnings", "tests" (per record: correlation, noise_std, noise_estimated, residual_rms and,
// when fitted, "offset" and "drift": {"<channel>": {"value", "std", "units"}}),
// "history" (per iteration: iteration, cost, step_norm, gradient_max_norm, successful),
// "work" (simulations, sensitivity_simulations, rhs_evaluations, wall_time_s) and, when given,
// "algebraic" (CharacteristicResultToJson). "correlation" is the smallest K of a channel over
// the records. Undefined numbers (a std the records do not determine) are null.
nlohmann::json UpdateResultToJson(const UpdateResult& result,
                                  const CharacteristicResult* algebraic = nullptr);

// One console line per fitted baseline term of `test`:
//   "offset(<test>, <channel>) = <value> +- <std> <units>", then the drifts in <units>/s.
std::vector<std::string> DescribeBaseline(const TestFit& test);

// Route 1 (eqs. 6-8): {"status", "message", "starts", "converged_starts", "best_residual",
// "chosen", "ambiguous", "poles": [{"re", "im", "frequency_hz", "decay_rate_per_s"}], "sets":
// [{"c": {...}, "d": {...}, "residual", "hits", "admissible", "reason", "mismatch",
// "displacement_mismatch", "velocity_mismatch", "initial_q": {...}, "initial_u": {...},
// "correlation": {...}}]}.
nlohmann::json CharacteristicResultToJson(const CharacteristicResult& result);

// /updating of the result file (docs/interfaces.md: one dataset per quantity, units as
// attributes, names as in the JSON):
//   attributes termination, message, jacobian
//   iterations, cost/initial, cost/final, rank, singular_values, undetermined (strings),
//   parameter_names (strings), parameter_correlation, covariance (Ceres' coordinates),
//   parameters/<name>/{value, initial, lower, upper, std, relative_std} with units,
//   correlation/<channel>, history/{iteration, cost, step_norm, gradient_max_norm, successful},
//   tests/<test>/{simulated/<channel>, noise_std/<channel>, correlation/<channel>,
//   residual_rms/<channel>, offset/<channel>, offset_std/<channel>, drift/<channel>,
//   drift_std/<channel> (the last four when fitted)}, work/{simulations, sensitivity_simulations,
//   rhs_evaluations, wall_time_s}
// and, when given, /updating/algebraic (WriteCharacteristicGroup). '/' in names becomes '_'.
// `root` other than /updating: a further test's result in the same layout.
void WriteUpdatingGroup(H5Writer& file, const UpdateResult& result,
                        const CharacteristicResult* algebraic = nullptr,
                        const std::string& root = "/updating");

// Route 1 under `group`: attributes status, message; chosen, ambiguous (0/1), starts,
// converged_starts;
// coordinates (strings), lambda_re, lambda_im (1/s); per set (rows) c, d, initial_q,
// initial_u matrices and residual, admissible (0/1), mismatch, displacement_mismatch,
// velocity_mismatch vectors.
void WriteCharacteristicGroup(H5Writer& file, const CharacteristicResult& result,
                              const std::string& group = "/updating/algebraic");

// The global search in the `update` JSON (interfaces.md): "non_unique", "alternatives" (the
// other minima of indistinguishable cost: {"parameters": {name: value}, "cost", "f_statistic",
// "p_value", "starts", "differs_in"}) and "search" {"starts", "screened", "full_fits",
// "residual_count", "wall_time_s", "differing", "notes", "minima": [every distinct minimum as an
// alternative is, with "alternative": true|false]}.
void AddGlobalSearchToJson(const GlobalSearchResult& search, nlohmann::json& json);

// /updating/search: attributes non_unique (0/1); starts, screened, full_fits; differing
// (strings); per distinct minimum (rows, by ascending cost) cost, f_statistic, p_value,
// alternative (0/1), and values (minima x parameters) with parameter_names.
void WriteGlobalSearchGroup(H5Writer& file, const GlobalSearchResult& search,
                            const std::string& group = "/updating/search");

// Console lines: how many minima the search found and, for each alternative, its cost and the
// parameters in which it differs from the best.
std::vector<std::string> DescribeGlobalSearch(const GlobalSearchResult& search);

}  // namespace mbid::updating
