#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include "mbid/campaign/campaign_case.h"
#include "mbid/common/error.h"
#include "mbid/validation/result_writers.h"
#include "mbid/validation/scenario.h"
#include "steps.h"
#include "vectors.h"

namespace mbid::campaign {
using validation::LoadScenarioFromText;
using validation::ModelTruth;
using validation::Scenario;
using validation::WriteModelTruth;
using validation::WriteSimulationInfo;
using validation::WriteTruth;

namespace {

using internal::Number;

using internal::kNaN;

// A swept value in the row: a number when the scalar is one, otherwise its YAML text.
nlohmann::ordered_json ValueJson(const YAML::Node& value) {
  if (value.IsScalar()) {
    const std::string& text = value.Scalar();
    char* end = nullptr;
    const double number = std::strtod(text.c_str(), &end);
    if (!text.empty() && end != nullptr && *end == '\0' && std::isfinite(number)) return number;
  }
  return ValueText(value);
}

void AddExactModes(const std::vector<model::Mode>& modes, CaseOutcome& outcome) {
  double smallest = kNaN;
  for (size_t k = 0; k < modes.size(); ++k) {
    const std::string prefix = fmt::format("exact.mode{}.", k + 1);
    outcome.row[prefix + "frequency_hz"] = Number(modes[k].frequency_hz());
    outcome.row[prefix + "decay_rate_per_s"] = Number(modes[k].decay_rate_per_s());
    outcome.row[prefix + "damping_ratio"] = Number(modes[k].damping_ratio());
    outcome.exact_damping_ratios.push_back(modes[k].damping_ratio());
    outcome.exact_frequencies_hz.push_back(modes[k].frequency_hz());
    outcome.exact_decay_rates_per_s.push_back(modes[k].decay_rate_per_s());
    if (!(modes[k].damping_ratio() >= smallest)) smallest = modes[k].damping_ratio();
  }
  outcome.row["exact.min_damping_ratio"] = Number(smallest);
}

// The inputs a case's model and noise-free test depend on: all but its sensors' seed and errors
// (applied to the noise-free record afterwards) and its identification and validation settings.
std::string TestKey(const CampaignCase& one_case) {
  static const std::vector<std::string> kAfterTheTest = {
      "sensors.seed",    "sensors.noise_std_", "sensors.bias_", "sensors.quantization_step_",
      "identification.", "validation."};
  std::string key;
  for (const Assignment& input : one_case.inputs) {
    const std::string dotted = input.key + ".";
    if (std::any_of(kAfterTheTest.begin(), kAfterTheTest.end(), [&](const std::string& prefix) {
          return dotted.compare(0, prefix.size(), prefix) == 0;
        })) {
      continue;
    }
    key += input.key + "=" + ValueText(input.value) + "\n";
  }
  return key;
}

void Fail(CaseOutcome& outcome, const std::string& status, const std::string& step,
          const std::string& reason) {
  outcome.status = status;
  outcome.failed_step = step;
  outcome.reason = reason;
}

}  // namespace

struct CaseCache::Test {
  std::string key;  // TestKey of the case that computed it
  std::shared_ptr<const model::MechanicalModel> model;
  std::shared_ptr<const ModelTruth> truth;
  std::shared_ptr<const simulation::SimulationResult> test;  // none unless the case simulates
};

CaseCache::CaseCache() = default;
CaseCache::~CaseCache() = default;

CaseOutcome ComputeCase(const Campaign& campaign, const CampaignCase& one_case, CaseCache* cache) {
  CaseOutcome outcome;
  outcome.id = one_case.id;
  outcome.index = one_case.index;
  nlohmann::ordered_json& row = outcome.row;
  row["case_id"] = one_case.id;
  row["index"] = one_case.index;
  row["status"] = "ok";
  row["step"] = "";
  row["reason"] = "";
  row["seed"] = one_case.sensor_seed;
  for (const Assignment& input : one_case.inputs) row[input.key] = ValueJson(input.value);

  std::string step = "scenario";
  try {
    outcome.scenario_text = campaign.CaseScenarioText(one_case);
    const Scenario scenario =
        LoadScenarioFromText(outcome.scenario_text, campaign.CaseSource(one_case));
    row["seed"] = scenario.sensors.seed;
    if (!scenario.records.empty()) {
      scenario.root.FailAt("record", "a recorded test", "no record: campaign cases simulate");
    }

    step = "modes";
    const std::string key = cache != nullptr ? TestKey(one_case) : "";
    const CaseCache::Test* cached =
        cache != nullptr && cache->last_ && cache->last_->key == key ? cache->last_.get() : nullptr;
    if (cached != nullptr) ++cache->hits_;
    const std::shared_ptr<const model::MechanicalModel> model =
        cached != nullptr ? cached->model : scenario.MakeModel();
    const std::shared_ptr<const ModelTruth> truth =
        cached != nullptr ? cached->truth
                          : std::make_shared<const ModelTruth>(validation::CalcModelTruth(*model));
    for (const model::Parameter& parameter : truth->parameters) {
      row["truth." + parameter.name] = parameter.value;
    }
    AddExactModes(truth->modes, outcome);

    if (!campaign.steps.simulate) {
      if (cache != nullptr && cached == nullptr) {
        cache->last_ =
            std::make_unique<const CaseCache::Test>(CaseCache::Test{key, model, truth, {}});
      }
      outcome.groups.push_back([truth](H5Writer& file) { WriteModelTruth(file, *truth); });
    } else {
      step = "simulate";
      const simulation::Excitation excitation = scenario.RequireExcitation();
      std::shared_ptr<const simulation::SimulationResult> test;
      if (cached != nullptr) {
        auto repeated = std::make_shared<simulation::SimulationResult>(*cached->test);
        repeated->measured = simulation::ApplySensor(repeated->exact, scenario.sensors);
        test = std::move(repeated);
      } else {
        test = std::make_shared<const simulation::SimulationResult>(
            simulation::Simulate(*model, excitation, scenario.simulation, scenario.sensors));
        if (cache != nullptr) {
          cache->last_ =
              std::make_unique<const CaseCache::Test>(CaseCache::Test{key, model, truth, test});
        }
      }
      row["simulation.samples"] = test->measured.samples();
      row["simulation.cvodes_steps"] = test->statistics.steps;
      row["simulation.rhs_evaluations"] = test->statistics.rhs_evaluations;
      const simulation::SimulationOptions options = scenario.simulation;
      outcome.groups.push_back([truth, test, excitation, options](H5Writer& file) {
        file.WriteMeasurement(test->measured);
        WriteTruth(file, *truth, *test);
        WriteSimulationInfo(file, excitation, options, *test);
      });
      if (campaign.study) campaign.study->AddCaseMetrics(*test, &outcome);

      internal::StepInput input{&scenario, model, test, nullptr};
      if (campaign.steps.identify) {
        step = "identify";
        input.identified = internal::RunIdentifyStep(input, outcome);
      }
      if (campaign.steps.update) {
        step = "update";
        internal::RunUpdateStep(input, outcome);
      }
    }
  } catch (const InputError& error) {
    Fail(outcome, "invalid_input", step, error.what());
  } catch (const NumericalError& error) {
    Fail(outcome, "numerical_failure", step, error.what());
  } catch (const std::exception& error) {
    Fail(outcome, "error", step, error.what());
  }
  row["status"] = outcome.status;
  row["step"] = outcome.failed_step;
  row["reason"] = outcome.reason;
  return outcome;
}

void WriteCaseFile(const CaseOutcome& outcome, const std::string& path) {
  // Not synced: --resume reads every case file back and runs a damaged one again, and two
  // fsyncs per case cost about 10% of a small case (docs/performance.md).
  H5Writer file(path, /*sync=*/false);
  for (const auto& write_group : outcome.groups) write_group(file);
  if (!outcome.scenario_text.empty()) file.WriteScenarioYaml(outcome.scenario_text);
  file.WriteStringAttribute("/", "case_id", outcome.id);
  file.WriteDoubleAttribute("/", "index", outcome.index);
  file.WriteStringAttribute("/", "status", outcome.status);
  file.WriteStringAttribute("/", "step", outcome.failed_step);
  file.WriteStringAttribute("/", "reason", outcome.reason);
  file.WriteDoubleAttribute("/", "seed", outcome.row["seed"].get<double>());
  // Written last: a case file with its row is complete (ReadCaseRow checks for it).
  file.WriteStringAttribute("/", "row", outcome.row.dump());
  file.Commit();
}

nlohmann::ordered_json ReadCaseRow(const std::string& path, H5Reader::Probe probe) {
  const H5Reader file(path, probe);
  const std::string text = file.ReadStringAttribute("/", "row");
  try {
    return nlohmann::ordered_json::parse(text);
  } catch (const nlohmann::json::exception& error) {
    throw InputError(path, "/ attribute 'row'", error.what(), "the case's summary row (JSON)");
  }
}

double RowNumber(const nlohmann::ordered_json& row, const std::string& column) {
  const auto it = row.find(column);
  if (it != row.end() && it->is_string()) {  // an infinity (internal::Number)
    const std::string& text = it->get_ref<const std::string&>();
    if (text == "inf") return std::numeric_limits<double>::infinity();
    if (text == "-inf") return -std::numeric_limits<double>::infinity();
  }
  if (it == row.end() || !it->is_number()) return kNaN;
  return it->get<double>();
}

}  // namespace mbid::campaign
