#include "mbid/simulation/scenario_sections.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "mbid/common/error.h"

namespace mbid::simulation {
namespace {

bool Contains(const std::vector<std::string>& names, const std::string& name) {
  return std::find(names.begin(), names.end(), name) != names.end();
}

}  // namespace

std::map<std::string, double> ReadChannelValues(const YamlReader& sensors, const std::string& key,
                                                const std::vector<std::string>& channels,
                                                bool non_negative) {
  std::map<std::string, double> values;
  if (!sensors.Has(key)) return values;
  const YamlReader node = sensors.Child(key);
  if (node.IsMap()) {
    node.ExpectMap(channels);
    for (const std::string& channel : node.Keys()) values[channel] = node.Double(channel);
  } else {
    const double value = sensors.Double(key);
    for (const std::string& channel : channels) values[channel] = value;
  }
  for (const auto& [channel, value] : values) {
    if (non_negative && value < 0) {
      sensors.FailAt(key, "negative value for " + channel, "a value >= 0 in the channel's unit");
    }
  }
  return values;
}

namespace {

// Sensor keys say their unit: `<base>_rad`, `_m`, `_mps`, `_mps2`, `_radps` for channels in rad,
// m, m/s, m/s^2 and rad/s.
struct UnitSuffix {
  const char* suffix;
  const char* units;
};
constexpr UnitSuffix kUnitSuffixes[] = {
    {"rad", "rad"}, {"m", "m"}, {"mps", "m/s"}, {"mps2", "m/s^2"}, {"radps", "rad/s"}};

}  // namespace

std::vector<std::string> UnitKeys(const std::string& base) {
  std::vector<std::string> keys;
  for (const UnitSuffix& unit : kUnitSuffixes) keys.push_back(base + "_" + unit.suffix);
  return keys;
}

std::map<std::string, std::string> ChannelUnits(const model::MechanicalModel& model) {
  std::map<std::string, std::string> units;
  for (int i = 0; i < model.output_count(); ++i) {
    units[model.output_names()[static_cast<size_t>(i)]] =
        model.output_units()[static_cast<size_t>(i)];
  }
  const std::vector<std::string> coordinate_units = model.coordinate_units();
  for (int i = 0; i < model.coordinate_count(); ++i) {
    // An output of the same name wins, as in the channel lookup.
    units.emplace(model.coordinate_names()[static_cast<size_t>(i)],
                  coordinate_units[static_cast<size_t>(i)]);
  }
  return units;
}

std::map<std::string, double> ReadPerUnitChannelValues(const YamlReader& node,
                                                       const std::string& base,
                                                       const std::vector<std::string>& channels,
                                                       const model::MechanicalModel& model,
                                                       bool non_negative) {
  const std::map<std::string, std::string> units = ChannelUnits(model);
  // Each unit's key read as ReadChannelValues reads one, over that unit's channels; first the
  // two mistakes its generic errors would describe poorly.
  std::map<std::string, double> values;
  for (const UnitSuffix& unit : kUnitSuffixes) {
    const std::string key = base + "_" + unit.suffix;
    if (!node.Has(key)) continue;
    std::vector<std::string> matching;
    for (const std::string& channel : channels) {
      if (units.at(channel) == unit.units) matching.push_back(channel);
    }
    const YamlReader values_node = node.Child(key);
    if (values_node.IsMap()) {
      for (const std::string& channel : values_node.Keys()) {
        const auto found = units.find(channel);
        if (found != units.end() && found->second != unit.units) {
          values_node.FailAt(
              channel, "channel '" + channel + "' is in " + found->second + ", not " + unit.units,
              "the key of the channel's unit");
        }
      }
    } else if (matching.empty()) {
      node.FailAt(key, "no channel is in " + std::string(unit.units),
                  "a key whose unit some channel has");
    }
    values.merge(ReadChannelValues(node, key, matching, non_negative));
  }
  return values;
}

Excitation ReadExcitation(const YamlReader& node, const model::MechanicalModel& model) {
  const std::string type = node.Choice("type", ExcitationTypeNames(), "");
  for (const ExcitationReader& reader : ExcitationReaders()) {
    if (type == reader.type_name) return reader.read(node, model);
  }
  throw std::logic_error("ReadExcitation: no reader for '" + type + "'");
}

IntegratorOptions ReadIntegratorOptions(const YamlReader& node, IntegratorOptions o) {
  node.ExpectMap({"method", "relative_tolerance", "absolute_tolerance", "max_steps", "max_step_s",
                  "interpolate_outputs"});
  using Method = IntegratorOptions::Method;
  const std::string method = node.Choice("method", {"auto", "bdf", "adams"}, MethodName(o.method));
  for (Method m : {Method::kAuto, Method::kBdf, Method::kAdams}) {
    if (method == MethodName(m)) o.method = m;
  }
  o.relative_tolerance = node.PositiveDouble("relative_tolerance", o.relative_tolerance);
  o.absolute_tolerance = node.PositiveDouble("absolute_tolerance", o.absolute_tolerance);
  o.max_steps = node.Int("max_steps", o.max_steps);
  o.max_step_s = node.Double("max_step_s", o.max_step_s);
  o.interpolate_outputs = node.Bool("interpolate_outputs", o.interpolate_outputs);
  std::string why;
  if (!o.IsValid(&why)) node.Fail(why, "valid integrator options (docs/scenarios.md)");
  return o;
}

SimulationOptions ReadSimulationOptions(const YamlReader& node) {
  SimulationOptions options;
  node.ExpectMap({"duration_s", "integrator"});
  options.duration_s = node.PositiveDouble("duration_s", options.duration_s);
  if (node.Has("integrator")) {
    options.integrator = ReadIntegratorOptions(node.Child("integrator"), options.integrator);
  }
  return options;
}

std::vector<std::string> DefaultChannels(const model::MechanicalModel& model) {
  return model.output_names().empty() ? model.coordinate_names() : model.output_names();
}

SensorOptions ReadSensorOptions(const YamlReader& node, const model::MechanicalModel& model) {
  SensorOptions options;
  std::vector<std::string> keys{"sample_rate_hz", "channels", "seed"};
  for (const char* base : {"noise_std", "bias", "quantization_step"}) {
    for (const std::string& key : UnitKeys(base)) keys.push_back(key);
  }
  node.ExpectMap(keys);
  options.sample_rate_hz = node.PositiveDouble("sample_rate_hz", options.sample_rate_hz);
  options.channels = node.Has("channels") ? node.StringList("channels") : DefaultChannels(model);
  if (options.channels.empty()) node.FailAt("channels", "no channel", "at least one channel");
  std::vector<std::string> known = model.output_names();
  known.insert(known.end(), model.coordinate_names().begin(), model.coordinate_names().end());
  for (size_t i = 0; i < options.channels.size(); ++i) {
    const std::string& channel = options.channels[i];
    if (!Contains(known, channel)) {
      node.FailAt("channels", "unknown channel '" + channel + "'",
                  "outputs or coordinates of the model; did you mean '" +
                      ClosestMatch(channel, known) + "'?");
    }
    if (std::count(options.channels.begin(), options.channels.end(), channel) > 1) {
      node.FailAt("channels", "channel '" + channel + "' listed twice", "unique channel names");
    }
  }
  options.noise_std = ReadPerUnitChannelValues(node, "noise_std", options.channels, model, true);
  options.bias = ReadPerUnitChannelValues(node, "bias", options.channels, model, false);
  options.quantization_step =
      ReadPerUnitChannelValues(node, "quantization_step", options.channels, model, true);
  const int seed = node.Seed("seed", 1);
  options.seed = static_cast<std::uint64_t>(seed);
  return options;
}

}  // namespace mbid::simulation
