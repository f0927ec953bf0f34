#pragma once

// The candidates file of `mbid plan` (docs/planning.md):
//
//   candidates:
//     - name: drop-1300                      # required, unique
//       excitation: {type: load_drop, payload_mass_kg: 1300}   # required, as in scenarios
//       simulation: {duration_s: 8}          # optional: merged over the scenario's section
//       sensors: {channels: [psi, phi], noise_std_rad: 1.0e-5}  # optional: merged likewise
//       model: {configuration: {boom_elevation_deg: 40}}        # optional: merged likewise
//
// Read strictly: unknown keys anywhere are InputErrors naming the file and the key path
// ("plan.yaml:candidates[1].excitation.type: ...").

#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "mbid/model/mechanical_model.h"
#include "mbid/updating/plan.h"
#include "mbid/updating/plan_alternatives.h"
#include "mbid/validation/scenario.h"

namespace mbid::validation {

struct CandidateFile {
  std::string path;
  std::vector<updating::PlanCandidate> candidates;
  // Per candidate, the channels whose noise level the candidate's own `sensors:` gives (its
  // test.sensors.noise_std holds these only until FillCandidateNoise).
  std::vector<std::vector<std::string>> own_noise;
};

// Reads the candidates of `path` for `scenario` (whose model is `model`): each candidate's
// model, simulation and sensors are the scenario's sections with the candidate's keys merged
// over them (maps key by key, anything else replaced); a candidate without `model:` has a null
// model (the scenario's). The scenario's sensor noise, bias and quantization are not merged: a
// candidate's noise is its own where it gives one (FillCandidateNoise does the rest).
CandidateFile ReadCandidateFile(const std::string& path, const Scenario& scenario,
                                const model::MechanicalModel& model);

// Gives every channel of every candidate a noise level: its own where given, else `recorded`
// (the recorded tests' noise per channel), else the scenario's sensors; none of them: an
// InputError naming the candidate's sensors.
void FillCandidateNoise(CandidateFile& file, const std::map<std::string, double>& recorded,
                        const std::map<std::string, double>& scenario_noise);

// {name: value} of `values` in the order of `names`; NaN as null.
nlohmann::json PerParameterJson(const std::vector<std::string>& names,
                                const Eigen::VectorXd& values);

// The JSON summary's `candidates` (docs/planning.md): each candidate's score, gain, expected
// relative std and determined parameters, its noise levels, and its scores at the alternative
// minima (`at_alternatives`, empty without alternatives).
nlohmann::json CandidateScoresToJson(
    const updating::TestPlan& plan, const CandidateFile& file,
    const updating::AlternativesPlan& at_alternatives,
    const std::vector<updating::AlternativeMinimumValues>& alternatives);

// `override` merged over `base`: maps key by key (recursively), anything else replaced.
YAML::Node MergeYaml(const YAML::Node& base, const YAML::Node& override);

}  // namespace mbid::validation
