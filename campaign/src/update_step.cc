#include <fmt/format.h>

#include <cmath>
#include <complex>
#include <limits>
#include <memory>
#include <optional>

#include "mbid/common/error.h"
#include "mbid/updating/characteristic.h"
#include "mbid/updating/output_error.h"
#include "mbid/updating/result_io.h"
#include "mbid/updating/settings.h"
#include "mbid/validation/two_route_update.h"
#include "steps.h"

namespace mbid::campaign::internal {
using validation::Scenario;
using validation::SolveAlgebraicRoute;
using validation::TuneModel;
using validation::WeighByIdentifiedNoise;

void RunUpdateStep(const StepInput& input, CaseOutcome& outcome) {
  const Scenario& scenario = *input.scenario;
  const model::MechanicalModel& model = *input.model;
  updating::UpdatingSettings settings = scenario.updating;
  settings.options.quiet = true;  // the campaign reports progress, not each fit

  std::string start;
  std::string note;
  const auto algebraic = input.identified
                             ? SolveAlgebraicRoute(model, *input.identified, input.test->measured,
                                                   scenario.excitation, settings, &note)
                             : nullptr;
  if (!input.identified) note = "no identify step";
  updating::TestRecord test =
      updating::MakeTestRecord(outcome.id, input.test->measured, scenario.excitation, settings);
  if (input.identified) WeighByIdentifiedNoise(*input.identified, test);
  // The campaign's workers share the machine: each case searches on one thread.
  settings.global_search.threads = 1;
  const updating::GlobalSearchResult search =
      TuneModel(model, {test}, settings, algebraic.get(), &start, &note, {});
  auto result = std::make_shared<updating::UpdateResult>(search.best);
  // The only number of the fit that depends on the machine and its load: a campaign's file must
  // be the same bit for bit whoever ran the case, so it is not recorded (NaN).
  result->wall_time_s = std::numeric_limits<double>::quiet_NaN();

  nlohmann::ordered_json& row = outcome.row;
  row["updated.termination"] = result->termination_name();
  row["updated.start"] = start;
  if (!note.empty()) row["updated.start_note"] = note;
  row["updated.iterations"] = result->iterations;
  row["updated.minima"] = static_cast<int>(search.minima.size());
  row["updated.non_unique"] = search.non_unique;
  row["updated.cost_initial"] = Number(result->initial_cost);
  row["updated.cost_final"] = Number(result->final_cost);
  row["updated.rank"] = result->rank;
  row["updated.credible"] = result->credible;
  for (const updating::ParameterEstimate& parameter : result->parameters) {
    const std::string name = "updated." + parameter.name;
    row[name] = Number(parameter.value);
    row[name + ".std"] = Number(parameter.std);
    row[name + ".determined"] = parameter.determined;
  }
  if (!result->tests.empty()) {
    const updating::TestFit& fit = result->tests.front();
    for (size_t c = 0; c < fit.channels.size(); ++c) {
      row["updated.correlation." + fit.channels[c]] =
          Number(fit.correlation[static_cast<Eigen::Index>(c)]);
    }
  }
  outcome.groups.push_back([result, algebraic](H5Writer& file) {
    updating::WriteUpdatingGroup(file, *result, algebraic.get());
  });
  if (result->termination != updating::UpdateResult::Termination::kConverged) {
    throw NumericalError("updating", result->termination_name() + ": " + result->message);
  }
}

}  // namespace mbid::campaign::internal
