#pragma once

#include <yaml-cpp/yaml.h>

#include <array>
#include <initializer_list>
#include <string>
#include <vector>

namespace mbid {

// A YAML node with the file and dotted field path it came from, so that every error names both
// ("scenario.yaml:model.base.mass_kg: ..."). Reading is strict: unknown keys are errors that
// suggest the closest known key, and a key given without its unit suffix ("duration" for
// "duration_s") is reported as a missing unit.
class YamlReader {
 public:
  // Parses `path`; a syntax error is an InputError naming the file and line.
  static YamlReader FromFile(const std::string& path);
  // Parses `text`; `source` names it in errors.
  static YamlReader FromString(const std::string& text, const std::string& source);

  YamlReader(YAML::Node node, std::string source, std::string field);

  const std::string& source() const { return source_; }
  const std::string& field() const { return field_; }  // dotted path, "" at the root
  const YAML::Node& node() const { return node_; }

  bool IsMap() const { return node_.IsMap(); }
  bool Has(const std::string& key) const;
  // Throws unless this is a map whose keys are all in `known`.
  void ExpectMap(std::initializer_list<const char*> known) const;
  void ExpectMap(const std::vector<std::string>& known) const;
  std::vector<std::string> Keys() const;

  // A child; a missing required child is an InputError.
  YamlReader Child(const std::string& key) const;

  // Typed values of children. Each checks type and finiteness; `Positive` variants also require
  // > 0. The defaulted forms return `fallback` when the key is absent.
  double Double(const std::string& key) const;
  double Double(const std::string& key, double fallback) const;
  double PositiveDouble(const std::string& key) const;
  double PositiveDouble(const std::string& key, double fallback) const;
  int Int(const std::string& key) const;
  int Int(const std::string& key, int fallback) const;
  // An integer in [min, max]; one message for a value out of range on either side.
  int IntInRange(const std::string& key, int fallback, int min, int max) const;
  // A random seed: an integer in [0, 2147483647].
  int Seed(const std::string& key, int fallback) const;
  bool Bool(const std::string& key, bool fallback) const;
  std::string String(const std::string& key) const;
  std::string String(const std::string& key, const std::string& fallback) const;
  // One of `choices`; otherwise the error lists them.
  std::string Choice(const std::string& key, const std::vector<std::string>& choices,
                     const std::string& fallback) const;
  std::array<double, 3> Vector3(const std::string& key) const;
  std::vector<std::string> StringList(const std::string& key) const;

  // Values of this node itself.
  double AsDouble() const;
  std::string AsString() const;

  // An InputError at this node (or at its child `key`).
  [[noreturn]] void Fail(const std::string& problem, const std::string& expected) const;
  [[noreturn]] void FailAt(const std::string& key, const std::string& problem,
                           const std::string& expected) const;

 private:
  std::string ChildField(const std::string& key) const;
  int RequiredIntInRange(const std::string& key, int min, int max) const;

  YAML::Node node_;
  std::string source_;
  std::string field_;
};

// The candidate closest to `word` by edit distance (for "did you mean" suggestions).
std::string ClosestMatch(const std::string& word, const std::vector<std::string>& candidates);

}  // namespace mbid
