#include "mbid/validation/scenario.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "mbid/common/error.h"
#include "mbid/model/model_factory.h"
#include "mbid/simulation/scenario_sections.h"
#include "mbid/validation/identification_settings.h"
#include "sample_count.h"

namespace mbid::validation {

std::unique_ptr<model::MechanicalModel> Scenario::MakeModel() const {
  return model::MakeModel(root.Child("model"));
}

std::unique_ptr<model::MechanicalModel> Scenario::MakeAlternativeModel(size_t index) const {
  const std::string& file = structure_alternatives.at(index);
  if (!std::filesystem::is_regular_file(file)) {
    throw InputError(path, "structure.alternatives[" + std::to_string(index) + "]",
                     "cannot open '" + file + "'", "a readable YAML file with a model: section");
  }
  const YamlReader alternative = YamlReader::FromFile(file);
  if (!alternative.IsMap() || !alternative.Has("model")) {
    alternative.Fail("no model: section", "a YAML file with a model: section");
  }
  return model::MakeModel(alternative.Child("model"));
}

updating::UpdatingSettings Scenario::ReadUpdating(const model::MechanicalModel& model) const {
  return root.Has("updating")
             ? updating::ReadUpdatingSettings(root.Child("updating"), model, simulation.integrator)
             : updating::MakeDefaultUpdatingSettings(model, simulation.integrator);
}

const simulation::Excitation& Scenario::RequireExcitation() const {
  if (!has_excitation) root.Fail("no excitation section", "excitation: {type: ...}");
  return excitation;
}

Scenario LoadScenario(const std::string& path) {
  // A folder opens and reads as nothing on Linux: said as what it is.
  std::error_code error;
  if (std::filesystem::is_directory(path, error)) {
    throw InputError(path, "", "is a folder", "a scenario YAML file");
  }
  std::ifstream in(path);
  if (!in) throw InputError(path, "", "cannot open the scenario file", "a readable YAML file");
  std::stringstream text;
  text << in.rdbuf();
  return LoadScenarioFromText(text.str(), path);
}

Scenario LoadScenarioFromText(const std::string& text, const std::string& source) {
  Scenario scenario{
      source, "", text, YamlReader::FromString(text, source), false, {}, {}, {}, {}, 0.95,
      {},     {}, {}};
  if (!scenario.root.IsMap()) scenario.root.Fail("not a mapping", "a YAML mapping of sections");
  scenario.root.ExpectMap({"name", "model", "excitation", "simulation", "sensors", "record",
                           "identification", "updating", "validation", "structure"});
  scenario.name = scenario.root.String("name");
  // Any other name is made a safe folder name where it names the results folder.
  if (scenario.name.empty()) scenario.root.FailAt("name", "''", "a non-empty name");
  // Build the model once so that every error surfaces at load time.
  const auto model = scenario.MakeModel();
  if (scenario.root.Has("excitation")) {
    scenario.has_excitation = true;
    scenario.excitation = simulation::ReadExcitation(scenario.root.Child("excitation"), *model);
  }
  if (scenario.root.Has("simulation")) {
    scenario.simulation = simulation::ReadSimulationOptions(scenario.root.Child("simulation"));
  }
  if (scenario.root.Has("validation")) {
    const YamlReader validation = scenario.root.Child("validation");
    validation.ExpectMap({"min_correlation"});
    scenario.validation_min_correlation = validation.Double("min_correlation", 0.95);
    if (!(scenario.validation_min_correlation > -1 && scenario.validation_min_correlation <= 1)) {
      validation.FailAt("min_correlation", "out of range", "a correlation in (-1, 1]");
    }
  }
  if (scenario.root.Has("sensors")) {
    scenario.sensors = simulation::ReadSensorOptions(scenario.root.Child("sensors"), *model);
  } else {
    scenario.sensors.channels = simulation::DefaultChannels(*model);
  }
  internal::CheckSampleCount(scenario.root.source(),
                             "simulation.duration_s, sensors.sample_rate_hz",
                             scenario.simulation.duration_s, scenario.sensors.sample_rate_hz);
  if (scenario.root.Has("structure")) {
    const YamlReader structure = scenario.root.Child("structure");
    structure.ExpectMap({"alternatives"});
    const std::filesystem::path folder = std::filesystem::path(source).parent_path();
    for (const std::string& file : structure.StringList("alternatives")) {
      const std::filesystem::path given(file);
      scenario.structure_alternatives.push_back(
          given.is_absolute() || folder.empty() ? file : (folder / given).string());
    }
    // Every alternative's model is built now, so that its errors surface at load time.
    for (size_t i = 0; i < scenario.structure_alternatives.size(); ++i) {
      scenario.MakeAlternativeModel(i);
    }
  }
  if (scenario.root.Has("identification")) {
    scenario.identification = ReadIdentificationSettings(scenario.root.Child("identification"));
  }
  // After `simulation`: the fits integrate with its integrator unless the section says otherwise.
  scenario.updating = scenario.ReadUpdating(*model);
  if (scenario.root.Has("record")) {
    const std::filesystem::path folder = std::filesystem::path(source).parent_path();
    scenario.records = ReadRecordSources(scenario.root.Child("record"),
                                         folder.empty() ? "." : folder.string(), *model);
  }
  return scenario;
}

std::string DefaultScenarioPath(const std::string& data_dir_hint) {
  namespace fs = std::filesystem;
  const fs::path relative = fs::path("scenarios") / "reference-crane.yaml";
  std::vector<fs::path> candidates;
  // An explicit choice first, then the installation the caller knows (its CMake package or
  // Python module), the installation beside the running program (bin/../share/mbid), the
  // source tree of a build, and the configured installation prefix.
  if (const char* env = std::getenv("MBID_DATA_DIR"); env != nullptr && *env != '\0') {
    candidates.emplace_back(env);
  }
  if (!data_dir_hint.empty()) candidates.emplace_back(data_dir_hint);
  std::error_code error;
  const fs::path exe = fs::read_symlink("/proc/self/exe", error);
  if (!error) candidates.push_back(exe.parent_path().parent_path() / "share" / "mbid");
  candidates.emplace_back(MBID_SOURCE_DIR);
  candidates.emplace_back(MBID_INSTALL_DATA_DIR);
  for (const fs::path& dir : candidates) {
    if (fs::is_regular_file(dir / relative, error)) return (dir / relative).string();
  }
  // None found: the source tree's path, which the error of reading it will name.
  return (fs::path(MBID_SOURCE_DIR) / relative).string();
}

std::string ExpectDeclaredParameter(const YAML::Node& root, const std::string& name,
                                    const std::string& whose) {
  std::vector<std::string> declared;
  // A missing key is an invalid node, which only its bool test may touch.
  const YAML::Node model = root.IsMap() ? root["model"] : YAML::Node();
  const YAML::Node parameters = model && model.IsMap() ? model["parameters"] : YAML::Node();
  if (parameters && parameters.IsMap()) {
    for (const auto& entry : parameters) declared.push_back(entry.first.as<std::string>());
  }
  if (std::find(declared.begin(), declared.end(), name) != declared.end()) return "";
  if (declared.empty()) {
    return "a parameter the " + whose + " declares in model.parameters (it declares none)";
  }
  return fmt::format("one of {}; did you mean '{}'?", fmt::join(declared, ", "),
                     ClosestMatch(name, declared));
}

}  // namespace mbid::validation
