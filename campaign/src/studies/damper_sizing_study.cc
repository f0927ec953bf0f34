// `study: damper_sizing` as a campaign study: the cases sweep each joint's damper, each case
// records its settling time, and after the cases the smallest dampers are refined
// (damper_sizing.h).
#include <optional>

#include "mbid/campaign/campaign.h"
#include "mbid/campaign/campaign_case.h"
#include "mbid/campaign/damper_sizing.h"
#include "mbid/campaign/study.h"
#include "mbid/common/hdf5_io.h"
#include "mbid/simulation/simulate.h"
#include "steps.h"

namespace mbid::campaign {
namespace {

class DamperSizingStudy : public CampaignStudy {
 public:
  std::string name() const override { return "damper_sizing"; }

  std::optional<std::vector<std::vector<Assignment>>> ReadCases(const YamlReader& root,
                                                                Campaign* campaign) override {
    if (root.Has("sweep")) {
      root.FailAt("sweep", "a sweep in a damper-sizing study",
                  "no sweep: the study sweeps the dampers of damper_sizing.joints itself");
    }
    spec_ = ReadDamperSizing(root.Child("damper_sizing"), campaign->base);
    std::vector<std::vector<Assignment>> inputs = DamperSizingCases(spec_, "damper_sizing");
    // The damping ratio alone needs no simulation; a settling time does.
    if (!root.Has("steps")) campaign->steps.simulate = spec_.has_settling_target();
    if (spec_.has_settling_target()) campaign->steps.simulate = true;
    for (const std::string& joint : spec_.joints) {
      campaign->swept_keys.push_back(spec_.DampingKey(joint));
    }
    return inputs;
  }

  void AddCaseMetrics(const simulation::SimulationResult& test,
                      CaseOutcome* outcome) const override {
    outcome->settling_time_s = CalcSettlingTime(
        test.exact, test.forcing_end_s, spec_.settling_band_fraction, spec_.settling_bands,
        SettlingHold(outcome->exact_frequencies_hz, outcome->exact_decay_rates_per_s),
        outcome->exact_frequencies_hz, outcome->exact_decay_rates_per_s);
    outcome->row["settling_time_s"] = internal::Number(outcome->settling_time_s);
  }

  // The bands are in the channels' units: read against the cases' model.
  void ReadSection(const YamlReader& root, const Campaign& campaign) override {
    CampaignCase probe;
    probe.id = "probe";
    ReadSettlingBands(root.Child("damper_sizing"),
                      validation::LoadScenarioFromText(campaign.CaseScenarioText(probe),
                                                       campaign.CaseSource(probe)),
                      &spec_);
  }

  // The curves are its own figures.
  bool PlotsModesAcrossCases() const override { return false; }

  StudyReport Run(const StudyRun& run) const override {
    run.say("sizing dampers (curves and bisection)");
    const DamperSizingResult result = SizeDampers(run.campaign, spec_, run.rows);
    H5Writer file(run.h5_path);
    WriteDamperSizing(file, spec_, result);
    file.Commit();
    StudyReport report;
    report.markdown = DamperSizingReport(spec_, result, run.folder, &report.figures);
    return report;
  }

 private:
  DamperSizingSpec spec_;
};

}  // namespace

std::shared_ptr<CampaignStudy> MakeDamperSizingStudy() {
  return std::make_shared<DamperSizingStudy>();
}

}  // namespace mbid::campaign
