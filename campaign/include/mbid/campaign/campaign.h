#pragma once

#include <yaml-cpp/yaml.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "mbid/campaign/campaign_sweep.h"
#include "mbid/campaign/study.h"
#include "mbid/common/yaml_reader.h"

namespace mbid::campaign {

// What every case does besides computing the exact modes of its model (which it always does).
// identify and update need a record, so they imply simulate.
struct CampaignSteps {
  bool simulate = true;
  bool identify = false;
  bool update = false;
};

// One case: the base scenario with the campaign's fixed values and this case's swept values.
struct CampaignCase {
  int index = -1;                  // 0-based position in the campaign; -1 for an ad-hoc case
  std::string id;                  // "case_0007": /cases/<id> in the results
  std::vector<Assignment> inputs;  // swept values, in the order of Campaign::swept_keys
  int sensor_seed = 1;             // sensors.seed unless the campaign sets or sweeps it
};

// A campaign file (docs/campaigns.md), read strictly: a base scenario, fixed values, sweeps
// over any scenario key, the steps of each case and optionally a design study. Loading checks
// everything that is the same for all cases (the base scenario, key paths, fixed values), so
// that a mistake fails at once with exit code 2; a value that only some cases get wrong (an
// out-of-range elevation) fails those cases alone, with the reason in their results.
struct Campaign {
  std::string path;  // the campaign file
  std::string text;  // its text as given
  std::string name;
  std::string description;  // optional, shown in the report
  std::string base_source;  // the base scenario's file, or "<campaign file>:scenario" inline
  std::string base_text;    // the base scenario's text as given
  YAML::Node base;          // and parsed
  std::uint64_t seed = 1;
  CampaignSteps steps;
  std::vector<Assignment> fixed;        // `set:`, applied to every case before its inputs
  std::vector<std::string> swept_keys;  // the inputs' keys, columns of summary.csv
  std::vector<CampaignCase> cases;
  // The design study run after the cases (`study:`, study.h), with its section; null for none.
  std::shared_ptr<CampaignStudy> study;

  // The case's resolved scenario, as YAML text that LoadScenarioFromText reads: the base with
  // name "<campaign>-<case id>", sensors.seed = the case's seed (unless set or swept), the fixed
  // values, then the inputs.
  std::string CaseScenarioText(const CampaignCase& one_case) const;
  // The source name of a case in error messages: "<campaign file>#<case id>".
  std::string CaseSource(const CampaignCase& one_case) const;
  // Changes when the campaign or its base scenario changes (FNV-1a of both texts): a results
  // folder can only be resumed by the campaign that started it.
  std::string Fingerprint() const;
};

// Reads a campaign file. Every error is an InputError naming the file (the campaign's or the
// base scenario's) and the field.
Campaign LoadCampaign(const std::string& path);

// The case at `index`'s id for a campaign of `count` cases: "case_" and at least 4 digits.
std::string CaseId(int index, int count);

// A case with the given inputs that is not part of the campaign's list (a study's extra
// evaluations); its seed is derived like the campaign's.
CampaignCase MakeAdHocCase(const Campaign& campaign, std::vector<Assignment> inputs,
                           const std::string& id);

}  // namespace mbid::campaign
