#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>

#include "mbid/campaign/campaign_sweep.h"
#include "mbid/common/error.h"

namespace mbid::campaign {
namespace {

constexpr size_t kMaxCases = 1000000;  // beyond this a typo in a grid, not a campaign

struct PathStep {
  std::string key;
  int index = -1;  // -1: no [i]
};

// "a.b[2].c" -> {a}, {b, 2}, {c}; an empty or malformed component is an error at `field`.
std::vector<PathStep> ParsePath(const std::string& path, const YamlReader& where,
                                const std::string& field) {
  std::vector<PathStep> steps;
  size_t start = 0;
  while (true) {
    const size_t dot = path.find('.', start);
    const std::string part = path.substr(start, dot == std::string::npos ? dot : dot - start);
    PathStep step;
    const size_t bracket = part.find('[');
    step.key = part.substr(0, bracket);
    if (bracket != std::string::npos) {
      const std::string index = part.substr(bracket + 1);
      char* end = nullptr;
      const long value = std::strtol(index.c_str(), &end, 10);
      if (index.empty() || end == index.c_str() || std::string(end) != "]" || value < 0) {
        where.FailAt(field, "malformed index in key '" + path + "'",
                     "a dotted scenario key such as model.base.com_m[2]");
      }
      step.index = static_cast<int>(value);
    }
    if (step.key.empty()) {
      where.FailAt(field, "empty component in key '" + path + "'",
                   "a dotted scenario key such as model.configuration.boom_elevation_deg");
    }
    steps.push_back(step);
    if (dot == std::string::npos) break;
    start = dot + 1;
  }
  return steps;
}

// Uniform in [0, 1) from the top 53 bits: the same on every platform (unlike
// std::uniform_real_distribution, whose algorithm the standard leaves open).
double Uniform01(std::mt19937_64& generator) {
  return static_cast<double>(generator() >> 11) * 0x1.0p-53;
}

std::vector<YAML::Node> ValueList(const YamlReader& factor, const std::string& key) {
  const YamlReader values = factor.Child(key);
  if (!values.node().IsSequence() || values.node().size() == 0) {
    values.Fail("is not a non-empty list", "a list of values for this key, e.g. [10, 20, 30]");
  }
  std::vector<YAML::Node> list;
  for (const YAML::Node& value : values.node()) list.push_back(value);
  return list;
}

using CaseList = std::vector<std::vector<Assignment>>;

CaseList ReadGrid(const YamlReader& grid) {
  CaseList cases{{}};
  for (const std::string& key : grid.Keys()) {
    const std::vector<YAML::Node> values = ValueList(grid, key);
    // Counted before the product is built: a typo in a grid must not allocate gigabytes first.
    if (cases.size() * values.size() > kMaxCases) {
      grid.Fail(std::to_string(cases.size() * values.size()) + " combinations",
                "at most 1000000 cases");
    }
    CaseList next;
    for (const auto& partial : cases) {
      for (const YAML::Node& value : values) {
        next.push_back(partial);
        next.back().push_back({key, value, grid.field() + "." + key});
      }
    }
    cases = std::move(next);
  }
  return cases;
}

CaseList ReadList(const YamlReader& list) {
  CaseList cases;
  std::string first_key;
  for (const std::string& key : list.Keys()) {
    const std::vector<YAML::Node> values = ValueList(list, key);
    if (first_key.empty()) {
      first_key = key;
      cases.resize(values.size());
    } else if (values.size() != cases.size()) {
      list.FailAt(key, fmt::format("{} values", values.size()),
                  fmt::format("as many values as '{}' ({})", first_key, cases.size()));
    }
    for (size_t i = 0; i < values.size(); ++i) {
      cases[i].push_back({key, values[i], list.field() + "." + key});
    }
  }
  return cases;
}

CaseList ReadLatinHypercube(const YamlReader& lhs, std::uint64_t seed) {
  lhs.ExpectMap({"samples", "ranges"});
  const int samples = lhs.Int("samples");
  if (samples < 1 || static_cast<size_t>(samples) > kMaxCases) {
    lhs.FailAt("samples", std::to_string(samples), "an integer between 1 and 1000000");
  }
  const YamlReader ranges = lhs.Child("ranges");
  CaseList cases(static_cast<size_t>(samples));
  std::mt19937_64 generator(seed);
  for (const std::string& key : ranges.Keys()) {
    const YamlReader range = ranges.Child(key);
    double low = 0, high = 0;
    bool log_scale = false;
    if (range.node().IsSequence()) {
      if (range.node().size() != 2) range.Fail("is not a pair", "[low, high]");
      low = YamlReader(range.node()[0], range.source(), range.field() + "[0]").AsDouble();
      high = YamlReader(range.node()[1], range.source(), range.field() + "[1]").AsDouble();
    } else {
      range.ExpectMap({"min", "max", "scale"});
      low = range.Double("min");
      high = range.Double("max");
      log_scale = range.Choice("scale", {"linear", "log"}, "linear") == "log";
    }
    if (!(low < high)) {
      range.Fail(fmt::format("range [{}, {}]", low, high), "low < high");
    }
    if (log_scale && !(low > 0)) {
      range.Fail(fmt::format("log scale from {}", low), "a positive lower bound for scale: log");
    }
    // One sample in each of the N equal strata, in a random order (McKay et al., 1979).
    std::vector<int> strata(static_cast<size_t>(samples));
    for (int i = 0; i < samples; ++i) strata[static_cast<size_t>(i)] = i;
    for (int i = samples - 1; i > 0; --i) {
      std::swap(strata[static_cast<size_t>(i)],
                strata[static_cast<size_t>(generator() % static_cast<std::uint64_t>(i + 1))]);
    }
    for (int i = 0; i < samples; ++i) {
      const double u = (strata[static_cast<size_t>(i)] + Uniform01(generator)) / samples;
      const double value = log_scale
                               ? std::exp(std::log(low) + u * (std::log(high) - std::log(low)))
                               : low + u * (high - low);
      cases[static_cast<size_t>(i)].push_back({key, NumberNode(value), ranges.field() + "." + key});
    }
  }
  return cases;
}

}  // namespace

std::uint64_t DeriveSeed(std::uint64_t campaign_seed, std::uint64_t stream) {
  // SplitMix64 (Steele, Lea, Flood 2014) of the seed advanced by `stream` golden-ratio steps.
  std::uint64_t z = campaign_seed + (stream + 1) * 0x9E3779B97F4A7C15ULL;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

YAML::Node NumberNode(double value) { return YAML::Node(fmt::format("{}", value)); }

std::string ValueText(const YAML::Node& value) {
  if (value.IsScalar()) return value.Scalar();
  YAML::Emitter out;
  out.SetMapFormat(YAML::Flow);
  out.SetSeqFormat(YAML::Flow);
  out << value;
  return out.c_str();
}

void ApplyAssignment(YAML::Node& root, const Assignment& assignment, const YamlReader& where) {
  const std::vector<PathStep> steps = ParsePath(assignment.key, where, assignment.field);
  YAML::Node node = root;  // yaml-cpp nodes are references: walk with reset(), never operator=
  for (size_t s = 0; s < steps.size(); ++s) {
    const PathStep& step = steps[s];
    const bool last = s + 1 == steps.size();
    if (!node.IsMap() && !node.IsNull()) {
      where.FailAt(assignment.field,
                   fmt::format("key '{}' runs through a value that is not a map (at '{}')",
                               assignment.key, step.key),
                   "a path through scenario sections");
    }
    if (step.index < 0) {
      if (last) {
        node[step.key] = YAML::Clone(assignment.value);
        return;
      }
      if (!node[step.key].IsDefined() || node[step.key].IsNull()) {
        node[step.key] = YAML::Node(YAML::NodeType::Map);
      }
      node.reset(node[step.key]);
      continue;
    }
    YAML::Node list = node[step.key];
    if (!list.IsSequence() || static_cast<size_t>(step.index) >= list.size()) {
      where.FailAt(assignment.field,
                   fmt::format("key '{}': '{}' is not a list with an element {}", assignment.key,
                               step.key, step.index),
                   "an index into an existing list of the scenario");
    }
    if (last) {
      list[static_cast<size_t>(step.index)] = YAML::Clone(assignment.value);
      return;
    }
    node.reset(list[static_cast<size_t>(step.index)]);
  }
}

SweepPlan ReadSweep(const YamlReader& campaign, std::uint64_t seed) {
  SweepPlan plan;
  plan.assignments = {{}};
  if (!campaign.Has("sweep")) return plan;
  const YamlReader sweep = campaign.Child("sweep");
  if (sweep.node().IsNull()) return plan;
  if (!sweep.node().IsSequence()) {
    sweep.Fail("is not a list", "a list of factors (grid, list, latin_hypercube, repeat)");
  }
  std::set<std::string> seen;
  for (size_t f = 0; f < sweep.node().size(); ++f) {
    const YamlReader factor(sweep.node()[f], sweep.source(), fmt::format("sweep[{}]", f));
    factor.ExpectMap({"grid", "list", "latin_hypercube", "repeat"});
    const std::vector<std::string> kinds = factor.Keys();
    if (kinds.size() != 1) {
      factor.Fail(fmt::format("{} factor kinds in one entry", kinds.size()),
                  "exactly one of grid, list, latin_hypercube, repeat per list entry");
    }
    const std::string& kind = kinds.front();
    CaseList factor_cases;
    if (kind == "grid") {
      factor_cases = ReadGrid(factor.Child("grid"));
    } else if (kind == "list") {
      factor_cases = ReadList(factor.Child("list"));
    } else if (kind == "latin_hypercube") {
      factor_cases = ReadLatinHypercube(factor.Child("latin_hypercube"),
                                        DeriveSeed(seed, 0x4C48530000000000ULL + f));
    } else {
      const int copies = factor.Int("repeat");
      if (copies < 1 || static_cast<size_t>(copies) > kMaxCases) {
        factor.FailAt("repeat", std::to_string(copies), "an integer from 1 to 1000000");
      }
      factor_cases.assign(static_cast<size_t>(copies), {});
    }
    if (factor_cases.empty()) factor.Fail("gives no cases", "at least one key with values");
    for (const Assignment& assignment : factor_cases.front()) {
      if (!seen.insert(assignment.key).second) {
        throw InputError(sweep.source(), assignment.field,
                         "key '" + assignment.key + "' swept twice", "each key in one factor only");
      }
      plan.keys.push_back(assignment.key);
    }
    CaseList combined;
    if (plan.assignments.size() * factor_cases.size() > kMaxCases) {
      factor.Fail("too many cases in the product", "at most 1000000 cases");
    }
    for (const auto& outer : plan.assignments) {
      for (const auto& inner : factor_cases) {
        combined.push_back(outer);
        combined.back().insert(combined.back().end(), inner.begin(), inner.end());
      }
    }
    plan.assignments = std::move(combined);
  }
  return plan;
}

}  // namespace mbid::campaign
