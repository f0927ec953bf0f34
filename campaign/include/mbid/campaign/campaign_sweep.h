#pragma once

#include <yaml-cpp/yaml.h>

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "mbid/common/yaml_reader.h"

namespace mbid::campaign {

// One value given to one scenario key: `key` is a dotted path into the scenario
// ("model.configuration.boom_elevation_deg", "model.base.com_m[2]"), `value` any YAML node.
struct Assignment {
  Assignment() = default;
  Assignment(std::string key_in, YAML::Node value_in, std::string field_in)
      : key(std::move(key_in)), value(std::move(value_in)), field(std::move(field_in)) {}
  Assignment(const Assignment&) = default;

  std::string key;
  YAML::Node value;
  std::string field;  // where the campaign file gives it ("sweep[1].grid.<key>"), for errors

  // yaml-cpp's Node::operator= writes through to the node it refers to (the campaign file's
  // value!); assigning an Assignment must rebind instead.
  Assignment& operator=(const Assignment& other) {
    key = other.key;
    value.reset(other.value);
    field = other.field;
    return *this;
  }
};

// Sets `value` at the dotted `key` of the scenario tree `root`, creating missing maps on the
// way (`[i]` indexes an existing list). Throws InputError at `where` if the path runs through a
// value that is not a map, or an index is out of range.
void ApplyAssignment(YAML::Node& root, const Assignment& assignment, const YamlReader& where);

// The scalar text of a value ("30", "1.5e-05") or its flow-style YAML ("[psi, phi]").
std::string ValueText(const YAML::Node& value);

// A YAML scalar holding `value` in the shortest form that reads back to the same double.
YAML::Node NumberNode(double value);

// The cases of a `sweep:` list of factors, combined as a Cartesian product in the order given
// (the last factor varies fastest). Factors:
//   grid: {key: [v1, v2, ...], ...}        every combination of the keys' values (last fastest)
//   list: {key: [v1, ...], key2: [...]}    the i-th values of all keys together (equal lengths)
//   latin_hypercube: {samples: N, ranges: {key: [lo, hi] | {min, max, scale: linear|log}}}
//                                          N points, one in each of N strata per key, seeded
//   repeat: N                              N copies (they differ by their derived sensor seed)
// An absent or empty sweep gives one case. Each case is its list of assignments, in the order
// the keys appear. `seed` drives the Latin hypercube; the result depends on nothing else.
struct SweepPlan {
  std::vector<std::string> keys;                     // swept keys, in order of appearance
  std::vector<std::vector<Assignment>> assignments;  // one list per case
};
SweepPlan ReadSweep(const YamlReader& campaign, std::uint64_t seed);

// Seeds derived from the campaign seed: a 64-bit mix (SplitMix64) of the seed and a stream
// number, so that cases and factors get independent, reproducible streams.
std::uint64_t DeriveSeed(std::uint64_t campaign_seed, std::uint64_t stream);

}  // namespace mbid::campaign
