#pragma once

#include <Eigen/Core>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "mbid/common/error.h"
#include "mbid/common/measurement.h"
#include "mbid/model/mechanical_model.h"
#include "mbid/simulation/excitation.h"
#include "mbid/simulation/integrator_options.h"
#include "mbid/updating/parameter_profile.h"

namespace mbid::updating {

// Route 2 of model updating: time-domain output error. Ceres minimizes
//   cost = 1/2 sum_tests sum_j sum_c ((y_c(t_j; p) - y_meas_c(t_j)) / sigma_c)^2
// over the selected parameters p (shared joint parameters c_<joint>, d_<joint>; optionally
// nuisance parameters of each test), where y(t; p) is the model simulated for the test's
// excitation. The Jacobian comes from CVODES forward sensitivities (default) or from central
// differences of whole simulations. A test with fit_offsets adds o_c (+ g_c t) to y_c, the
// best o, g for every p: the cost is minimized over p and the baselines at once.

// A parameter to tune: a model parameter ("c_alpha", "d_theta", ...).
struct ParameterSetting {
  std::string name;
  // NaN: the model's current value.
  double initial = std::numeric_limits<double>::quiet_NaN();
  // NaN: initial / 100 and initial * 100 (within the model's own range).
  double lower = std::numeric_limits<double>::quiet_NaN();
  double upper = std::numeric_limits<double>::quiet_NaN();
  // Ceres works on log(p): positive parameters spanning decades get steps relative to their
  // size, and the reported standard deviation of log(p) is the relative one.
  bool log_scale = true;
};

// One test: a record and the excitation that produced it. Its first sample is at
// record.start_time_s >= 0 after the excitation's t = 0 (the release): a whole number of sample
// intervals, or any fraction of one (the simulation then samples at the record's own times).
struct TestRecord {
  std::string name;  // e.g. the file name; names nuisance parameters "<name>:payload_mass_kg"
  Measurement record;
  simulation::Excitation excitation;
  // Noise standard deviation per channel (channel units), e.g. the identification's residual.
  // Channels without a value get one estimated from the residual of a first fit.
  std::map<std::string, double> noise_std;
  // Nuisance parameters of this test, fitted with the shared ones: the payload mass of a load
  // drop ("<name>:payload_mass_kg", kg, log scale), the initial deflections of an
  // initial_deflection test ("<name>:deflection_<coordinate>", rad, linear scale).
  bool fit_payload_mass = false;
  bool fit_initial_deflection = false;
  // Nuisance baseline per channel, eliminated by variable projection (not among the
  // parameters): record = simulation + offset (+ drift t). Sensor zero errors and slow drift of
  // field records; fit_drift needs fit_offsets.
  bool fit_offsets = false;
  bool fit_drift = false;
  // The record was cut at a release found in it (not given, not simulated): known to a fraction
  // of a sample, so the fit places it too (validation/release_profile.h).
  bool release_detected = false;
  // Samples of `record` that were not measured but interpolated into a gap (--fill-gaps):
  // their residual is the interpolation's error, which the credibility's look for spikes
  // leaves out (one filled sample of a 10 Hz arm at 200 Hz stood 23 times above the noise).
  std::vector<Eigen::Index> unmeasured_samples{};
};

struct UpdateOptions {
  enum class Jacobian { kSensitivities, kNumeric };

  // The parameters to tune; empty: every parameter of the model.
  std::vector<ParameterSetting> parameters;
  Jacobian jacobian = Jacobian::kSensitivities;
  // The simulations of the fit (the records' own rate and length). Outputs interpolated from
  // CVODES' history by default: stopping at every sample would double the steps, and the tests'
  // inputs depend on time alone.
  simulation::IntegratorOptions integrator = [] {
    simulation::IntegratorOptions o;
    o.interpolate_outputs = true;
    return o;
  }();
  // Forward difference quotients: one right-hand side per parameter instead of two. The
  // joints' forces are affine in c and d, so the quotients' truncation error stays far below
  // the sensitivity tolerance (measured: as close to central differences as the centered ones).
  // kAuto: the state Jacobian (forward columns) where a fit has at least as many sensitivities
  // as states (every joint's c and d; initial deflections beside them).
  simulation::SensitivityOptions sensitivity = [] {
    simulation::SensitivityOptions o;
    o.difference_quotient = simulation::SensitivityOptions::DifferenceQuotient::kForward;
    o.right_hand_side = simulation::SensitivityOptions::RightHandSide::kAuto;
    return o;
  }();
  // kNumeric: central differences with this step in Ceres' coordinates (log p: relative).
  double numeric_step = 1e-4;
  int max_iterations = 50;
  // Ceres: relative decrease of the cost. With residuals in units of their noise the cost is
  // about half the sample count, so 1e-6 stops when a step changes it by ~1e-3: statistically
  // nothing (a parameter moving by a few percent of its std). Noiseless records reach the
  // integration error's floor first.
  double function_tolerance = 1e-6;
  double gradient_tolerance = 1e-10;
  // Relative step (|dx| <= tol (|x| + tol), x in log p): 1e-8 stops before the steps drown in
  // the integration error (~1e-9 relative) yet far below any parameter's uncertainty.
  double parameter_tolerance = 1e-8;
  // Noise estimated from a first fit's residual is refined by a second fit with those weights.
  bool refit_after_noise_estimate = true;
  // A parameter is undetermined when its relative standard deviation (log-scale parameters;
  // std / max(|value|, 1e-6) otherwise) exceeds this, or it lies in the numerical null space of
  // the weighted Jacobian (singular values below rank_tolerance times the largest; 1e-7 is
  // Ceres' own limit for inverting J^T J, a reciprocal condition number of 1e-14).
  double undetermined_relative_std = 0.3;
  double rank_tolerance = 1e-7;
  // Credibility of the Fisher standard deviations (credibility.cc). With weights from the
  // record's own noise (the identification's residual), 2 cost / (N - k) is about 1 when the
  // model explains the record; above `max_chi_square_per_dof` the fit does not (a local
  // minimum, or a model that lacks something) and no parameter is reported determined; nor
  // above 1.05 (significantly, at the 0.1% level) with a residual that is not white: the excess
  // is then signal the model leaves out, not noise. Between 1 and it, and for residuals whose
  // integrated autocorrelation time over `whiteness_lags` lags exceeds 1 (not white), the
  // standard deviations are inflated by sqrt(chi^2/dof * time) before the undetermined test,
  // and the result says so.
  double max_chi_square_per_dof = 4.0;
  int whiteness_lags = 20;
  // Ceres' Levenberg-Marquardt starts with this trust region radius (Ceres' default is 1e4):
  // strong regularization at first keeps the early steps from jumping into the far local
  // minima that oscillatory records have.
  double initial_trust_region_radius = 10.0;
  // Continuation in time: fit the first fraction(s) of each record first (ascending, each in
  // (0, 1)), then the whole record from there. Short windows have fewer cycles to slip, so fewer
  // local minima; e.g. {0.25}. Empty: fit the whole record at once.
  std::vector<double> continuation_fractions;
  // A trial point whose predicted cost decrease (the last iterate's linear model) is well above
  // the function tolerance is simulated with its sensitivities at once: Ceres asks for the
  // Jacobian at every accepted point, and a sensitivity run yields the residuals too, so the
  // plain run there is saved; a rejected one costs a sensitivity run instead of a plain one.
  bool speculative_jacobians = true;
  // Simulations in parallel: tests, and parameter groups of one test's sensitivities.
  int threads = 1;
  // Progress (iteration, cost, step) on standard error unless quiet.
  bool quiet = false;

  bool IsValid(std::string* why) const;
};

struct ParameterEstimate {
  std::string name;
  std::string units;
  std::string test;  // a nuisance parameter's test; empty for shared ones
  bool log_scale = true;
  double value = 0;
  double initial = 0;
  double lower = 0;
  double upper = 0;
  // One standard deviation (parameter units) from Ceres' covariance at the estimate, by the
  // delta method for log-scale parameters (std = value * std(log p)). NaN when the covariance
  // is undefined (a rank-deficient Jacobian).
  double std = std::numeric_limits<double>::quiet_NaN();
  double relative_std = std::numeric_limits<double>::quiet_NaN();
  bool determined = true;
  bool at_bound = false;  // within 1e-6 (relative) of a bound: the std means little there
  // Approximate 95% interval: value */ exp(2 relative_std std_inflation) for log-scale
  // parameters, value -+ 2 std std_inflation otherwise; open (infinite) when undefined.
  double interval_lower = -std::numeric_limits<double>::infinity();
  double interval_upper = std::numeric_limits<double>::infinity();
  std::string why_undetermined;  // empty when determined
  // Profile-likelihood interval of a shared parameter, when asked for (profile.h).
  ParameterProfile profile;
  // Undetermined because another minimum fits as well and differs in it (the global search's
  // alternatives, a Route-1 set): a judgment from outside this fit, which a refit of the same
  // minimum (a placed release, validation/release_profile.h) keeps.
  bool rival_differs = false;
  // How much `std` was widened because the Fisher std at its interval's end is larger
  // (WidenToTheIntervalEnds, credibility.h); 1 when not.
  double std_widening = 1;
};

struct IterationRecord {
  int iteration = 0;
  double cost = 0;
  double step_norm = 0;  // in Ceres' coordinates (log p)
  double gradient_max_norm = 0;
  double trust_region_radius = 0;
  bool successful = true;
  double cumulative_time_s = 0;
  // 1-based: the continuation windows first, then the whole record; a refit after a noise
  // estimate is a stage of its own (its cost has other weights).
  int stage = 1;
};

// The tuned model against one test.
struct TestFit {
  std::string name;
  std::vector<std::string> channels;
  Eigen::VectorXd noise_std;  // used weights, per channel
  std::vector<bool> noise_estimated;
  Eigen::VectorXd residual_rms;  // per channel, channel units
  Eigen::VectorXd correlation;   // per channel: Pearson's K of record and re-simulation
  // Re-simulation with the tuned values at the record's samples, the fitted offsets and drifts
  // added: what the record is compared with (residual_rms, correlation).
  Measurement simulated;
  // The fitted baseline per channel (empty when not fitted): offset at the excitation's t = 0
  // (channel units) and drift (channel units per s), with standard deviations that include the
  // parameters' uncertainty.
  Eigen::VectorXd offset, offset_std;
  Eigen::VectorXd drift, drift_std;
  // Per channel, the weighted residual's whiteness: Ljung-Box Q over UpdateOptions::
  // whiteness_lags lags, its p-value (chi-square), and the integrated autocorrelation time
  // 1 + 2 sum rho_k (1 for white noise; how many samples one independent one is worth).
  Eigen::VectorXd whiteness_q, whiteness_p, correlation_time;
  // A release found in the record (TestRecord::release_detected) is placed by the fit
  // (validation/release_profile.h): how much later than the cut it put the release (s), and that
  // instant's standard deviation; NaN when the fit did not place it.
  double release_shift_s = 0;
  double release_shift_std_s = std::numeric_limits<double>::quiet_NaN();
};

struct UpdateResult {
  enum class Termination { kConverged, kNoConvergence, kFailure };

  std::vector<ParameterEstimate> parameters;
  // Correlation of the estimates (in Ceres' coordinates); NaN where undefined.
  Eigen::MatrixXd correlation;
  Eigen::MatrixXd covariance;  // of Ceres' coordinates (log p for log-scale parameters)
  Termination termination = Termination::kFailure;
  std::string message;  // Ceres' own words, plus ours
  int iterations = 0;
  double initial_cost = 0;
  double final_cost = 0;
  // Every Ceres iteration of every stage and pass (see IterationRecord::stage).
  std::vector<IterationRecord> history;
  // Identifiability: singular values of the weighted Jacobian in Ceres' coordinates, its
  // numerical rank and the parameters the records leave undetermined.
  Eigen::VectorXd singular_values;
  int rank = 0;
  std::vector<std::string> undetermined;
  std::vector<std::string> warnings;
  // Credibility (UpdateOptions::max_chi_square_per_dof): chi^2 per degree of freedom of the
  // weighted cost, whether every weight came from the records' noise (else some were estimated
  // from this fit's residual, which makes chi^2/dof 1 by construction), the factor the
  // standard deviations were inflated by for the undetermined test and the intervals, and in
  // words why the Fisher numbers are not to be taken as they are (empty: credible).
  double chi_square_per_dof = std::numeric_limits<double>::quiet_NaN();
  bool weights_from_records = false;
  double std_inflation = 1;
  bool credible = false;  // until AssessCredibility judges it: a failed fit is never credible
  // Weights from the records' noise and a residual that is that noise: neither above
  // max_chi_square_per_dof, nor noticeably above 1 and not white (signal left unexplained).
  bool explains_records = false;
  std::vector<std::string> credibility;
  std::vector<TestFit> tests;
  // Work: simulations (with and without sensitivities), right-hand-side evaluations (all
  // kinds), wall time.
  long simulations = 0;
  long sensitivity_simulations = 0;
  long rhs_evaluations = 0;
  double wall_time_s = 0;
  std::string jacobian;  // "sensitivities" | "numeric"

  std::string termination_name() const;  // "converged" | "no_convergence" | "failure"
  // The estimate named `name`; throws std::out_of_range if absent.
  const ParameterEstimate& Find(const std::string& name) const;
};

// Tunes the parameters of `model` (left unchanged) to the tests. Throws InputError for unknown
// parameters, bounds that do not bracket the start, records whose channels the model lacks,
// records starting before the excitation; a failing simulation inside the fit is a
// Termination::kFailure result, not an exception.
UpdateResult UpdateModel(const model::MechanicalModel& model, const std::vector<TestRecord>& tests,
                         const UpdateOptions& options);

// Sets each tuned shared parameter of `model` to its estimate.
void ApplyEstimates(const UpdateResult& result, model::MechanicalModel& model);

// `p`'s approximate 95% interval (ParameterEstimate::interval_lower) from its std, inflated by
// `std_inflation`; left as it is when the std is undefined.
void SetInterval(ParameterEstimate& p, double std_inflation);

}  // namespace mbid::updating
