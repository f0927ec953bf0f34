#pragma once

#include <string>
#include <vector>

#include "mbid/common/measurement.h"
#include "mbid/identification/modal_result.h"
#include "mbid/identification/updating/characteristic.h"
#include "mbid/identification/updating/output_error.h"
#include "mbid/model/linear_model.h"
#include "mbid/model/mechanical_model.h"

namespace mbid::app {

// The figures of a run (gnuplot PNGs), each returned as its file name in `folder`.
std::string DrawRecordFigure(const std::string& folder, const Measurement& measured,
                             const Measurement* exact, int channel);
std::string DrawSpectrumFigure(const std::string& folder,
                               const identification::ModalResult& result);
std::string DrawReconstructionFigure(const std::string& folder, const Measurement& measured,
                                     const identification::ModalResult& result, int channel);
std::string DrawStabilizationFigure(const std::string& folder,
                                    const identification::ModalResult& result);

// The paper's Table 1 in Markdown: identified modes (frequency, decay, half-life, amplitudes
// per channel and their mean, with standard deviations), the correlation K per channel, and the
// model's exact modes beside them when `exact` is given (simulated tests).
std::string ModalTableMarkdown(const identification::ModalResult& result,
                               const std::vector<model::Mode>* exact);

// Record against the re-simulation with the tuned parameters, and the updating's convergence
// (cost per iteration).
std::string DrawResimulationFigure(const std::string& folder, const Measurement& measured,
                                   const updating::TestFit& fit, int channel);
std::string DrawConvergenceFigure(const std::string& folder, const updating::UpdateResult& result);

// The paper's Table 2: tuned values with standard deviations, the model's values (the truth of a
// simulated test) and the relative difference; undetermined parameters marked.
std::string TunedParametersMarkdown(const updating::UpdateResult& result,
                                    const model::MechanicalModel& truth);
// Route 1's solution sets (eq. 7), admissible or not, with their initial-state mismatch.
std::string AlgebraicSetsMarkdown(const updating::CharacteristicResult& result);

}  // namespace mbid::app
