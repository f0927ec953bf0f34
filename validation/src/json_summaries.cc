#include "mbid/validation/json_summaries.h"

#include <cmath>

#include "mbid/common/json_io.h"

namespace mbid::validation {

nlohmann::json MatrixToJson(const Eigen::MatrixXd& matrix) {
  nlohmann::json rows = nlohmann::json::array();
  for (Eigen::Index i = 0; i < matrix.rows(); ++i) {
    nlohmann::json row = nlohmann::json::array();
    for (Eigen::Index j = 0; j < matrix.cols(); ++j) row.push_back(matrix(i, j));
    rows.push_back(row);
  }
  return rows;
}

nlohmann::json ModelModeToJson(const model::Mode& mode, const model::LinearModel& linear) {
  nlohmann::json json{{"frequency_hz", mode.frequency_hz()},
                      {"decay_rate_per_s", mode.decay_rate_per_s()},
                      {"damping_ratio", NumberOrNull(mode.damping_ratio())},
                      {"undamped_frequency_hz", mode.undamped_frequency_hz()}};
  // A free coordinate's rigid-body motion: a pole at 0, neither oscillating nor decaying.
  if (mode.lambda == 0.0) json["rigid_body"] = true;
  // Only oscillatory modes have a period (log decrement); real poles report null there.
  if (mode.lambda.imag() > 0) {
    json["log_decrement"] = mode.log_decrement();
  } else {
    json["log_decrement"] = nullptr;
  }
  json["half_life_s"] = NumberOrNull(mode.half_life_s());
  nlohmann::json amplitude, phase, shape;
  for (size_t i = 0; i < linear.outputs.size(); ++i) {
    amplitude[linear.outputs[i]] = std::abs(mode.output_shape[i]);
    phase[linear.outputs[i]] = std::arg(mode.output_shape[i]);
  }
  for (size_t i = 0; i < linear.coordinates.size(); ++i) {
    shape[linear.coordinates[i]] = {mode.shape[i].real(), mode.shape[i].imag()};
  }
  json["amplitude"] = amplitude;
  json["phase_rad"] = phase;
  json["shape"] = shape;
  return json;
}

nlohmann::json LinearModelToJson(const model::LinearModel& linear,
                                 const std::vector<model::Mode>& modes) {
  nlohmann::json json{{"coordinates", linear.coordinates}, {"outputs", linear.outputs},
                      {"M", MatrixToJson(linear.M)},       {"D", MatrixToJson(linear.D)},
                      {"C", MatrixToJson(linear.C)},       {"H", MatrixToJson(linear.H)}};
  json["modes"] = nlohmann::json::array();
  for (const model::Mode& mode : modes) json["modes"].push_back(ModelModeToJson(mode, linear));
  json["warnings"] = model::FindModeDoubts(modes);
  return json;
}

}  // namespace mbid::validation
