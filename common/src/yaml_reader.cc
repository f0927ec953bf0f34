#include "mbid/common/yaml_reader.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <set>
#include <vector>

#include "internal.h"
#include "mbid/common/error.h"
#include "mbid/common/utf8.h"

namespace mbid {
namespace {

int EditDistance(const std::string& a, const std::string& b) {
  std::vector<int> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = static_cast<int>(j);
  for (size_t i = 1; i <= a.size(); ++i) {
    int diagonal = row[0];
    row[0] = static_cast<int>(i);
    for (size_t j = 1; j <= b.size(); ++j) {
      const int substitution = diagonal + (a[i - 1] == b[j - 1] ? 0 : 1);
      diagonal = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, substitution});
    }
  }
  return row[b.size()];
}

std::string ToLower(std::string text) {
  for (char& c : text) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return text;
}

std::string Quoted(const std::vector<std::string>& items) {
  std::vector<std::string> quoted;
  for (const auto& item : items) quoted.push_back("'" + item + "'");
  return internal::Join(quoted, " or ");
}

// Suffixes made of short tokens ("s", "kg", "Nm_per_rad", "kgm2") are units; a long token
// ("tolerance") means the known key is a different word, not the same quantity with a unit.
bool LooksLikeUnitSuffix(const std::string& suffix) {
  size_t start = 0;
  while (start <= suffix.size()) {
    size_t end = suffix.find('_', start);
    if (end == std::string::npos) end = suffix.size();
    const size_t length = end - start;
    // Unit words are short (s, m, kg, deg, mps2, per); rad/s is the one of five letters.
    if (length == 0 || (length > 4 && suffix.compare(start, length, "radps") != 0)) return false;
    start = end + 1;
  }
  return true;
}

std::string Describe(const YAML::Node& node) {
  switch (node.Type()) {
    case YAML::NodeType::Null:
      return "empty";
    case YAML::NodeType::Sequence:
      return "a list";
    case YAML::NodeType::Map:
      return "a map";
    case YAML::NodeType::Scalar:
      return "'" + node.Scalar() + "'";
    default:
      return "undefined";
  }
}

// A quoted scalar is a string to YAML even if it looks like a number ("10").
bool IsQuoted(const YAML::Node& node) { return node.Tag() == "!"; }

std::string KnownKeysExpectation(const std::vector<std::string>& known) {
  if (known.empty()) return "no keys here";
  return "one of " + internal::Join(known, ", ");
}

// "did you mean 'x'?" when a candidate is close enough to be a plausible typo.
std::string Suggestion(const std::string& word, const std::vector<std::string>& candidates) {
  const std::string best = ClosestMatch(word, candidates);
  if (best.empty()) return "";
  const int limit = std::max(2, static_cast<int>(word.size()) / 2);
  if (EditDistance(ToLower(word), ToLower(best)) > limit) return "";
  return "did you mean '" + best + "'?";
}

// Where the innermost flow collection ('{' or '[') still open at `line`/`column` (0-based, the
// parser's mark) was opened, with the bracket: yaml-cpp reports an unclosed one where it gave up,
// often lines later. Quoted scalars and comments are skipped; empty if none is open.
struct OpenFlow {
  char bracket = 0;
  int line = 0, column = 0;
};
OpenFlow FindOpenFlow(const std::string& text, int line, int column) {
  std::vector<OpenFlow> open;
  int l = 0, c = 0;
  char quote = 0;
  bool comment = false;
  for (size_t i = 0; i < text.size() && (l < line || (l == line && c < column)); ++i) {
    const char ch = text[i];
    if (ch == '\n') {
      ++l;
      c = 0;
      comment = false;
      continue;
    }
    if (comment) {
    } else if (quote != 0) {
      if (ch == '\\' && quote == '"') {
        ++i;
        ++c;
      } else if (ch == quote) {
        quote = 0;  // '' inside single quotes closes and reopens: the same state
      }
    } else if (ch == '#' && (c == 0 || text[i - 1] == ' ' || text[i - 1] == '\t')) {
      comment = true;
    } else if (ch == '"' || ch == '\'') {
      quote = ch;
    } else if (ch == '{' || ch == '[') {
      open.push_back({ch, l, c});
    } else if ((ch == '}' || ch == ']') && !open.empty()) {
      open.pop_back();
    }
    ++c;
  }
  return open.empty() ? OpenFlow{} : open.back();
}

// Where a quoted scalar opens that no quote closes before the end of the text (0-based), or
// {0, ...} if none: yaml-cpp reads such a scalar to the end of the file without an error, and
// the keys after it go missing ("name: \"crane" then "missing required key 'model'"). A quote
// opens a scalar only where a value or key starts (the line's first character, or after ": ",
// "- ", '[', '{', ','); an apostrophe inside a word does not. Comments and block scalars
// (| or >) are skipped.
OpenFlow FindUnclosedQuote(const std::string& text) {
  OpenFlow open;
  int l = 0, c = 0;
  char quote = 0;
  bool comment = false;
  int block_indent = -1;  // a block scalar's lines are indented more than its key's
  int line_indent = 0;
  bool line_start = true;
  char previous = '\n';  // the last non-blank character on the line before this one
  for (size_t i = 0; i < text.size(); ++i) {
    const char ch = text[i];
    if (ch == '\n') {
      if (quote == 0) {
        // "key: |" or "key: >-": the following, deeper lines are text.
        if (previous == '|' || previous == '>' ||
            ((previous == '-' || previous == '+') && i >= 2 &&
             (text[i - 2] == '|' || text[i - 2] == '>'))) {
          block_indent = line_indent;
        }
      }
      ++l;
      c = 0;
      comment = false;
      line_start = true;
      line_indent = 0;
      previous = '\n';
      continue;
    }
    if (line_start && quote == 0) {
      if (ch == ' ' || ch == '\t') {
        ++line_indent;
        ++c;
        continue;
      }
      line_start = false;
      if (block_indent >= 0 && line_indent > block_indent)
        comment = true;  // block text
      else
        block_indent = -1;
    }
    if (comment) {
    } else if (quote != 0) {
      if (ch == '\\' && quote == '"') {
        ++i;
        ++c;
      } else if (ch == quote && quote == '\'' && i + 1 < text.size() && text[i + 1] == '\'') {
        ++i;  // '' is a quote inside single quotes
        ++c;
      } else if (ch == quote) {
        quote = 0;
        previous = ch;
      }
    } else if (ch == '#' && (c == 0 || text[i - 1] == ' ' || text[i - 1] == '\t')) {
      comment = true;
    } else if ((ch == '"' || ch == '\'') &&
               (previous == '\n' || previous == '[' || previous == '{' || previous == ',' ||
                ((previous == ':' || previous == '-' || previous == '?') &&
                 (text[i - 1] == ' ' || text[i - 1] == '\t')))) {
      quote = ch;
      open = {ch, l, c};
    } else if (ch != ' ' && ch != '\t') {
      previous = ch;
    }
    ++c;
  }
  return quote != 0 ? open : OpenFlow{};
}

void ThrowIfAQuoteIsNotClosed(const std::string& text, const std::string& source,
                              const std::string& consequence) {
  const OpenFlow quote = FindUnclosedQuote(text);
  if (quote.bracket == 0) return;
  throw InputError(source, fmt::format("line {}", quote.line + 1),
                   fmt::format("the {} at column {} is not closed ({})", quote.bracket,
                               quote.column + 1, consequence),
                   fmt::format("a {} closing it", quote.bracket));
}
}  // namespace

std::string ClosestMatch(const std::string& word, const std::vector<std::string>& candidates) {
  std::string best;
  int best_distance = std::numeric_limits<int>::max();
  const std::string lower = ToLower(word);
  for (const auto& candidate : candidates) {
    const int d = EditDistance(lower, ToLower(candidate));
    if (d < best_distance) {
      best_distance = d;
      best = candidate;
    }
  }
  return best;
}

YamlReader YamlReader::FromFile(const std::string& path) {
  return FromString(internal::ReadTextFile(path, "a YAML file"), path);
}

YamlReader YamlReader::FromString(const std::string& text, const std::string& source) {
  ValidateUtf8Text(text, source);
  try {
    YAML::Node root = YAML::Load(text);
    ThrowIfAQuoteIsNotClosed(text, source, "the rest of the file was read as its text");
    return YamlReader(root, source, "");
  } catch (const YAML::ParserException& e) {
    ThrowIfAQuoteIsNotClosed(text, source,
                             fmt::format("YAML syntax error at line {}, column {}: {}",
                                         e.mark.line + 1, e.mark.column + 1, e.msg));
    const OpenFlow flow = e.msg.find("flow") != std::string::npos
                              ? FindOpenFlow(text, e.mark.line, e.mark.column)
                              : OpenFlow{};
    if (flow.bracket != 0 && flow.line < e.mark.line) {
      throw InputError(
          source, fmt::format("line {}", flow.line + 1),
          fmt::format("the '{}' at column {} is not closed (YAML syntax error at line {}, column "
                      "{}: {})",
                      flow.bracket, flow.column + 1, e.mark.line + 1, e.mark.column + 1, e.msg),
          fmt::format("a '{}' closing it", flow.bracket == '{' ? '}' : ']'));
    }
    throw InputError(source, fmt::format("line {}", e.mark.line + 1),
                     fmt::format("YAML syntax error at column {}: {}", e.mark.column + 1, e.msg),
                     "valid YAML");
  } catch (const YAML::Exception& e) {
    throw InputError(source, "", std::string("cannot parse YAML: ") + e.what(), "valid YAML");
  }
}

YamlReader::YamlReader(YAML::Node node, std::string source, std::string field)
    : node_(std::move(node)), source_(std::move(source)), field_(std::move(field)) {}

std::string YamlReader::ChildField(const std::string& key) const {
  return field_.empty() ? key : field_ + "." + key;
}

void YamlReader::Fail(const std::string& problem, const std::string& expected) const {
  throw InputError(source_, field_, problem, expected);
}

void YamlReader::FailAt(const std::string& key, const std::string& problem,
                        const std::string& expected) const {
  throw InputError(source_, ChildField(key), problem, expected);
}

bool YamlReader::Has(const std::string& key) const {
  if (node_.IsNull()) return false;  // "section:" with nothing under it is an empty map.
  if (!node_.IsMap()) Fail("is " + Describe(node_) + ", not a map", "a map");
  const YAML::Node& node = node_;  // const lookup: the non-const operator[] would insert.
  return node[key].IsDefined();
}

std::vector<std::string> YamlReader::Keys() const {
  std::vector<std::string> keys;
  if (node_.IsNull()) return keys;
  if (!node_.IsMap()) Fail("is " + Describe(node_) + ", not a map", "a map");
  for (const auto& item : node_) {
    if (!item.first.IsScalar()) Fail("has a key that is " + Describe(item.first), "plain keys");
    keys.push_back(item.first.Scalar());
  }
  return keys;
}

void YamlReader::ExpectMap(std::initializer_list<const char*> known) const {
  ExpectMap(std::vector<std::string>(known.begin(), known.end()));
}

void YamlReader::ExpectMap(const std::vector<std::string>& known) const {
  if (!node_.IsNull() && !node_.IsMap()) {
    Fail("is " + Describe(node_) + ", not a map", "a map with " + KnownKeysExpectation(known));
  }
  std::set<std::string> seen;
  for (const std::string& key : Keys()) {
    // yaml-cpp keeps duplicate keys and lookups see only one of them.
    if (!seen.insert(key).second) FailAt(key, "duplicate key '" + key + "'", "each key once");
    if (std::find(known.begin(), known.end(), key) != known.end()) continue;

    std::vector<std::string> with_unit;
    std::vector<std::string> with_word;
    for (const auto& k : known) {
      if (k.size() > key.size() + 1 && k.compare(0, key.size(), key) == 0 && k[key.size()] == '_') {
        (LooksLikeUnitSuffix(k.substr(key.size() + 1)) ? with_unit : with_word).push_back(k);
      }
    }
    if (!with_unit.empty()) {
      FailAt(key, "key '" + key + "' has no unit", Quoted(with_unit));
    }
    std::string expected = KnownKeysExpectation(known);
    const std::string suggestion =
        with_word.empty() ? Suggestion(key, known) : "did you mean '" + with_word.front() + "'?";
    if (!suggestion.empty()) expected += "; " + suggestion;
    FailAt(key, "unknown key '" + key + "'", expected);
  }
}

YamlReader YamlReader::Child(const std::string& key) const {
  if (!Has(key)) FailAt(key, "missing required key '" + key + "'", "a value for this required key");
  const YAML::Node& node = node_;
  return YamlReader(node[key], source_, ChildField(key));
}

double YamlReader::AsDouble() const {
  if (node_.IsNull()) Fail("has no value", "a number");
  if (!node_.IsScalar()) Fail("is " + Describe(node_) + ", not a number", "a number");
  const std::string& text = node_.Scalar();
  if (IsQuoted(node_)) {
    Fail("is the quoted string '" + text + "'", "a plain number (without quotes)");
  }
  const std::string lower = ToLower(text);
  // YAML spells infinity and NaN ".inf" and ".nan"; yaml-cpp would convert them silently.
  if (lower == ".nan" || lower == ".inf" || lower == "+.inf" || lower == "-.inf") {
    Fail("'" + text + "' is not finite", "a finite number");
  }
  double value = 0;
  switch (internal::ParseDouble(text, &value)) {
    case internal::ParseStatus::kOk:
      break;
    case internal::ParseStatus::kOutOfRange:
      Fail("'" + text + "' is out of the range of a double", "a finite number");
    case internal::ParseStatus::kNotANumber:
      Fail("'" + text + "' is not a number", "a plain number (the unit is in the key name)");
  }
  if (!std::isfinite(value)) Fail("'" + text + "' is not finite", "a finite number");
  return value;
}

std::string YamlReader::AsString() const {
  if (node_.IsNull()) Fail("has no value", "a string");
  if (!node_.IsScalar()) Fail("is " + Describe(node_) + ", not a string", "a string");
  return node_.Scalar();
}

double YamlReader::Double(const std::string& key) const { return Child(key).AsDouble(); }

double YamlReader::Double(const std::string& key, double fallback) const {
  return Has(key) ? Double(key) : fallback;
}

double YamlReader::PositiveDouble(const std::string& key) const {
  const double value = Double(key);
  if (value <= 0) {
    FailAt(key, fmt::format("{} value {}", value == 0 ? "zero" : "negative", value),
           "a number > 0");
  }
  return value;
}

double YamlReader::PositiveDouble(const std::string& key, double fallback) const {
  return Has(key) ? PositiveDouble(key) : fallback;
}

int YamlReader::Int(const std::string& key) const {
  return RequiredIntInRange(key, std::numeric_limits<int>::min(), std::numeric_limits<int>::max());
}

int YamlReader::Int(const std::string& key, int fallback) const {
  return Has(key) ? Int(key) : fallback;
}

int YamlReader::IntInRange(const std::string& key, int fallback, int min, int max) const {
  return Has(key) ? RequiredIntInRange(key, min, max) : fallback;
}

int YamlReader::RequiredIntInRange(const std::string& key, int min, int max) const {
  const YamlReader child = Child(key);
  const std::string text = child.AsString();
  const std::string expected = fmt::format("an integer between {} and {}", min, max);
  if (IsQuoted(child.node_)) {
    child.Fail("is the quoted string '" + text + "'", "a plain integer (without quotes)");
  }
  std::string_view digits = text;
  if (!digits.empty() && digits.front() == '+') digits.remove_prefix(1);
  long long value = 0;
  const char* end = digits.data() + digits.size();
  const auto [ptr, ec] = std::from_chars(digits.data(), end, value);
  bool integral = ptr == end && ec == std::errc();
  bool in_range = integral && value >= min && value <= max;
  if (!integral) {
    // Also integral numbers written with an exponent ("1e6").
    double d = 0;
    integral = internal::ParseDouble(text, &d) == internal::ParseStatus::kOk && std::isfinite(d) &&
               d == std::floor(d);
    in_range = integral && d >= min && d <= max;
    if (in_range) value = static_cast<long long>(d);
  }
  if (in_range) return static_cast<int>(value);
  // An integer beyond the range is one, out of range (it was "not an integer" above int's).
  const bool digits_only =
      !digits.empty() && digits.find_first_not_of("-0123456789") == std::string_view::npos;
  child.Fail("'" + text + "' is " + (integral || digits_only ? "out of range" : "not an integer"),
             expected);
}

int YamlReader::Seed(const std::string& key, int fallback) const {
  return IntInRange(key, fallback, 0, std::numeric_limits<int>::max());
}

bool YamlReader::Bool(const std::string& key, bool fallback) const {
  if (!Has(key)) return fallback;
  const YamlReader child = Child(key);
  const std::string text = child.AsString();
  if (!IsQuoted(child.node_)) {
    if (text == "true" || text == "True" || text == "TRUE") return true;
    if (text == "false" || text == "False" || text == "FALSE") return false;
  }
  child.Fail("'" + text + "' is not a boolean", "true or false");
}

std::string YamlReader::String(const std::string& key) const { return Child(key).AsString(); }

std::string YamlReader::String(const std::string& key, const std::string& fallback) const {
  return Has(key) ? String(key) : fallback;
}

std::string YamlReader::Choice(const std::string& key, const std::vector<std::string>& choices,
                               const std::string& fallback) const {
  const std::string value = String(key, fallback);
  if (std::find(choices.begin(), choices.end(), value) != choices.end()) return value;
  std::string expected = "one of " + internal::Join(choices, ", ");
  if (!Has(key)) FailAt(key, "missing", expected);  // no usable default: a required key
  const std::string suggestion = Suggestion(value, choices);
  if (!suggestion.empty()) expected += "; " + suggestion;
  FailAt(key, "unknown choice '" + value + "'", expected);
}

std::array<double, 3> YamlReader::Vector3(const std::string& key) const {
  const YamlReader child = Child(key);
  const std::string expected = "a list of 3 numbers [x, y, z]";
  if (!child.node_.IsSequence())
    child.Fail("is " + Describe(child.node_) + ", not a list", expected);
  if (child.node_.size() != 3) {
    child.Fail(fmt::format("has {} elements", child.node_.size()), expected);
  }
  std::array<double, 3> out{};
  for (size_t i = 0; i < 3; ++i) {
    out[i] = YamlReader(child.node_[i], source_, fmt::format("{}[{}]", child.field_, i)).AsDouble();
  }
  return out;
}

std::vector<std::string> YamlReader::StringList(const std::string& key) const {
  const YamlReader child = Child(key);
  if (!child.node_.IsSequence()) {
    child.Fail("is " + Describe(child.node_) + ", not a list", "a list of strings [a, b]");
  }
  std::vector<std::string> out;
  for (size_t i = 0; i < child.node_.size(); ++i) {
    out.push_back(
        YamlReader(child.node_[i], source_, fmt::format("{}[{}]", child.field_, i)).AsString());
  }
  return out;
}

}  // namespace mbid
