#pragma once

#include <functional>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "mbid/campaign/campaign.h"
#include "mbid/common/hdf5_io.h"

namespace mbid::campaign {

// What one case produced. A case that fails keeps what its earlier steps computed, and says
// which step failed and why; the campaign goes on.
struct CaseOutcome {
  std::string id;
  int index = -1;
  // "ok", "invalid_input" (a value the scenario rejects), "numerical_failure" (integrator,
  // optimizer, no modes found) or "error" (anything else).
  std::string status = "ok";
  std::string failed_step;  // "", "scenario", "modes", "simulate", "identify", "update"
  std::string reason;
  std::string scenario_text;  // the resolved scenario of the case
  // The flat summary row (summary.csv): case_id, index, status, step, reason, seed, the inputs,
  // truth.<parameter>, exact.mode<k>.<quantity>, simulation.*, identified.*, updated.*, and the
  // study's metrics. Missing numbers are null.
  nlohmann::ordered_json row;
  // Writers of the case's result groups (/measurement, /truth, /simulation, /identification,
  // /updating), in order, as far as the steps got.
  std::vector<std::function<void(H5Writer&)>> groups;

  // Study metrics (NaN when not computed).
  std::vector<double> exact_damping_ratios;     // per exact mode, ascending frequency
  std::vector<double> exact_frequencies_hz;     // damped, the same modes (0 for a real pole)
  std::vector<double> exact_decay_rates_per_s;  // the same modes
  double settling_time_s = std::numeric_limits<double>::quiet_NaN();

  bool ok() const { return status == "ok"; }
};

// What a worker keeps of the last case it simulated. Repeated tests differ only in their sensors'
// seed and errors (or in how they are identified): the next such case of the same campaign
// reuses its model, exact modes and noise-free simulation and applies its own sensors to it,
// with the same bits as computed afresh. A model serves one thread: one cache per worker.
class CaseCache {
 public:
  CaseCache();
  ~CaseCache();
  CaseCache(const CaseCache&) = delete;
  CaseCache& operator=(const CaseCache&) = delete;

  int hits() const { return hits_; }  // cases that reused the cached test

 private:
  friend CaseOutcome ComputeCase(const Campaign&, const CampaignCase&, CaseCache*);
  struct Test;
  std::unique_ptr<const Test> last_;
  int hits_ = 0;
};

// Runs the case: resolves its scenario, builds its own model (or takes it from `cache`),
// computes the exact modes and runs the campaign's steps. Never throws for a failure of the
// case itself (bad value, integrator, identification): those are recorded in the outcome. Safe
// to call from several threads at once, each with its own cache or none (each call owns its
// model and states).
CaseOutcome ComputeCase(const Campaign& campaign, const CampaignCase& one_case,
                        CaseCache* cache = nullptr);

// Writes the case's file atomically (temporary name, renamed when complete): the groups of a
// run at the root, the resolved scenario, and root attributes case_id, index, status, step,
// reason, seed and `row` (the summary row as JSON).
void WriteCaseFile(const CaseOutcome& outcome, const std::string& path);

// The summary row of a committed case file. Throws InputError if the file is not a complete
// case file (unreadable, or without the row). `probe`: H5Reader's guard against files that
// crash libhdf5 (a child process per file); kNone for a file this program wrote or whose
// CRC-32 matched the one it was committed with.
nlohmann::ordered_json ReadCaseRow(const std::string& path,
                                   H5Reader::Probe probe = H5Reader::Probe::kEverything);

// A summary row value: a number, +-inf for "inf"/"-inf", or NaN for null or absent.
double RowNumber(const nlohmann::ordered_json& row, const std::string& column);

}  // namespace mbid::campaign
