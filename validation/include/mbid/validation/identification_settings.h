#pragma once

#include "mbid/common/measurement.h"
#include "mbid/common/yaml_reader.h"
#include "mbid/identification/modal_result.h"
#include "mbid/identification/options.h"
#include "mbid/simulation/excitation.h"

namespace mbid::validation {

// The `identification:` section of a scenario, read strictly into the identifier's options
// (mbid/identification/options.h; every key is optional and defaults to the option's default):
//   method: hankel-nls | prony-svd      window_start_s, window_end_s (s)
//   channels: [psi, phi]                offset: none | mean | fit       decimation: 1
//   min_frequency_hz, max_frequency_hz  min_damping_ratio, max_damping_ratio
//   max_decay_rate_per_s                max_modes                        significance_false_alarm
//   min_significance                    drop_insignificant               compute_spectrum
//   compute_stabilization               compute_uncertainty              prony: {order,
//   rank_tolerance}
// Errors name the file and field; options out of range are reported as IdentificationOptions::
// IsValid says.
identification::IdentificationOptions ReadIdentificationSettings(const YamlReader& section);

// Only the free decay is identified: without an explicit window start, the window opens at the
// excitation's forcing end (impulse, burst).
identification::IdentificationOptions FreeDecayOptions(
    identification::IdentificationOptions options, const simulation::Excitation& excitation);

// The record's modes for `update` and `run`: Identify, except that where it finds no modes (an
// overdamped machine) the result has none, no noise levels, and is unreliable saying why: the
// time-domain fit tunes the joints without them. Other failures throw as Identify's.
identification::ModalResult IdentifyForTheFit(const Measurement& record,
                                              const identification::IdentificationOptions& options,
                                              const std::string& origin);

// The scenario an HDF5 record file mbid wrote carries (/scenario), or "" (other files too).
std::string ReadRecordScenario(const std::string& path);

// The options for a record file whose scenario text is `scenario_yaml` (ReadRecordScenario) as
// `mbid identify` and the Python module's identify() take it: after a forcing (an impulse, a
// burst) its free decay starts where the forcing ends (FreeDecayOptions); the user's release or
// window still win, and a scenario this version cannot read changes nothing. `origin` names the
// file; `said` gets the line that tells the user so, else "".
identification::IdentificationOptions RecordFileOptions(
    const std::string& scenario_yaml, const std::string& origin,
    const identification::IdentificationOptions& options, std::string* said);

}  // namespace mbid::validation
