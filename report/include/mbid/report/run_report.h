#pragma once

#include <map>
#include <string>
#include <utility>
#include <vector>

#include "mbid/common/measurement.h"
#include "mbid/identification/modal_result.h"
#include "mbid/model/linear_model.h"
#include "mbid/model/mechanical_model.h"
#include "mbid/report/gnuplot.h"
#include "mbid/updating/characteristic.h"
#include "mbid/updating/output_error.h"

namespace mbid::report {

// The instant a recorded test's free decay starts, as the record figure marks it: in the
// record's own time, and how it was found ("detected" or "given").
struct ReleaseMark {
  double time_s = 0;
  std::string how;
};

// The record figure of one channel: the record (and `exact`, on the same samples, if given) with
// a vertical line at the release when `release` is given, labelled with its time and how it was
// found.
Figure MakeRecordFigure(const Measurement& measured, const Measurement* exact,
                        const std::string& exact_label, int channel, const ReleaseMark* release);

// The figures of a run (gnuplot PNGs), each returned as its file name in `folder`.
std::string DrawRecordFigure(const std::string& folder, const Measurement& measured,
                             const Measurement* exact, const std::string& exact_label, int channel,
                             const ReleaseMark* release = nullptr);
std::string DrawSpectrumFigure(const std::string& folder,
                               const identification::ModalResult& result);
std::string DrawReconstructionFigure(const std::string& folder, const Measurement& measured,
                                     const identification::ModalResult& result, int channel);
std::string DrawStabilizationFigure(const std::string& folder,
                                    const identification::ModalResult& result);

// The backbone of `result`'s mode `k` (0-based; mode k + 1 of the tables) against its amplitude:
// the frequency (`damping` false) or the damping ratio (true), each point with its standard
// deviation as an error bar, the sliding-window fits and the Hilbert estimate as two series.
// Requires the mode to have a backbone.
Figure MakeBackboneFigure(const identification::ModalResult& result, int k, bool damping);
// Both figures of every mode with a backbone: backbone_frequency_<k+1>.png and
// backbone_damping_<k+1>.png.
std::vector<std::string> DrawBackboneFigures(const std::string& folder,
                                             const identification::ModalResult& result);
// One line per mode with a backbone (windows, the range of frequency and damping ratio over the
// amplitudes, whether they depend on it); empty when no mode has one.
std::string BackboneMarkdown(const identification::ModalResult& result);

// A mode the record is known to contain: the model's exact mode of a simulated test, or a mode
// a synthetic record was made from (then with its amplitudes per channel).
struct ReferenceMode {
  double frequency_hz = 0;
  double decay_rate_per_s = 0;
  std::map<std::string, double> amplitude;  // per channel, its unit; empty if not known
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

// The relative spread (max - min) / max of each shared parameter over the results where it is
// determined (NaN where fewer than two determine it; names in the first result's order; nuisance
// parameters of single tests left out).
std::vector<std::pair<std::string, double>> CalcRelativeSpread(
    const std::vector<const updating::UpdateResult*>& results);
// Route 1's solution sets (eq. 7), admissible or not, with their initial-state mismatch.
std::string AlgebraicSetsMarkdown(const updating::CharacteristicResult& result);

}  // namespace mbid::report
