#pragma once

#include <map>
#include <string>

#include "mbid/common/yaml_reader.h"
#include "mbid/model/mechanical_model.h"
#include "mbid/simulation/integrator_options.h"
#include "mbid/updating/characteristic.h"
#include "mbid/updating/global_search.h"
#include "mbid/updating/output_error.h"
#include "mbid/updating/profile.h"

namespace mbid::updating {

// The `updating:` section of a scenario (docs/scenarios.md), read strictly: unknown keys are
// errors naming the closest known key. Every key is optional:
//
//   updating:
//     parameters: [c_alpha, d_alpha, ...]  # parameters to tune; default: all c_<joint>, d_<joint>
//     start: {c_alpha: 3.0e7}              # start values in the parameter's units (N*m/rad,
//                                          #   N*m*s/rad); default: Route 1's chosen set if
//                                          #   algebraic_start, else the model section's values
//     bounds: {c_alpha: [1.0e5, 1.0e9]}    # [lower, upper]; default [start / 100, start * 100]
//     log_scale: true                      # Ceres works on log(p) (recommended)
//     algebraic_start: true                # start from Route 1 (eqs. 6-8) when identified poles
//                                          #   give an admissible set; explicit starts win
//     jacobian: sensitivities              # sensitivities (CVODES) | numeric (central
//                                          #   differences of whole simulations)
//     numeric_step: 1.0e-4                 # relative step of the numeric Jacobian
//     noise_std_rad: 1.0e-5                # or {psi: 1.0e-5, phi: 2.0e-5}: residual weights;
//                                          #   default: the identification's residual noise,
//                                          #   else estimated from a first fit
//     fit_payload_mass: false              # nuisance: each load drop's payload mass
//     fit_initial_deflection: false        # nuisance: each initial_deflection test's angles
//     fit_offsets: auto                    # auto | true | false: a constant offset per test and
//                                          #   channel (auto: records not made by mbid)
//     fit_drift: false                     # also a linear drift (with the offsets)
//     max_iterations: 50
//     function_tolerance: 1.0e-6           # Ceres: relative cost decrease
//     gradient_tolerance: 1.0e-10
//     parameter_tolerance: 1.0e-8          # Ceres: relative step in log(p)
//     undetermined_relative_std: 0.3       # relative std above which a parameter is reported
//                                          #   as undetermined by the records
//     rank_tolerance: 1.0e-7               # singular-value ratio of the numerical null space
//     max_chi_square_per_dof: 4            # above: the fit does not explain the records
//     whiteness_lags: 20                   # Ljung-Box lags of the residual's whiteness
//     threads: 1                           # parallel simulations (tests, sensitivity groups)
//     initial_trust_region_radius: 10      # Ceres LM; small = cautious first steps; when not
//                                          #   given, Route 1's sets start at 1000
//                                          #   (GlobalSearchOptions::matched_trust_region_radius)
//     speculative_jacobians: true          # sensitivities at once at a trial point the last
//                                          #   iterate's linear model expects to be accepted
//     continuation_fractions: []           # e.g. [0.25]: fit the first quarter of each record
//                                          #   first, then the whole (fewer local minima)
//     integrator:                          # the fit's simulations; default: the scenario's
//       method: bdf                        #   simulation.integrator with outputs interpolated
//       relative_tolerance: 1.0e-8
//       absolute_tolerance: 1.0e-10
//       max_steps: 100000
//       max_step_s: 0
//       interpolate_outputs: true
//     sensitivity:                         # CVODES forward sensitivities (docs/toolchain.md)
//       right_hand_side: auto              # auto | quotients | state_jacobian
//       corrector: simultaneous            # simultaneous | staggered
//       difference_quotient: forward       # forward | centered (twice the work)
//       relative_tolerance: 1.0e-6         # looser than the state's on purpose
//       absolute_tolerance: 1.0e-8         # divided by each parameter's magnitude
//       error_control: true
//     global_search:                       # Route 2 from many starts (global_search.h)
//       enabled: true
//       design_starts: 12                  # space-filling points over the bounds
//       seed: 1
//       screen_fraction: 0.3               # design points fitted on this much of each record
//       screen_iterations: 20
//       screen_relative_tolerance: 1.0e-5  # the screens' integration (where the fit's is tighter)
//       full_fits: 3                       # whole-record fits from the best screened ends
//       cluster_tolerance: 0.02            # relative distance of one minimum's end points
//       significance: 0.05                 # F-test level of an alternative minimum
//       threads: 0                         # parallel local fits; 0: one per hardware thread
//       pole_equivalent_starts: true       # also fit the other sets with the best's poles
//     profile:                             # profile-likelihood intervals (profile.h)
//       enabled: false                     # a few constrained fits per parameter and side
//       sigmas: 2                          # the interval's level, in Fisher standard deviations
//       max_fits_per_side: 6
//       max_iterations: 20                 # of each constrained fit
//       tolerance: 0.05                    # relative, on sqrt(2 x cost rise) at the ends
//     algebraic:                           # Route 1 (eq. 7)
//       starts: 100                        # multi-start points
//       seed: 1
//       start_spread: 10                   # starts within [reference / 10, reference * 10]
//       max_iterations: 100
//       residual_tolerance: 1.0e-9         # scaled |det| below which a start has converged
//       duplicate_tolerance: 1.0e-6        # relative distance of two equal sets
//       fit_offset: false                  # eq. 8 with a constant per channel
//       ambiguity_ratio: 2                 # runner-up mismatch within this factor: ambiguous
//       shape_significance: 1.0e-3         # eq. 8 fit this much worse: shapes not the record's
struct UpdatingSettings {
  UpdateOptions options;  // parameters carry NaN where the section gives no start or bounds
  CharacteristicOptions algebraic;
  GlobalSearchOptions global_search;  // threads resolved (0 in the file: hardware threads)
  ProfileOptions profile;             // threads: the global search's
  bool algebraic_start = true;
  std::map<std::string, double> noise_std;  // per channel; empty: not given
  bool fit_payload_mass = false;
  bool fit_initial_deflection = false;
  // Offsets per channel: kAuto fits them for imported records (Measurement::source other than
  // "simulation" and "synthetic"), not for records mbid made itself (no zero error to fit).
  enum class Offsets { kAuto, kAlways, kNever };
  Offsets fit_offsets = Offsets::kAuto;
  bool fit_drift = false;  // a drift too, wherever offsets are fitted
};

// The defaults: every parameter of `model`, the scenario's integrator with outputs interpolated.
UpdatingSettings MakeDefaultUpdatingSettings(const model::MechanicalModel& model,
                                             const simulation::IntegratorOptions& integrator);

// Reads the section (a map, or null for the defaults); names are checked against `model`.
UpdatingSettings ReadUpdatingSettings(const YamlReader& updating,
                                      const model::MechanicalModel& model,
                                      const simulation::IntegratorOptions& integrator);

// Starts the parameters without an explicit start at Route 1's chosen set (c_<coordinate>,
// d_<coordinate>). Returns false, leaving `options` unchanged, unless `algebraic` is solved and
// every such start lies within the parameter's explicit bounds; `why` says why not.
bool ApplyAlgebraicStart(const CharacteristicResult& algebraic, UpdateOptions& options,
                         std::string* why = nullptr);

// Every admissible Route-1 set as a start of the global search ("route1 set <i>", i its index
// in `algebraic.solutions`), except `skip_chosen`'s chosen set.
std::vector<SearchStart> MakeAlgebraicStarts(const CharacteristicResult& algebraic,
                                             bool skip_chosen);

// The label of Route 1's set `index` as a start of the global search.
std::string AlgebraicStartLabel(size_t index);

// When Route 1's choice was ambiguous, the parameters in which its rival sets differ from the
// chosen one by more than `relative_difference` are not determined by the record either, even
// if Route 2's local standard deviations look small (a second minimum of equal fit): marks them
// undetermined in `result` with a warning. Returns their names. Rivals whose start label is in
// `judged_starts` are left out: the whole-record fits from them settled the question (a
// minimum as good as the best is then an alternative of the global search).
std::vector<std::string> MarkAlgebraicAmbiguity(const CharacteristicResult& algebraic,
                                                UpdateResult& result,
                                                double relative_difference = 0.1,
                                                const std::vector<std::string>& judged_starts = {});

// A test record with the settings' noise levels and nuisance switches (fit_offsets resolved
// for this record).
TestRecord MakeTestRecord(const std::string& name, const Measurement& record,
                          const simulation::Excitation& excitation,
                          const UpdatingSettings& settings);

}  // namespace mbid::updating
