#pragma once

#include <nlohmann/json.hpp>
#include <vector>

#include "mbid/model/linear_model.h"

namespace mbid::validation {

// Matrix as a list of rows (docs/interfaces: JSON summaries).
nlohmann::json MatrixToJson(const Eigen::MatrixXd& matrix);

// An exact mode of the model: the identify fields (frequency_hz, decay_rate_per_s, ...,
// amplitude and phase_rad per output of the unit-normalized shape) plus `shape` per coordinate
// as [re, im].
nlohmann::json ModelModeToJson(const model::Mode& mode, const model::LinearModel& linear);

// The `mbid modes` summary: coordinates, outputs, M, D, C, H, modes.
nlohmann::json LinearModelToJson(const model::LinearModel& linear,
                                 const std::vector<model::Mode>& modes);

}  // namespace mbid::validation
