#include "mbid/identification/modal_result.h"

#include <cmath>

#include "mbid/common/json_io.h"

namespace mbid::identification {
namespace {

nlohmann::json PerChannel(const std::vector<std::string>& channels, const Eigen::VectorXd& v) {
  nlohmann::json object = nlohmann::json::object();
  for (size_t c = 0; c < channels.size() && static_cast<Eigen::Index>(c) < v.size(); ++c) {
    object[channels[c]] = NumberOrNull(v(c));
  }
  return object;
}

template <typename Get>
Eigen::VectorXd ModeVector(const ModalResult& result, Get&& get) {
  Eigen::VectorXd v(result.modes.size());
  for (size_t k = 0; k < result.modes.size(); ++k) v(k) = get(result.modes[k]);
  return v;
}

std::string UnitOf(const ModalResult& result, size_t channel) {
  return channel < result.units.size() ? result.units[channel] : "";
}

}  // namespace

void IdentifiedMode::SetPole(std::complex<double> pole) {
  lambda = pole;
  const double omega = pole.imag();
  const double decay = -pole.real();
  const double magnitude = std::abs(pole);
  frequency_hz = omega / (2 * M_PI);
  decay_rate_per_s = decay;
  damping_ratio = magnitude > 0 ? decay / magnitude : 0.0;
  undamped_frequency_hz = magnitude / (2 * M_PI);
  log_decrement = omega > 0 ? 2 * M_PI * decay / omega : std::numeric_limits<double>::infinity();
  half_life_s = decay > 0 ? std::log(2.0) / decay : std::numeric_limits<double>::infinity();
}

nlohmann::json ModalResultToJson(const ModalResult& result) {
  nlohmann::json json;
  json["channels"] = result.channels;
  json["sample_interval_s"] = result.sample_interval_s;
  json["samples"] = result.samples;
  json["method"] = result.method;
  json["model_order"] = result.model_order;
  json["effective_rank"] = result.effective_rank;
  nlohmann::json modes = nlohmann::json::array();
  for (const IdentifiedMode& mode : result.modes) {
    nlohmann::json m;
    m["frequency_hz"] = NumberOrNull(mode.frequency_hz);
    m["decay_rate_per_s"] = NumberOrNull(mode.decay_rate_per_s);
    m["damping_ratio"] = NumberOrNull(mode.damping_ratio);
    m["undamped_frequency_hz"] = NumberOrNull(mode.undamped_frequency_hz);
    m["log_decrement"] = NumberOrNull(mode.log_decrement);
    m["half_life_s"] = NumberOrNull(mode.half_life_s);
    m["amplitude"] = PerChannel(result.channels, mode.amplitude);
    m["phase_rad"] = PerChannel(result.channels, mode.phase_rad);
    m["std_frequency_hz"] = NumberOrNull(mode.std_frequency_hz);
    m["std_decay_rate_per_s"] = NumberOrNull(mode.std_decay_rate_per_s);
    m["significance"] = NumberOrNull(mode.significance);
    m["significant"] = mode.significant;
    if (!mode.combination.empty()) m["combination"] = mode.combination;
    if (mode.backbone) {
      const Backbone& b = *mode.backbone;
      m["backbone"] = {{"time_s", b.time_s},
                       {"amplitude", b.amplitude},
                       {"frequency_hz", b.frequency_hz},
                       {"damping_ratio", b.damping_ratio},
                       {"std_frequency_hz", b.std_frequency_hz},
                       {"std_damping_ratio", b.std_damping_ratio},
                       {"amplitude_dependent", b.amplitude_dependent},
                       {"spread_chi_square_per_dof", b.spread_chi_square_per_dof}};
      if (b.hilbert) {
        const BackboneCurve& h = *b.hilbert;
        m["backbone"]["hilbert"] = {{"time_s", h.time_s},
                                    {"amplitude", h.amplitude},
                                    {"frequency_hz", h.frequency_hz},
                                    {"damping_ratio", h.damping_ratio},
                                    {"std_frequency_hz", h.std_frequency_hz},
                                    {"std_damping_ratio", h.std_damping_ratio}};
      }
    }
    modes.push_back(m);
  }
  json["modes"] = modes;
  json["correlation"] = PerChannel(result.channels, result.correlation);

  json["reliable"] = result.reliable;
  json["reasons"] = result.reasons;
  json["min_correlation"] = result.min_correlation;
  if (result.drift_per_s.size() > 0) {
    json["drift_per_s"] = PerChannel(result.channels, result.drift_per_s);
  }
  json["release_time_s"] = result.release_time_s;
  json["release"] = result.release;
  if (result.next_excitation_s) json["next_excitation_s"] = *result.next_excitation_s;
  json["start_time_s"] = result.start_time_s;
  json["decimation"] = result.decimation;
  json["max_frequency_hz"] = NumberOrNull(result.max_frequency_hz);
  json["significance_threshold"] = NumberOrNull(result.significance_threshold);
  json["offset"] = PerChannel(result.channels, result.offset);
  json["noise_std"] = PerChannel(result.channels, result.noise_std);
  if (result.residual_to_noise.size() > 0) {
    json["residual_to_noise"] = PerChannel(result.channels, result.residual_to_noise);
    json["residual_window_ratio"] = PerChannel(result.channels, result.residual_window_ratio);
  }
  json["termination"] = result.termination;
  json["iterations"] = result.iterations;
  if (result.has_spectrum) {
    nlohmann::json peaks = nlohmann::json::array();
    for (const SpectrumPeak& peak : result.spectrum.peaks) {
      peaks.push_back({{"channel", result.channels.at(peak.channel)},
                       {"frequency_hz", peak.frequency_hz},
                       {"amplitude", peak.amplitude},
                       {"prominence", peak.prominence}});
    }
    json["spectrum_peaks"] = peaks;
  }
  if (!result.stabilization.empty()) {
    nlohmann::json orders = nlohmann::json::array();
    for (const StabilizationOrder& order : result.stabilization) {
      nlohmann::json frequency = nlohmann::json::array();
      nlohmann::json decay = nlohmann::json::array();
      for (const auto& lambda : order.lambda) {
        frequency.push_back(NumberOrNull(lambda.imag() / (2 * M_PI)));
        decay.push_back(NumberOrNull(-lambda.real()));
      }
      orders.push_back({{"order", order.order},
                        {"frequency_hz", frequency},
                        {"decay_rate_per_s", decay},
                        {"stable", order.stable}});
    }
    json["stabilization"] = orders;
  }
  if (result.eq2_coefficients.size() > 0) {
    nlohmann::json rows = nlohmann::json::array();
    for (Eigen::Index r = 0; r < result.eq2_coefficients.rows(); ++r) {
      nlohmann::json row = nlohmann::json::array();
      for (Eigen::Index c = 0; c < result.eq2_coefficients.cols(); ++c) {
        row.push_back(NumberOrNull(result.eq2_coefficients(r, c)));
      }
      rows.push_back(row);
    }
    json["eq2_coefficients"] = rows;
  }
  json["warnings"] = result.warnings;
  return json;
}

void WriteModalResult(H5Writer& writer, const ModalResult& result, const std::string& group) {
  const auto sub = [&group](const std::string& name) { return group + "/" + name; };
  writer.WriteStringAttribute(group, "method", result.method);
  writer.WriteStrings(group, "channels", result.channels);
  writer.WriteScalar(group, "sample_interval_s", result.sample_interval_s, "s");
  writer.WriteScalar(group, "samples", result.samples, "1");
  writer.WriteScalar(group, "model_order", result.model_order, "1");
  writer.WriteScalar(group, "effective_rank", result.effective_rank, "1");
  writer.WriteScalar(group, "start_time_s", result.start_time_s, "s");
  writer.WriteScalar(group, "decimation", result.decimation, "1");
  writer.WriteScalar(group, "max_frequency_hz", result.max_frequency_hz, "Hz");
  writer.WriteScalar(group, "release_time_s", result.release_time_s, "s");
  writer.WriteStringAttribute(group, "release", result.release);
  if (result.next_excitation_s) {
    writer.WriteScalar(group, "next_excitation_s", *result.next_excitation_s, "s");
  }
  writer.WriteStringAttribute(group, "reliable", result.reliable ? "true" : "false");
  writer.WriteStrings(group, "reasons", result.reasons);
  writer.WriteScalar(group, "significance_threshold", result.significance_threshold, "1");
  writer.WriteScalar(group, "iterations", result.iterations, "1");
  writer.WriteStringAttribute(group, "termination", result.termination);

  const std::string modes = sub("modes");
  const auto write_mode_vector = [&](const char* name, const char* units, auto get) {
    writer.WriteVector(modes, name, ModeVector(result, get), units);
  };
  for (size_t k = 0; k < result.modes.size(); ++k) {
    if (!result.modes[k].backbone) continue;
    const Backbone& b = *result.modes[k].backbone;
    const std::string backbone_group = modes + "/backbone/" + std::to_string(k);
    const auto vector = [](const std::vector<double>& v) {
      return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()))
          .eval();
    };
    const auto write_curve = [&](const std::string& curve_group, const BackboneCurve& curve) {
      writer.WriteVector(curve_group, "time_s", vector(curve.time_s), "s");
      writer.WriteVector(curve_group, "amplitude", vector(curve.amplitude),
                         "units of the mode's largest channel");
      writer.WriteVector(curve_group, "frequency_hz", vector(curve.frequency_hz), "Hz");
      writer.WriteVector(curve_group, "damping_ratio", vector(curve.damping_ratio), "1");
      writer.WriteVector(curve_group, "std_frequency_hz", vector(curve.std_frequency_hz), "Hz");
      writer.WriteVector(curve_group, "std_damping_ratio", vector(curve.std_damping_ratio), "1");
    };
    write_curve(backbone_group, b);
    if (b.hilbert) write_curve(backbone_group + "/hilbert", *b.hilbert);
    writer.WriteStringAttribute(backbone_group, "amplitude_dependent",
                                b.amplitude_dependent ? "true" : "false");
  }
  write_mode_vector("frequency_hz", "Hz", [](const IdentifiedMode& m) { return m.frequency_hz; });
  write_mode_vector("decay_rate_per_s", "1/s",
                    [](const IdentifiedMode& m) { return m.decay_rate_per_s; });
  write_mode_vector("damping_ratio", "1", [](const IdentifiedMode& m) { return m.damping_ratio; });
  write_mode_vector("undamped_frequency_hz", "Hz",
                    [](const IdentifiedMode& m) { return m.undamped_frequency_hz; });
  write_mode_vector("log_decrement", "1", [](const IdentifiedMode& m) { return m.log_decrement; });
  write_mode_vector("half_life_s", "s", [](const IdentifiedMode& m) { return m.half_life_s; });
  write_mode_vector("std_frequency_hz", "Hz",
                    [](const IdentifiedMode& m) { return m.std_frequency_hz; });
  write_mode_vector("std_decay_rate_per_s", "1/s",
                    [](const IdentifiedMode& m) { return m.std_decay_rate_per_s; });
  write_mode_vector("significance", "1", [](const IdentifiedMode& m) { return m.significance; });
  write_mode_vector("significant", "1",
                    [](const IdentifiedMode& m) { return m.significant ? 1.0 : 0.0; });
  std::vector<std::string> combination;
  for (const IdentifiedMode& mode : result.modes) combination.push_back(mode.combination);
  writer.WriteStrings(modes, "combination", combination);
  for (size_t c = 0; c < result.channels.size(); ++c) {
    const std::string& channel = result.channels[c];
    writer.WriteVector(modes + "/amplitude", channel,
                       ModeVector(result, [c](const IdentifiedMode& m) { return m.amplitude(c); }),
                       UnitOf(result, c));
    writer.WriteVector(modes + "/phase_rad", channel,
                       ModeVector(result, [c](const IdentifiedMode& m) { return m.phase_rad(c); }),
                       "rad");
    writer.WriteScalar(sub("correlation"), channel, result.correlation(c), "1");
    writer.WriteScalar(sub("offset"), channel, result.offset(c), UnitOf(result, c));
    writer.WriteScalar(sub("noise_std"), channel, result.noise_std(c), UnitOf(result, c));
    if (result.residual_to_noise.size() > 0) {
      writer.WriteScalar(sub("residual_to_noise"), channel, result.residual_to_noise(c), "1");
      writer.WriteScalar(sub("residual_window_ratio"), channel, result.residual_window_ratio(c),
                         "1");
    }
    if (result.drift_per_s.size() > 0) {
      writer.WriteScalar(sub("drift_per_s"), channel, result.drift_per_s(c),
                         UnitOf(result, c) + "/s");
    }
    writer.WriteVector(sub("reconstruction"), channel, result.reconstruction.col(c),
                       UnitOf(result, c));
  }
  writer.WriteVector(sub("reconstruction"), "time",
                     Eigen::VectorXd::LinSpaced(result.samples, 0.0, 1.0) * (result.samples - 1) *
                             result.sample_interval_s +
                         Eigen::VectorXd::Constant(result.samples, result.start_time_s),
                     "s");

  if (result.has_spectrum) {
    const std::string spectrum = sub("spectrum");
    writer.WriteVector(spectrum, "frequency_hz", result.spectrum.frequency_hz, "Hz");
    for (size_t c = 0; c < result.channels.size(); ++c) {
      writer.WriteVector(spectrum, result.channels[c], result.spectrum.amplitude.col(c),
                         UnitOf(result, c));
    }
    const auto& peaks = result.spectrum.peaks;
    Eigen::VectorXd channel(peaks.size()), frequency(peaks.size()), amplitude(peaks.size()),
        prominence(peaks.size());
    for (size_t i = 0; i < peaks.size(); ++i) {
      channel(i) = peaks[i].channel;
      frequency(i) = peaks[i].frequency_hz;
      amplitude(i) = peaks[i].amplitude;
      prominence(i) = peaks[i].prominence;
    }
    writer.WriteVector(spectrum, "peaks_channel", channel, "1");
    writer.WriteVector(spectrum, "peaks_frequency_hz", frequency, "Hz");
    writer.WriteVector(spectrum, "peaks_amplitude", amplitude, "");
    writer.WriteVector(spectrum, "peaks_prominence", prominence, "");
  }

  if (!result.stabilization.empty()) {
    std::vector<double> order, frequency, decay, damping, stable;
    for (const StabilizationOrder& entry : result.stabilization) {
      for (size_t i = 0; i < entry.lambda.size(); ++i) {
        IdentifiedMode pole;
        pole.SetPole(entry.lambda[i]);
        order.push_back(entry.order);
        frequency.push_back(pole.frequency_hz);
        decay.push_back(pole.decay_rate_per_s);
        damping.push_back(pole.damping_ratio);
        stable.push_back(entry.stable[i] ? 1.0 : 0.0);
      }
    }
    const auto as_vector = [](const std::vector<double>& v) {
      return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
    };
    const std::string stabilization = sub("stabilization");
    writer.WriteVector(stabilization, "order", as_vector(order), "1");
    writer.WriteVector(stabilization, "frequency_hz", as_vector(frequency), "Hz");
    writer.WriteVector(stabilization, "decay_rate_per_s", as_vector(decay), "1/s");
    writer.WriteVector(stabilization, "damping_ratio", as_vector(damping), "1");
    writer.WriteVector(stabilization, "stable", as_vector(stable), "1");
  }
  if (result.eq2_coefficients.size() > 0) {
    writer.WriteMatrix(group, "eq2_coefficients", result.eq2_coefficients, "");
  }
}

}  // namespace mbid::identification
