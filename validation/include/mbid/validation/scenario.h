#pragma once

#include <memory>
#include <string>
#include <vector>

#include "mbid/common/yaml_reader.h"
#include "mbid/identification/options.h"
#include "mbid/model/mechanical_model.h"
#include "mbid/simulation/excitation.h"
#include "mbid/simulation/sensor.h"
#include "mbid/simulation/simulate.h"
#include "mbid/updating/settings.h"
#include "mbid/validation/record_source.h"

namespace mbid::validation {

// A scenario file (docs/scenarios.md), read strictly: unknown keys anywhere are errors.
struct Scenario {
  std::string path;
  std::string name;
  std::string yaml_text;  // the file as given, stored with every result
  YamlReader root;
  bool has_excitation = false;
  simulation::Excitation excitation;
  simulation::SimulationOptions simulation;  // defaults where the section is absent
  simulation::SensorOptions sensors;         // defaults where the section is absent
  // `record:`: the tests' records when they are measured (or made from modes) rather than
  // simulated from the model; empty: `mbid run` simulates the test.
  std::vector<RecordSource> records;
  // `validation: {min_correlation: K}`: the run passes when the re-simulation with the tuned
  // parameters correlates with the record at least this well on every channel.
  double validation_min_correlation = 0.95;
  // `structure: {alternatives: [file, ...]}`: other descriptions of the machine for
  // `mbid structure` to rank beside the model's own rigid variants; paths resolved against the
  // scenario's folder, each a YAML file with a `model:` section (a scenario file will do).
  std::vector<std::string> structure_alternatives;
  // `identification:` and `updating:` (for the scenario's own model, the fits integrating with
  // `simulation`'s integrator as loaded unless the section names one), read and checked at load
  // like every other section: a typo there is an error of every command, not only of the one
  // that needs it. Commands on the scenario's own model use these.
  identification::IdentificationOptions identification;
  updating::UpdatingSettings updating;

  // A fresh model instance (one per worker).
  std::unique_ptr<model::MechanicalModel> MakeModel() const;
  // The model of structure_alternatives[index], checked as the scenario's own.
  std::unique_ptr<model::MechanicalModel> MakeAlternativeModel(size_t index) const;
  // The `updating:` section for `model` (another description's, or a fresh instance of the
  // scenario's), or the defaults; the fits integrate with the scenario's integrator unless the
  // section says otherwise.
  updating::UpdatingSettings ReadUpdating(const model::MechanicalModel& model) const;
  // The excitation; an InputError if the scenario has none.
  const simulation::Excitation& RequireExcitation() const;
};

Scenario LoadScenario(const std::string& path);

// The same from scenario text already in memory (a campaign's case); `source` names it in errors
// and becomes Scenario::path.
Scenario LoadScenarioFromText(const std::string& text, const std::string& source);

// The built-in reference scenario, scenarios/reference-crane.yaml, from the first data folder
// that has it: $MBID_DATA_DIR, `data_dir_hint`, <program>/../share/mbid, the source tree, the
// configured installation's share/mbid.
std::string DefaultScenarioPath(const std::string& data_dir_hint = "");

// What a reference to parameter `name` of a scenario's `model.parameters` (`root`: the
// scenario's YAML) expects instead, or "" when the scenario declares it. model.parameters is a
// free map: a misspelt name elsewhere (a campaign's sweep, a plan candidate) would be one more
// parameter that nothing uses. `whose` names the scenario in the text ("base scenario").
std::string ExpectDeclaredParameter(const YAML::Node& root, const std::string& name,
                                    const std::string& whose);

}  // namespace mbid::validation
