#pragma once

#include <map>
#include <string>
#include <utility>
#include <vector>

#include "mbid/common/measurement.h"
#include "mbid/identification/modal_result.h"
#include "mbid/model/linear_model.h"
#include "mbid/model/mechanical_model.h"
#include "mbid/updating/characteristic.h"
#include "mbid/updating/output_error.h"

namespace mbid::report {

// The figures of a run (gnuplot PNGs), each returned as its file name in `folder`.
std::string DrawRecordFigure(const std::string& folder, const Measurement& measured,
                             const Measurement* exact, const std::string& exact_label, int channel);
std::string DrawSpectrumFigure(const std::string& folder,
                               const identification::ModalResult& result);
std::string DrawReconstructionFigure(const std::string& folder, const Measurement& measured,
                                     const identification::ModalResult& result, int channel);
std::string DrawStabilizationFigure(const std::string& folder,
                                    const identification::ModalResult& result);

// A mode the record is known to contain: the model's exact mode of a simulated test, or a mode
// a synthetic record was made from (then with its amplitudes per channel).
struct ReferenceMode {
  double frequency_hz = 0;
  double decay_rate_per_s = 0;
  std::map<std::string, double> amplitude;  // per channel, rad; empty if not known
};

// The paper's Table 1 in Markdown: identified modes (frequency, decay, half-life, amplitudes
// per channel and their mean over the analysed record, with standard deviations), the
// correlation K per channel, and the nearest `reference` mode beside each (labelled
// `reference_label`) when given.
std::string ModalTableMarkdown(const identification::ModalResult& result,
                               const std::vector<ReferenceMode>* reference,
                               const std::string& reference_label);

// Record against the re-simulation with the tuned parameters, and the updating's convergence
// (cost per iteration).
std::string DrawResimulationFigure(const std::string& folder, const Measurement& measured,
                                   const updating::TestFit& fit, int channel);
std::string DrawConvergenceFigure(const std::string& folder, const updating::UpdateResult& result);

// The paper's Table 2 for one test: tuned values with standard deviations, the model's values
// (the truth of a simulated test, the design values of a measured one: `model_label`) and the
// relative difference; undetermined parameters marked.
std::string TunedParametersMarkdown(const updating::UpdateResult& result,
                                    const model::MechanicalModel& model,
                                    const std::string& model_label);

// The paper's Table 2 for several tests: one row of tuned values per test, and the relative
// spread (max - min) / max per parameter in percent, as the paper's last row.
std::string TestsTableMarkdown(const std::vector<std::string>& test_names,
                               const std::vector<const updating::UpdateResult*>& results);

// The relative spread (max - min) / max of each shared parameter over the results (names in the
// first result's order; nuisance parameters of single tests left out).
std::vector<std::pair<std::string, double>> CalcRelativeSpread(
    const std::vector<const updating::UpdateResult*>& results);
// Route 1's solution sets (eq. 7), admissible or not, with their initial-state mismatch.
std::string AlgebraicSetsMarkdown(const updating::CharacteristicResult& result);

}  // namespace mbid::report
