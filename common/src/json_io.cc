#include "mbid/common/json_io.h"

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <iostream>
#include <stdexcept>

#include "internal.h"
#include "mbid/common/atomic_file.h"
#include "mbid/common/error.h"

namespace mbid {
namespace {

// JSON pointer escaping (RFC 6901) so that the reported location is unambiguous.
std::string EscapePointerToken(const std::string& key) {
  std::string out;
  for (char c : key) {
    if (c == '~') {
      out += "~0";
    } else if (c == '/') {
      out += "~1";
    } else {
      out += c;
    }
  }
  return out;
}

// nlohmann::json would print NaN/Inf as null, silently losing the fact that a result is bad.
// A negative zero (the decay of a rigid-body pole, a phase of nothing) prints as "-0.0", which
// reads as a sign the result does not have: it is written as 0.0.
void CheckFiniteUnsignZeros(nlohmann::json& value, const std::string& pointer) {
  if (value.is_number_float()) {
    const double v = value.get<double>();
    if (v == 0.0) value = 0.0;
    if (!std::isfinite(v)) {
      throw std::invalid_argument(fmt::format(
          "WriteJson: the value at '{}' is {}; JSON has no NaN or infinity",
          pointer.empty() ? "/" : pointer, std::isnan(v) ? "NaN" : (v > 0 ? "+Inf" : "-Inf")));
    }
  } else if (value.is_object()) {
    for (auto& item : value.items()) {
      CheckFiniteUnsignZeros(item.value(), pointer + "/" + EscapePointerToken(item.key()));
    }
  } else if (value.is_array()) {
    for (size_t i = 0; i < value.size(); ++i) {
      CheckFiniteUnsignZeros(value[i], pointer + "/" + std::to_string(i));
    }
  }
}

}  // namespace

void WriteJson(const nlohmann::json& value, const std::string& path) {
  nlohmann::json written = value;
  CheckFiniteUnsignZeros(written, "");
  const std::string text = written.dump(2) + "\n";
  if (path == "-") {
    std::cout << text << std::flush;
    if (!std::cout) throw std::runtime_error("cannot write JSON to standard output");
    return;
  }
  AtomicFile file(path);
  {
    std::ofstream out(file.temp_path(), std::ios::binary | std::ios::trunc);
    if (!out) throw std::runtime_error("cannot create " + file.temp_path());
    out << text;
    out.close();
    if (!out) throw std::runtime_error("cannot write " + file.temp_path());
  }
  file.Commit();
}

nlohmann::json ReadJson(const std::string& path) {
  const std::string expected = "a JSON file";
  const std::string text = internal::ReadTextFile(path, expected);
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    // e.byte is 1-based and points just past the offending character.
    const size_t end = std::min(text.size(), e.byte == 0 ? size_t{0} : e.byte - 1);
    size_t line = 1;
    for (size_t i = 0; i < end; ++i) {
      if (text[i] == '\n') ++line;
    }
    std::string problem = e.what();
    // Drop the library's "[json.exception.parse_error.101] parse error at line 1, column 2: ".
    const size_t column = problem.find("column ");
    const size_t colon =
        column == std::string::npos ? std::string::npos : problem.find(": ", column);
    if (colon != std::string::npos) problem = problem.substr(colon + 2);
    throw InputError(path, fmt::format("line {}", line), problem, "valid JSON");
  }
}

}  // namespace mbid
