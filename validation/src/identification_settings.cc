#include "mbid/validation/identification_settings.h"

#include <fmt/format.h>

#include <cmath>
#include <limits>

#include "mbid/common/error.h"
#include "mbid/common/hdf5_io.h"
#include "mbid/identification/identify.h"
#include "mbid/records/records.h"
#include "mbid/validation/scenario.h"

namespace mbid::validation {

identification::IdentificationOptions ReadIdentificationSettings(const YamlReader& section) {
  identification::IdentificationOptions options;
  if (section.node().IsNull()) return options;
  section.ExpectMap({"method",
                     "window_start_s",
                     "window_end_s",
                     "channels",
                     "offset",
                     "decimation",
                     "min_frequency_hz",
                     "max_frequency_hz",
                     "min_damping_ratio",
                     "max_damping_ratio",
                     "max_decay_rate_per_s",
                     "max_modes",
                     "significance_false_alarm",
                     "min_significance",
                     "drop_insignificant",
                     "compute_spectrum",
                     "compute_stabilization",
                     "compute_uncertainty",
                     "extra_orders",
                     "min_correlation",
                     "backbone",
                     "remove_drift",
                     "skip_clipped",
                     "prony"});
  const std::string method = section.Choice("method", identification::MethodNames(),
                                            identification::Method::kHankelNls.name());
  identification::ParseMethod(method, &options.method);
  options.window_start_s = section.Double("window_start_s", options.window_start_s);
  options.window_end_s = section.Double("window_end_s", options.window_end_s);
  if (section.Has("channels")) options.channels = section.StringList("channels");
  const std::string offset = section.Choice("offset", {"none", "mean", "fit"}, "fit");
  options.offset = offset == "none"   ? identification::OffsetRemoval::kNone
                   : offset == "mean" ? identification::OffsetRemoval::kMean
                                      : identification::OffsetRemoval::kFit;
  options.decimation = section.Int("decimation", options.decimation);
  options.min_correlation = section.Double("min_correlation", options.min_correlation);
  options.min_frequency_hz = section.Double("min_frequency_hz", options.min_frequency_hz);
  options.max_frequency_hz = section.Double("max_frequency_hz", options.max_frequency_hz);
  options.min_damping_ratio = section.Double("min_damping_ratio", options.min_damping_ratio);
  options.max_damping_ratio = section.Double("max_damping_ratio", options.max_damping_ratio);
  options.max_decay_rate_per_s =
      section.Double("max_decay_rate_per_s", options.max_decay_rate_per_s);
  options.max_modes = section.Int("max_modes", options.max_modes);
  options.hankel.extra_orders = section.Int("extra_orders", options.hankel.extra_orders);
  options.significance_false_alarm =
      section.Double("significance_false_alarm", options.significance_false_alarm);
  options.min_significance = section.Double("min_significance", options.min_significance);
  options.drop_insignificant = section.Bool("drop_insignificant", options.drop_insignificant);
  options.compute_spectrum = section.Bool("compute_spectrum", options.compute_spectrum);
  options.compute_stabilization =
      section.Bool("compute_stabilization", options.compute_stabilization);
  options.compute_uncertainty = section.Bool("compute_uncertainty", options.compute_uncertainty);
  options.remove_drift = section.Bool("remove_drift", options.remove_drift);
  options.skip_clipped = section.Bool("skip_clipped", options.skip_clipped);
  identification::ParseBackboneMode(
      section.Choice("backbone", {"clusters", "always", "never"},
                     identification::BackboneModeName(options.backbone)),
      &options.backbone);
  if (section.Has("prony")) {
    const YamlReader prony = section.Child("prony");
    prony.ExpectMap({"order", "rank_tolerance", "noise_floor_factor"});
    options.prony.order = prony.Int("order", options.prony.order);
    options.prony.noise_floor_factor =
        prony.Double("noise_floor_factor", options.prony.noise_floor_factor);
    options.prony.rank_tolerance = prony.Double("rank_tolerance", options.prony.rank_tolerance);
  }
  std::string why;
  if (!options.IsValid(&why)) {
    // IsValid names the option ("max_modes: 0 is out of range; expected ..."); keep its words.
    const size_t colon = why.find(": ");
    const size_t expected = why.find("; expected ");
    if (colon != std::string::npos && expected != std::string::npos) {
      throw InputError(section.source(), section.field() + "." + why.substr(0, colon),
                       why.substr(colon + 2, expected - colon - 2), why.substr(expected + 11));
    }
    section.Fail(why, "identification options in range");
  }
  return options;
}

identification::IdentificationOptions FreeDecayOptions(
    identification::IdentificationOptions options, const simulation::Excitation& excitation) {
  const double forcing_end = excitation.CalcForcingEndTime();
  if (forcing_end > 0 && !std::isfinite(options.window_start_s)) {
    if (options.release == identification::ReleaseMode::kDetect) {
      // The free decay starts where the forcing ends: that is the result's release_time_s.
      options.release = identification::ReleaseMode::kForcingEnd;
      options.release_time_s = forcing_end;
    } else {
      options.window_start_s = forcing_end;
    }
  }
  return options;
}

identification::ModalResult IdentifyForTheFit(const Measurement& record,
                                              const identification::IdentificationOptions& options,
                                              const std::string& origin) {
  try {
    return identification::Identify(record, options, origin);
  } catch (const NumericalError& error) {
    if (error.reason().rfind("no modes found", 0) != 0) throw;
    // An overdamped machine (every joint past critical: what damper sizing designs) rings at no
    // frequency; the time-domain fit needs no modes and tunes its joints from the decay alone.
    identification::ModalResult nothing;
    nothing.channels = record.channels;
    nothing.units = record.units;
    nothing.sample_interval_s = record.sample_interval_s;
    nothing.samples = record.samples();
    nothing.start_time_s = record.start_time_s;
    nothing.release_time_s = record.start_time_s;
    const Eigen::Index m = record.channel_count();
    nothing.noise_std = Eigen::VectorXd::Zero(m);  // no weights from it
    // No mode reconstructs nothing of the record: K 0 in every channel.
    nothing.correlation = Eigen::VectorXd::Zero(m);
    nothing.offset = Eigen::VectorXd::Zero(m);
    nothing.reconstruction = Eigen::MatrixXd::Zero(record.samples(), m);
    nothing.reliable = false;
    nothing.reasons.push_back(
        error.reason() +
        " (an overdamped machine rings at no frequency; its joints are tuned to the record by "
        "the time-domain fit alone, without Route 1)");
    return nothing;
  }
}

std::string ReadRecordScenario(const std::string& path) {
  const std::string lower = records::LowerExtension(path);
  return lower == ".h5" || lower == ".hdf5" ? ReadScenarioYaml(path) : std::string();
}

identification::IdentificationOptions RecordFileOptions(
    const std::string& scenario_yaml, const std::string& origin,
    const identification::IdentificationOptions& options, std::string* said) {
  said->clear();
  if (scenario_yaml.empty() || options.release != identification::ReleaseMode::kDetect ||
      std::isfinite(options.window_start_s)) {
    return options;
  }
  try {
    const Scenario test = LoadScenarioFromText(scenario_yaml, origin);
    if (!test.has_excitation || !(test.excitation.CalcForcingEndTime() > 0)) return options;
    *said = fmt::format("free decay after the {} that ends at {:.6g} s (the record's scenario)",
                        test.excitation.type_name(), test.excitation.CalcForcingEndTime());
    return FreeDecayOptions(options, test.excitation);
  } catch (const InputError&) {
    return options;  // a scenario this version cannot read: the record as any other
  }
}

}  // namespace mbid::validation
