#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "mbid/model/mechanical_model.h"
#include "mbid/simulation/excitation.h"
#include "mbid/simulation/integrator_options.h"
#include "mbid/simulation/sensor.h"
#include "mbid/simulation/simulate.h"
#include "mbid/updating/output_error.h"

namespace mbid::updating {

// Fisher information of a test about the tuned parameters, in their log coordinates x = log p:
//   F = J^T J,   J(j m + c, k) = dy_c(t_j)/dp_k * p_k / sigma_c,
// the output sensitivities of Route 2 (CVODES forward sensitivities of the simulated test, as
// UpdateModel uses them) weighted by each channel's noise. For Gaussian noise of those standard
// deviations F^-1 is the Cramer-Rao bound of log p, the covariance UpdateModel reports at its
// estimate: sqrt(diag(F^-1)) is each parameter's relative standard deviation. Information of
// independent tests adds: the tests of one fit together have F = sum of their F.

// A test as its information depends on it: what excites the machine, when and what is
// sampled, and how noisy each channel is. Sensor bias, quantization and seed play no part.
struct TestDesign {
  std::string name;
  simulation::Excitation excitation;
  // duration_s and the integrator of the sensitivity run.
  simulation::SimulationOptions simulation;
  // sample_rate_hz, start_time_s and channels; noise_std must give every channel a positive
  // standard deviation (channel units): the weights 1 / sigma_c.
  simulation::SensorOptions sensors;
  // A constant offset (and drift) per channel fitted beside the parameters (UpdateModel's
  // fit_offsets, fit_drift): their information is taken out exactly (each column of J projected
  // orthogonal to [1] or [1, t] per channel, the Schur complement of the nuisance block).
  bool fit_offsets = false;
  bool fit_drift = false;
};

// The design of a recorded test as UpdateModel fits it: the record's own samples (its start
// after the release, rate, length, channels), excitation and offset switches, with the noise
// per channel `noise_std` (TestFit::noise_std, the weights of the fit, in the record's channel
// order) and the fit's integrator. Its nuisance parameters (fit_payload_mass,
// fit_initial_deflection) are taken as known: the design carries no information about them.
TestDesign MakeRecordedDesign(const TestRecord& test, const Eigen::VectorXd& noise_std,
                              const simulation::IntegratorOptions& integrator);

struct FisherInformation {
  std::vector<std::string> parameters;  // the order of the rows and columns
  Eigen::MatrixXd matrix;               // F in log coordinates (dimensionless)
  long residuals = 0;                   // samples x channels
  // The test's largest swing: max over channels of (max y - min y) / noise std of the
  // noise-free outputs. Below 1 the test moves nothing its sensors can see.
  double largest_swing_to_noise = 0;
  simulation::IntegratorStatistics statistics;
};

// F of `test` for the model's `parameters` (all positive: log coordinates) at their current
// values in `model`. Throws InputError for unknown parameters, channels the model lacks or
// missing noise levels; CVODES failures as NumericalError.
FisherInformation CalcFisherInformation(const model::MechanicalModel& model, const TestDesign& test,
                                        const std::vector<std::string>& parameters,
                                        const simulation::SensitivityOptions& sensitivity);

// What F says of each parameter, by UpdateModel's rules: the numerical null space of F
// (eigenvalues below rank_tolerance^2 times the largest: singular values of J below
// rank_tolerance times its largest) leaves the parameters that take part in it (|eigenvector
// entry| > 0.1) undetermined, with an infinite standard deviation; the others get
// sqrt(diag(F^+)), the pseudo-inverse without the null space.
struct ExpectedUncertainty {
  Eigen::VectorXd relative_std;  // per parameter; +Inf where undetermined by F
  int rank = 0;
};
ExpectedUncertainty CalcExpectedUncertainty(const Eigen::MatrixXd& fisher,
                                            double rank_tolerance = 1e-7);

}  // namespace mbid::updating
