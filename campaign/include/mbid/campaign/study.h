#pragma once

#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "mbid/campaign/campaign_sweep.h"
#include "mbid/common/yaml_reader.h"

namespace mbid::simulation {
struct SimulationResult;
}  // namespace mbid::simulation

namespace mbid::campaign {

struct Campaign;
struct CaseOutcome;

// A study's part of report.md: Markdown and the figures it drew.
struct StudyReport {
  std::string markdown;
  std::vector<std::string> figures;
};

// What a study runs on once every case is done.
struct StudyRun {
  const Campaign& campaign;
  const std::vector<nlohmann::ordered_json>& rows;  // the cases' summary rows, campaign order
  std::string folder;                               // the results folder: figures go here
  std::string h5_path;  // the study's HDF5 file (merged into campaign.h5); written if at all
  std::function<void(const std::string&)> say;  // one progress line
};

// A design study a campaign runs after its cases (docs/campaigns.md, `study:`). Each study is a
// plug-in in campaign/src/studies/, registered by name in study_registry.cc; its section in the
// campaign file has the same name (`study: laws` reads `laws:`). Adding one: docs/extending.md.
// A study is read while the campaign loads and then only used through const members, from the
// case workers' threads too.
class CampaignStudy {
 public:
  virtual ~CampaignStudy() = default;

  // The `study:` value and the key of the study's section.
  virtual std::string name() const = 0;

  // Before the cases are made (after the base scenario, `steps:` and `set:`): a study that makes
  // the cases itself instead of `sweep:` reads its section here, returns the cases' inputs, sets
  // campaign->swept_keys and may adjust campaign->steps. Default: the sweep makes them.
  virtual std::optional<std::vector<std::vector<Assignment>>> ReadCases(const YamlReader& root,
                                                                        Campaign* campaign);
  // Once the cases and swept keys are known and the base scenario with `set:` is known to load:
  // reads (the rest of) the study's section.
  virtual void ReadSection(const YamlReader& root, const Campaign& campaign);

  // Adds the study's metrics of one simulated case to its outcome and summary row.
  virtual void AddCaseMetrics(const simulation::SimulationResult& test, CaseOutcome* outcome) const;

  // Whether report.md plots the modes against the first numeric swept key.
  virtual bool PlotsModesAcrossCases() const { return true; }

  // After the cases: computes from their rows, writes run.h5_path if it has groups to merge
  // into campaign.h5, and returns its section of report.md.
  virtual StudyReport Run(const StudyRun& run) const = 0;
};

// The registered studies' names, in the order the campaign's `study:` choices list them.
std::vector<std::string> StudyNames();
// A new study of that name (one of StudyNames()); nullptr for "none".
std::shared_ptr<CampaignStudy> MakeStudy(const std::string& name);

}  // namespace mbid::campaign
