#include "units.h"

#include <fmt/format.h>
#include <udunits2.h>

#include <algorithm>
#include <cctype>
#include <map>
#include <memory>
#include <mutex>
#include <sstream>
#include <stdexcept>

#include "mbid/common/error.h"

namespace mbid::records::internal {
namespace {

// udunits2 is not thread-safe: one lock around every call, one unit system for the process.
std::mutex& UnitsMutex() {
  static std::mutex mutex;
  return mutex;
}

// Names udunits2 does not know (or reads otherwise: its `g` is the gram, `g0` is g^0) that
// loggers write.
const std::map<std::string, std::string>& Aliases() {
  static const std::map<std::string, std::string> aliases = {
      {"deg", "degree"},
      {"degs", "degree"},
      {"mdeg", "millidegree"},  // a prefix on an alias: udunits2 knows "millidegree" only
      {"udeg", "microdegree"},
      {"\u00b5deg", "microdegree"},  // micro sign
      {"\u03bcdeg", "microdegree"},  // Greek mu
      {"gn", "standard_free_fall"},
      {"g0", "standard_free_fall"},
      {"g_n", "standard_free_fall"},
      // Upper-case spellings of loggers' exports that udunits2 does not know.
      {"DEG", "degree"},
      {"Deg", "degree"},
      {"RAD", "rad"},
      {"MM", "mm"},
      {"Nm", "N.m"},
      {"kNm", "kN.m"},
      // Upper-case exports' S of seconds (MM/S, DEG/S): udunits2 reads the siemens, which no
      // vibration sensor measures.
      {"S", "s"},
  };
  return aliases;
}

bool IsNameByte(char c) {
  const auto u = static_cast<unsigned char>(c);
  return std::isalpha(u) != 0 || c == '_' || u >= 0x80;
}

// `text` with every alias replaced where it stands as a whole name ("deg/s" -> "degree/s").
std::string ApplyAliases(const std::string& text) {
  std::string out;
  size_t i = 0;
  while (i < text.size()) {
    if (!IsNameByte(text[i])) {
      out += text[i++];
      continue;
    }
    size_t end = i;
    while (end < text.size() && IsNameByte(text[end])) ++end;
    std::string name = text.substr(i, end - i);
    // "g0": the name and its digit, unless more digits follow (then it is not standard gravity).
    if (name == "g" && end < text.size() && text[end] == '0' &&
        (end + 1 == text.size() || std::isdigit(static_cast<unsigned char>(text[end + 1])) == 0)) {
      name = "g0";
      ++end;
    }
    const auto alias = Aliases().find(name);
    out += alias == Aliases().end() ? name : alias->second;
    i = end;
  }
  return out;
}

struct UnitDeleter {
  void operator()(ut_unit* unit) const { ut_free(unit); }
};
using UnitPtr = std::unique_ptr<ut_unit, UnitDeleter>;

ut_system* System() {
  // Called with the lock held; loaded once (the XML database takes milliseconds to parse).
  static ut_system* system = [] {
    ut_set_error_message_handler(ut_ignore);
    ut_system* loaded = ut_read_xml(nullptr);
    if (loaded == nullptr) {
      throw std::runtime_error(fmt::format(
          "cannot load the udunits2 unit database (status {}; UDUNITS2_XML_PATH may name it)",
          static_cast<int>(ut_get_status())));
    }
    return loaded;
  }();
  return system;
}

UnitPtr Parse(const std::string& text) {
  if (text.empty()) return nullptr;
  // The typographic minus (U+2212, what a word processor makes of "-0.02 deg") is a minus.
  std::string ascii = text;
  for (size_t at = ascii.find("\xE2\x88\x92"); at != std::string::npos;
       at = ascii.find("\xE2\x88\x92", at)) {
    ascii.replace(at, 3, "-");
  }
  return UnitPtr(ut_parse(System(), ApplyAliases(ascii).c_str(), UT_UTF8));
}

// The unit's base-unit expression without its factor and offset: "0.001 m.s-2" -> "m.s-2",
// "K @ 273.15" -> "K", "0.0174532925199433 rad" -> "rad". Equal for units of equal dimension,
// the radian counted as a dimension of its own.
std::string Dimension(const ut_unit* unit) {
  char buffer[256] = "";
  const int length = ut_format(unit, buffer, sizeof(buffer), UT_ASCII | UT_DEFINITION);
  if (length < 0 || length >= static_cast<int>(sizeof(buffer))) return "?";
  std::string definition(buffer);
  const size_t at = definition.find(" @ ");
  if (at != std::string::npos) definition.erase(at);
  std::istringstream words(definition);
  std::string first, rest;
  words >> first;
  std::getline(words, rest);
  char* end = nullptr;
  std::strtod(first.c_str(), &end);
  const bool factor = end != first.c_str() && *end == '\0' && !rest.empty();
  std::string dimension = factor ? rest : definition;
  const size_t begin = dimension.find_first_not_of(' ');
  return begin == std::string::npos ? std::string("1") : dimension.substr(begin);
}

// Dimension -> the SI unit mbid writes for it; the first candidate of a dimension wins (N*m
// before J: torques are what machines measure).
const std::map<std::string, std::string>& SiUnits() {
  static const std::map<std::string, std::string> units = [] {
    std::map<std::string, std::string> map;
    for (const char* name : {"rad", "rad/s",   "rad/s^2", "m",         "m/s",    "m/s^2", "s", "Hz",
                             "kg",  "N",       "N*m",     "Pa",        "V",      "A",     "K", "W",
                             "N/m", "N*m/rad", "N*s/m",   "N*m*s/rad", "kg*m^2", "1"}) {
      const UnitPtr unit = Parse(name);
      if (unit) map.emplace(Dimension(unit.get()), name);
    }
    return map;
  }();
  return units;
}

std::string UnknownUnitHint(const std::string& text) {
  return fmt::format("a unit udunits2 knows (e.g. rad, deg, mm, m/s^2, gn, ms); '{}' is not one",
                     text);
}

// Spellings loggers write that udunits2 reads as another unit: never guessed, the user writes
// what is meant. A bare `g` is the gram to udunits2 and almost always standard gravity on a
// vibration logger; `mg` the milligram, not milli-g; `Grad` the giga-radian, not the German
// "Grad" (degree, a trial's inclinometer read 1e9 times too large); `ms-2` per millisecond
// squared, not the British m s-2 (1e6 times too large); `Mrad` the mega-radian, not mrad.
void RefuseAmbiguous(const std::string& text, const std::string& source, const std::string& field) {
  struct Reading {
    const char* udunits;
    const char* expected;
  };
  static const std::map<std::string, Reading> readings = {
      {"g", {"the gram", "gn for standard gravity (9.80665 m/s^2), or gram for a mass"}},
      {"G", {"the gram", "gn for standard gravity (9.80665 m/s^2), or gram for a mass"}},
      {"mg", {"the milligram", "'0.001 gn' for milli-g, or milligram for a mass"}},
      {"Grad", {"the giga-radian", "deg for degrees (German Grad)"}},
      {"Mrad", {"the mega-radian", "mrad for milliradians"}},
      {"ms-1", {"per millisecond", "m/s (or m s-1, with a space)"}},
      {"ms^-1", {"per millisecond", "m/s (or m s-1, with a space)"}},
      {"ms-2", {"per millisecond squared", "m/s^2 (or m s-2, with a space)"}},
      {"ms^-2", {"per millisecond squared", "m/s^2 (or m s-2, with a space)"}},
  };
  const auto found = readings.find(text);
  if (found != readings.end()) {
    throw InputError(
        source, field,
        fmt::format("unit '{}' is ambiguous (udunits2 reads {})", text, found->second.udunits),
        found->second.expected);
  }
  // Inside a compound unit too: a gyro's `Grad/s` was read as giga-radians per second, `ms**-2`
  // as per millisecond squared.
  for (size_t i = 0; i < text.size();) {
    if (!IsNameByte(text[i])) {
      ++i;
      continue;
    }
    size_t end = i;
    while (end < text.size() && IsNameByte(text[end])) ++end;
    const std::string name = text.substr(i, end - i);
    const std::string after = text.substr(end, 3);
    const bool negative_power =
        after.rfind("-", 0) == 0 || after.rfind("^-", 0) == 0 || after.rfind("**-", 0) == 0;
    if (name == "Grad" || name == "Mrad" || (name == "ms" && negative_power)) {
      throw InputError(source, field,
                       fmt::format("unit '{}' is ambiguous: udunits2 reads '{}' as {}", text, name,
                                   name == "Grad"   ? "the giga-radian"
                                   : name == "Mrad" ? "the mega-radian"
                                                    : "the millisecond"),
                       name == "Grad"   ? "deg for degrees (German Grad), e.g. deg/s"
                       : name == "Mrad" ? "mrad for milliradians"
                                        : "m/s^2 or m/s (or m s-2, with a space)");
    }
    i = end;
  }
}

}  // namespace

bool IsUnit(const std::string& text) {
  const std::lock_guard<std::mutex> lock(UnitsMutex());
  return Parse(text) != nullptr;
}

const std::vector<std::string>& SelfSiUnits() {
  static const std::vector<std::string> units{"rad",   "rad/s", "rad/s^2", "m", "m/s",
                                              "m/s^2", "s",     "kg",      "N", "N*m"};
  return units;
}

std::string SiUnitFor(const std::string& unit, const std::string& source,
                      const std::string& field) {
  const std::vector<std::string>& self = SelfSiUnits();
  if (std::find(self.begin(), self.end(), unit) != self.end()) return unit;
  return SiUnitByUdunits(unit, source, field);
}

std::string SiUnitByUdunits(const std::string& unit, const std::string& source,
                            const std::string& field) {
  RefuseAmbiguous(unit, source, field);
  const std::lock_guard<std::mutex> lock(UnitsMutex());
  const UnitPtr parsed = Parse(unit);
  if (!parsed) {
    throw InputError(source, field, fmt::format("unknown unit '{}'", unit), UnknownUnitHint(unit));
  }
  const std::string dimension = Dimension(parsed.get());
  const auto si = SiUnits().find(dimension);
  // A dimension without a name of its own keeps udunits' base-unit expression ("m2.kg.s-3.A-1").
  return si == SiUnits().end() ? dimension : si->second;
}

std::string EverydayUnit(const std::string& si_unit) {
  if (si_unit.empty() || si_unit == "rad") return "deg";
  if (si_unit == "m") return "mm";
  if (si_unit == "m/s^2") return "gn";
  if (si_unit == "rad/s") return "deg/s";
  if (si_unit == "m/s") return "mm/s";
  return si_unit;
}

UnitConversion FindConversion(const std::string& from, const std::string& to,
                              const std::string& source, const std::string& field,
                              const std::string& column) {
  if (from == to) return {};
  RefuseAmbiguous(from, source, field);
  const std::lock_guard<std::mutex> lock(UnitsMutex());
  const UnitPtr a = Parse(from);
  if (!a) {
    throw InputError(source, field, fmt::format("unknown unit '{}'", from),
                     fmt::format("a unit convertible to {} ({})", to, UnknownUnitHint(from)));
  }
  const UnitPtr b = Parse(to);
  if (!b) throw std::logic_error("mbid: target unit '" + to + "' unknown to udunits2");
  if (Dimension(a.get()) != Dimension(b.get()) || ut_are_convertible(a.get(), b.get()) == 0) {
    // udunits' g is the gram (and mg the milligram): say how an accelerometer's g is written.
    const bool gram = Dimension(a.get()) == "kg" && Dimension(b.get()) == "m.s-2";
    // A sensor's raw signal (volts, a 4-20 mA loop): its calibration is a scaled unit of what it
    // measures (a trial's 50 mV/deg inclinometer, mounted reversed, read as "-0.02 deg").
    // A bridge's ratio (mV/V, %) is dimensionless: as raw, calibrated the same way.
    const bool electric = Dimension(a.get()) == "m2.kg.s-3.A-1" || Dimension(a.get()) == "A" ||
                          Dimension(a.get()) == "1";
    const std::string example = "0.02 " + EverydayUnit(to);
    // A sensitivity ("deg/mV": what one mV measures) written where the column's unit goes.
    const size_t slash = from.rfind('/');
    if (slash != std::string::npos && slash + 1 < from.size()) {
      const std::string per = from.substr(slash + 1);
      const UnitPtr denominator = Parse(per);
      const UnitPtr numerator = Parse(from.substr(0, slash));
      const std::string dimension = denominator ? Dimension(denominator.get()) : "";
      if ((dimension == "m2.kg.s-3.A-1" || dimension == "A") && numerator &&
          Dimension(numerator.get()) == Dimension(b.get())) {
        throw InputError(
            source, field,
            fmt::format("unit '{}' is a sensitivity (what one {} measures), not the unit of the "
                        "column's values",
                        from, per),
            fmt::format(
                "for a column in {}, its calibration as a scaled unit of what it "
                "measures: the sensitivity's number times '{}' (`units: {{\"{}\": \"{}\"}}` "
                "for 0.02 {} per {}; a minus sign for a sensor mounted reversed)",
                per, from.substr(0, slash), column, "0.02 " + from.substr(0, slash),
                from.substr(0, slash), per));
      }
    }
    throw InputError(
        source, field,
        fmt::format("unit '{}' ({}) cannot be converted to {}", from, Dimension(a.get()), to),
        gram ? std::string("a unit of acceleration; standard gravity is written gn ('g' is the "
                           "gram), milli-g '0.001 gn'")
        : electric
            ? fmt::format("a unit convertible to {}: the sensor's calibration, what one {} of its "
                          "signal measures, as a scaled unit (`units: {{\"{}\": \"{}\"}}` in the "
                          "record entry or --unit \"{}={}\"; a minus sign for a sensor mounted "
                          "reversed)",
                          to, from, column, example, column, example)
            : fmt::format("a unit convertible to {} ({})", to, Dimension(b.get())));
  }
  cv_converter* converter = ut_get_converter(a.get(), b.get());
  if (converter == nullptr) {
    throw InputError(source, field, fmt::format("no conversion from '{}' to {}", from, to),
                     fmt::format("a unit convertible to {}", to));
  }
  UnitConversion conversion;
  conversion.offset = cv_convert_double(converter, 0.0);
  conversion.scale = cv_convert_double(converter, 1.0) - conversion.offset;
  cv_free(converter);
  return conversion;
}

void Convert(const UnitConversion& conversion, std::vector<double>* values) {
  if (conversion.identity()) return;
  for (double& v : *values) v = conversion.scale * v + conversion.offset;
}

std::string DescribeConversion(const std::string& channel, const std::string& from,
                               const std::string& to, const UnitConversion& conversion) {
  return conversion.offset == 0.0
             ? fmt::format("{}: {} -> {} (x {:g})", channel, from, to, conversion.scale)
             : fmt::format("{}: {} -> {} (x {:g} + {:g})", channel, from, to, conversion.scale,
                           conversion.offset);
}

}  // namespace mbid::records::internal
