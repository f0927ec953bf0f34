#pragma once

#include <string>
#include <vector>

#include "mbid/common/measurement.h"
#include "mbid/identification/modal_result.h"
#include "mbid/model/linear_model.h"

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

}  // namespace mbid::app
