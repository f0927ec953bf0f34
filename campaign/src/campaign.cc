#include "mbid/campaign/campaign.h"

#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>

#include "mbid/common/error.h"
#include "mbid/validation/scenario.h"

namespace mbid::campaign {
using validation::LoadScenarioFromText;

namespace {

namespace fs = std::filesystem;

constexpr char kSeedKey[] = "sensors.seed";

std::string ReadText(const std::string& path, const std::string& source, const std::string& field,
                     const std::string& what) {
  std::ifstream in(path);
  if (!in || fs::is_directory(path)) {
    throw InputError(source, field, "cannot open '" + path + "'", what);
  }
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

std::uint64_t Fnv1a(const std::string& text, std::uint64_t hash) {
  for (unsigned char c : text) {
    hash ^= c;
    hash *= 0x100000001B3ULL;
  }
  return hash;
}

// Whether the scenario reader's complaint is about the key path itself (a typo in a swept
// key) rather than about the value it got.
bool IsUnknownKeyError(const InputError& error, const std::string& key) {
  const bool about_key = error.problem().rfind("unknown key", 0) == 0 ||
                         error.problem().find("has no unit") != std::string::npos;
  const std::string& field = error.field();
  const bool on_path =
      key == field || (key.size() > field.size() && key.compare(0, field.size(), field) == 0 &&
                       (key[field.size()] == '.' || key[field.size()] == '['));
  return about_key && on_path;
}

void ReadSteps(const YamlReader& root, Campaign& campaign) {
  if (!root.Has("steps")) return;
  campaign.steps = {false, false, false};
  const std::vector<std::string> steps = root.StringList("steps");
  if (steps.empty()) {
    root.FailAt("steps", "empty list", "some of modes, simulate, identify, update, all");
  }
  for (size_t i = 0; i < steps.size(); ++i) {
    const std::string& step = steps[i];
    if (step == "modes") continue;  // every case computes its exact modes
    if (step == "simulate" || step == "identify" || step == "update" || step == "all") {
      campaign.steps.simulate = true;  // identify and update need a record
      campaign.steps.identify |= step == "identify" || step == "all";
      campaign.steps.update |= step == "update" || step == "all";
      continue;
    }
    std::string expected = "one of modes, simulate, identify, update, all";
    const std::string best = ClosestMatch(step, {"modes", "simulate", "identify", "update", "all"});
    throw InputError(root.source(), fmt::format("steps[{}]", i), "unknown step '" + step + "'",
                     expected + "; did you mean '" + best + "'?");
  }
}

void ReadBase(const YamlReader& root, Campaign& campaign) {
  const bool has_file = root.Has("base");
  const bool has_inline = root.Has("scenario");
  if (has_file == has_inline) {
    root.Fail(has_file ? "both base and scenario given" : "no base scenario",
              "either base: <scenario file, relative to the campaign file> or scenario: {...}");
  }
  if (has_file) {
    const std::string file = root.String("base");
    fs::path base_path(file);
    if (base_path.is_relative()) base_path = fs::path(campaign.path).parent_path() / base_path;
    campaign.base_source = base_path.lexically_normal().string();
    campaign.base_text = ReadText(campaign.base_source, campaign.path, "base",
                                  "a scenario file (relative paths start at the campaign file)");
  } else {
    const YamlReader scenario = root.Child("scenario");
    if (!scenario.IsMap()) scenario.Fail("is not a map", "an inline scenario: {name, model, ...}");
    YAML::Emitter out;
    out << scenario.node();
    campaign.base_source = campaign.path + ":scenario";
    campaign.base_text = std::string(out.c_str()) + "\n";
  }
  // Errors in the base name its own file and field.
  LoadScenarioFromText(campaign.base_text, campaign.base_source);
  campaign.base = YAML::Load(campaign.base_text);
}

// `model.parameters` is a free map (any name may be declared, used or not), so the scenario
// reader cannot tell a misspelt swept parameter: it became a new parameter nothing used, and
// every case was the base (a sweep of `boom_angel_deg` gave identical cases, reported as swept).
// A set or swept `model.parameters.<name>` must name one the base scenario declares.
void CheckDeclaredParameter(const Campaign& campaign, const Assignment& input) {
  const std::string prefix = "model.parameters.";
  if (input.key.rfind(prefix, 0) != 0) return;
  const std::string name =
      input.key.substr(prefix.size(), input.key.find_first_of(".[", prefix.size()) - prefix.size());
  const std::string expected =
      validation::ExpectDeclaredParameter(campaign.base, name, "base scenario");
  if (expected.empty()) return;
  throw InputError(campaign.path, input.field,
                   "'" + name +
                       "' is not a parameter of the base scenario's model (a value "
                       "nothing uses: every case would be the same)",
                   expected);
}

// Checks once what all cases share: fixed values must give a valid scenario, swept keys must be
// keys the scenario knows (their values are checked per case).
void ProbeKeys(const Campaign& campaign, const std::vector<Assignment>& first_inputs) {
  for (const Assignment& input : campaign.fixed) CheckDeclaredParameter(campaign, input);
  for (const Assignment& input : first_inputs) CheckDeclaredParameter(campaign, input);
  CampaignCase probe;
  probe.id = "probe";
  try {
    LoadScenarioFromText(campaign.CaseScenarioText(probe), campaign.CaseSource(probe));
  } catch (const InputError& error) {
    if (error.source() == campaign.path) throw;  // a path error of ApplyAssignment
    throw InputError(campaign.path, "set." + error.field(), error.problem(), error.expected());
  }
  for (const Assignment& input : first_inputs) {
    probe.inputs = {input};
    try {
      LoadScenarioFromText(campaign.CaseScenarioText(probe), campaign.CaseSource(probe));
    } catch (const InputError& error) {
      if (error.source() == campaign.path) throw;  // a path error of ApplyAssignment
      if (IsUnknownKeyError(error, input.key)) {
        throw InputError(campaign.path, input.field, error.problem(), error.expected());
      }
      // A value that this case rejects: the case fails alone when it runs.
    }
  }
}

}  // namespace

std::string CaseId(int index, int count) {
  const int digits = std::max(4, static_cast<int>(std::to_string(std::max(count - 1, 0)).size()));
  return fmt::format("case_{:0{}d}", index, digits);
}

std::string Campaign::CaseSource(const CampaignCase& one_case) const {
  return path + "#" + one_case.id;
}

std::string Campaign::CaseScenarioText(const CampaignCase& one_case) const {
  const YamlReader where(YAML::Node(), path, "");
  YAML::Node tree = YAML::Clone(base);
  tree["name"] = name + "-" + one_case.id;
  const auto sets = [&](const std::vector<Assignment>& assignments) {
    return std::any_of(assignments.begin(), assignments.end(),
                       [](const Assignment& a) { return a.key == kSeedKey; });
  };
  if (!sets(fixed) && !sets(one_case.inputs)) {
    ApplyAssignment(tree, {kSeedKey, YAML::Node(one_case.sensor_seed), "seed"}, where);
  }
  for (const Assignment& assignment : fixed) ApplyAssignment(tree, assignment, where);
  for (const Assignment& assignment : one_case.inputs) ApplyAssignment(tree, assignment, where);
  YAML::Emitter out;
  out << tree;
  return std::string(out.c_str()) + "\n";
}

std::string Campaign::Fingerprint() const {
  std::uint64_t hash = Fnv1a(text, 0xCBF29CE484222325ULL);
  hash = Fnv1a(std::string(1, '\0') + base_text, hash);
  return fmt::format("{:016x}", hash);
}

CampaignCase MakeAdHocCase(const Campaign& campaign, std::vector<Assignment> inputs,
                           const std::string& id) {
  CampaignCase one_case;
  one_case.id = id;
  one_case.inputs = std::move(inputs);
  // Ad-hoc cases are evaluations of the model, not repeated tests: they share one seed stream.
  one_case.sensor_seed = static_cast<int>(DeriveSeed(campaign.seed, 0xADC0000000000000ULL) >> 33);
  return one_case;
}

Campaign LoadCampaign(const std::string& path) {
  Campaign campaign;
  campaign.path = path;
  campaign.text = ReadText(path, path, "", "a readable campaign file (YAML)");
  const YamlReader root = YamlReader::FromString(campaign.text, path);
  if (!root.IsMap()) root.Fail("is not a map", "a campaign: name, base, steps, sweep, ...");
  std::vector<std::string> keys{"name",  "description", "base",  "scenario", "seed",
                                "steps", "set",         "sweep", "study"};
  const std::vector<std::string> studies = StudyNames();
  keys.insert(keys.end(), studies.begin(), studies.end());  // each study's section
  root.ExpectMap(keys);
  campaign.name = root.String("name");
  if (campaign.name.empty() || campaign.name.find('/') != std::string::npos) {
    root.FailAt("name", "'" + campaign.name + "'", "a non-empty name without '/'");
  }
  campaign.description = root.String("description", "");
  const int seed = root.Seed("seed", 1);
  campaign.seed = static_cast<std::uint64_t>(seed);
  ReadBase(root, campaign);

  std::vector<std::string> study_choices{"none"};
  study_choices.insert(study_choices.end(), studies.begin(), studies.end());
  const std::string study = root.Choice("study", study_choices, "none");
  campaign.study = MakeStudy(study);
  for (const std::string& name : studies) {
    if (root.Has(name) && study != name) {
      root.FailAt(name, "section without study: " + name,
                  "study: " + name + ", or no " + name + " section");
    }
  }
  ReadSteps(root, campaign);

  if (root.Has("set")) {
    const YamlReader set = root.Child("set");
    for (const std::string& key : set.Keys()) {
      campaign.fixed.push_back({key, set.node()[key], "set." + key});
    }
  }

  // A study may make the cases itself (damper sizing sweeps its dampers); else the sweep does.
  std::optional<std::vector<std::vector<Assignment>>> study_cases;
  if (campaign.study) study_cases = campaign.study->ReadCases(root, &campaign);
  std::vector<std::vector<Assignment>> inputs;
  if (study_cases) {
    inputs = std::move(*study_cases);
  } else {
    SweepPlan plan = ReadSweep(root, campaign.seed);
    inputs = std::move(plan.assignments);
    campaign.swept_keys = std::move(plan.keys);
  }
  for (const Assignment& fixed : campaign.fixed) {
    if (std::find(campaign.swept_keys.begin(), campaign.swept_keys.end(), fixed.key) !=
        campaign.swept_keys.end()) {
      throw InputError(path, fixed.field, "key '" + fixed.key + "' both set and swept",
                       "each key either in set or in the sweep");
    }
  }
  const int count = static_cast<int>(inputs.size());
  campaign.cases.reserve(inputs.size());
  for (int i = 0; i < count; ++i) {
    CampaignCase one_case;
    one_case.index = i;
    one_case.id = CaseId(i, count);
    one_case.inputs = std::move(inputs[static_cast<size_t>(i)]);
    // sensors.seed is a non-negative int: the top 31 bits of the case's stream.
    one_case.sensor_seed =
        static_cast<int>(DeriveSeed(campaign.seed, static_cast<std::uint64_t>(i)) >> 33);
    campaign.cases.push_back(std::move(one_case));
  }
  // The damper sweep's first point of each joint stands for its key.
  std::vector<Assignment> first_inputs;
  for (const CampaignCase& one_case : campaign.cases) {
    for (const Assignment& input : one_case.inputs) {
      const bool seen = std::any_of(first_inputs.begin(), first_inputs.end(),
                                    [&](const Assignment& a) { return a.key == input.key; });
      if (!seen) first_inputs.push_back(input);
    }
    if (first_inputs.size() == campaign.swept_keys.size()) break;
  }
  ProbeKeys(campaign, first_inputs);
  // After the probe: the base scenario with `set:` loads, and a study may read it.
  if (campaign.study) campaign.study->ReadSection(root, campaign);
  return campaign;
}

}  // namespace mbid::campaign
