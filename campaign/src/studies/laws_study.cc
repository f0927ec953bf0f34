// `study: laws` as a campaign study: after the cases, polynomial laws of the chosen quantities
// over the swept variables (laws.h).
#include <yaml-cpp/yaml.h>

#include "mbid/campaign/campaign.h"
#include "mbid/campaign/laws.h"
#include "mbid/campaign/study.h"
#include "mbid/common/hdf5_io.h"
#include "mbid/model/mechanical_model.h"
#include "mbid/validation/scenario.h"
#include "units.h"

namespace mbid::campaign {
namespace {

class LawsStudy : public CampaignStudy {
 public:
  std::string name() const override { return "laws"; }

  // Variables must be swept keys: read once the sweep is; quantities columns of the model's.
  void ReadSection(const YamlReader& root, const Campaign& campaign) override {
    CampaignCase probe;
    probe.id = "probe";
    const validation::Scenario scenario = validation::LoadScenarioFromText(
        campaign.CaseScenarioText(probe), campaign.CaseSource(probe));
    const std::unique_ptr<model::MechanicalModel> model = scenario.MakeModel();
    std::vector<std::string> parameters;
    for (const model::Parameter& parameter : model->parameters()) {
      parameters.push_back(parameter.name);
    }
    spec_ = ReadLaws(
        root.Child("laws"), campaign.swept_keys, campaign.steps.identify, campaign.steps.update,
        NumericColumns(parameters, scenario.sensors.channels, model->coordinate_count()),
        scenario.sensors.channels);
  }

  StudyReport Run(const StudyRun& run) const override {
    run.say("fitting the laws");
    std::vector<PolynomialLaw> laws = FitLaws(spec_, run.rows);
    // Stiffness and damping units from the base model: N*m/rad on pins, N/m on slides.
    const std::vector<model::Parameter> parameters =
        validation::LoadScenarioFromText(YAML::Dump(run.campaign.base), run.campaign.base_source)
            .MakeModel()
            ->parameters();
    for (PolynomialLaw& law : laws) {
      for (const model::Parameter& parameter : parameters) {
        if (internal::ShortName(law.quantity) == parameter.name) law.units = parameter.units;
      }
    }
    H5Writer file(run.h5_path);
    WriteLaws(file, laws);
    file.Commit();
    StudyReport report;
    report.markdown = LawsReport(spec_, laws, run.rows, run.folder, &report.figures);
    return report;
  }

 private:
  LawsSpec spec_;
};

}  // namespace

std::shared_ptr<CampaignStudy> MakeLawsStudy() { return std::make_shared<LawsStudy>(); }

}  // namespace mbid::campaign
