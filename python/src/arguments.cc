#include "arguments.h"

#include <cmath>
#include <limits>

#include "mbid/records/records.h"

namespace mbid::python {
namespace {

using Doubles = py::array_t<double, py::array::c_style | py::array::forcecast>;

// `object` as a one-dimensional float64 array, or an InputError naming `field`: real numbers only
// (strings once crashed; a complex channel lost its imaginary part with numpy's warning alone).
// `given` gets the array as given (its dtype before the cast).
Doubles RealVector(const py::object& object, const std::string& field, const std::string& what,
                   py::array* given) {
  *given = py::array::ensure(object);
  const char kind = *given ? given->dtype().kind() : '?';
  if (kind != 'f' && kind != 'i' && kind != 'u') {
    throw mbid::InputError(
        "identify_arrays", field,
        *given ? "an array of " + std::string(py::str(given->dtype())) + " values" : "not an array",
        "a one-dimensional array of " + what + " (real numbers)");
  }
  if (given->ndim() != 1) {
    throw mbid::InputError("identify_arrays", field,
                           "an array of dimension " + std::to_string(given->ndim()),
                           "a one-dimensional array of " + what);
  }
  const Doubles values = Doubles::ensure(*given);
  if (!values) {
    throw mbid::InputError("identify_arrays", field, "not convertible to float64",
                           "a one-dimensional array of " + what);
  }
  return values;
}

}  // namespace

// A path given as str or os.PathLike (pathlib.Path), or nothing.
std::optional<std::string> AsPath(const py::handle& object) {
  if (py::isinstance<py::str>(object)) return object.cast<std::string>();
  if (py::hasattr(object, "__fspath__")) {
    return py::module_::import("os").attr("fspath")(object).cast<std::string>();
  }
  return std::nullopt;
}

std::string TypeName(const py::handle& object) {
  return py::str(py::type::of(object).attr("__name__")).cast<std::string>();
}

// A path argument (str or os.PathLike), else a one-line TypeError.
std::string PathArgument(const py::object& object, const std::string& function) {
  if (const auto path = AsPath(object)) return *path;
  throw py::type_error(function + "(): path is of type " + TypeName(object) +
                       "; expected a str or os.PathLike");
}

// A scenario argument: an mbid.Scenario or the path of its file. Anything else is a TypeError of
// one line naming the function and the argument (pybind11's own lists every overload).
mbid::Scenario AsScenario(const py::object& object, const std::string& function) {
  if (py::isinstance<mbid::Scenario>(object)) return object.cast<mbid::Scenario>();
  if (const auto path = AsPath(object)) return mbid::LoadScenario(*path);
  throw py::type_error(function + "(): scenario is of type " + TypeName(object) +
                       "; expected an mbid.Scenario or the path of a scenario file");
}

// A record argument: an mbid.Record or the path of a record file.
mbid::Measurement AsRecord(const py::handle& object, const std::string& function,
                           const std::string& argument) {
  if (py::isinstance<mbid::Measurement>(object)) return object.cast<mbid::Measurement>();
  if (const auto path = AsPath(object)) return mbid::ReadRecord(*path);
  throw py::type_error(function + "(): " + argument + " is of type " + TypeName(object) +
                       "; expected an mbid.Record or the path of a record file");
}

// update()'s records: a list (any iterable) of records or paths, or a single one.
// `paths` (if set) gets each record's file, "" for a Record object.
std::vector<mbid::Measurement> AsRecords(const py::object& object,
                                         std::vector<std::string>* paths) {
  std::vector<mbid::Measurement> records;
  const auto add = [&](const py::object& item, const std::string& field) {
    records.push_back(AsRecord(item, "update", field));
    if (paths != nullptr) paths->push_back(AsPath(item).value_or(""));
  };
  if (py::isinstance<mbid::Measurement>(object) || AsPath(object)) {
    add(object, "records");
  } else if (py::isinstance<py::iterable>(object)) {
    for (const py::handle item : object) {
      add(py::reinterpret_borrow<py::object>(item),
          "records[" + std::to_string(records.size()) + "]");
    }
  } else {
    throw py::type_error("update(): records is of type " + TypeName(object) +
                         "; expected a list of mbid.Record or of record file paths");
  }
  return records;
}

// identify_arrays: a uniformly sampled record from a time array and named channel arrays.
mbid::Measurement MakeRecord(const py::object& time_object,
                             const std::map<std::string, py::object>& channels,
                             const std::map<std::string, std::string>& units) {
  py::array given;
  const Doubles time = RealVector(time_object, "time", "times in s", &given);
  const char kind = given.dtype().kind();
  const Eigen::Index n = time.shape(0);
  const Eigen::VectorXd t = Eigen::Map<const Eigen::VectorXd>(time.data(), n);
  // Floating-point times are rounded to their last bit, as a printed column is to its last
  // digit: a 10 kHz float32 clock at 100 s is off the grid by up to 4 us, float64 epoch times
  // (1.7e9 s) by 0.1 us. Allowed where that is more than the uniformity tolerance leaves.
  double resolution_s = 0;
  if (kind == 'f' && n > 1) {
    const int digits = given.itemsize() == 2   ? 11
                       : given.itemsize() == 4 ? std::numeric_limits<float>::digits
                                               : std::numeric_limits<double>::digits;
    const double last_bit = std::ldexp(1.0, std::ilogb(t.cwiseAbs().maxCoeff()) + 1 - digits);
    const double step = std::abs(t[n - 1] - t[0]) / static_cast<double>(n - 1);
    if (last_bit > 0.1 * mbid::kTimeUniformityTolerance * step) resolution_s = last_bit;
  }
  mbid::Measurement m;
  try {
    m.sample_interval_s = mbid::CheckUniformTime(
        t, "identify_arrays", [](Eigen::Index j) { return "time[" + std::to_string(j) + "]"; },
        resolution_s, &m.start_time_s);
  } catch (const mbid::InputError& error) {
    // The reader's advice (a record entry's sample_rate_hz, --sample-rate-hz) is no argument of
    // this call: times made from the rate are.
    const size_t advice = error.expected().find(", or, for a time printed coarser than its step");
    const size_t jitter = error.expected().find("; for a logger that samples at a fixed rate");
    const size_t cut = std::min(advice, jitter);
    if (cut == std::string::npos) throw;
    throw mbid::InputError(
        error.source(), error.field(), error.problem(),
        error.expected().substr(0, cut) +
            (advice < jitter ? ", or times made from the rate: numpy.arange(n) / rate_hz (float64; "
                               "float16 holds 3 digits)"
                             : "; for a logger that samples at a fixed rate, times made from it: "
                               "numpy.arange(n) / rate_hz"));
  }
  if (channels.empty()) {
    throw mbid::InputError("identify_arrays", "channels", "no channel",
                           "a dict {name: array} with at least one channel");
  }
  m.values.resize(n, static_cast<Eigen::Index>(channels.size()));
  Eigen::Index column = 0;
  for (const auto& [name, object] : channels) {
    py::array as_given;
    const Doubles values = RealVector(object, "channels/" + name, "values", &as_given);
    if (values.shape(0) != n) {
      throw mbid::InputError("identify_arrays", "channels/" + name,
                             "an array of shape different from time's",
                             "a one-dimensional array of " + std::to_string(n) + " samples");
    }
    m.values.col(column++) = Eigen::Map<const Eigen::VectorXd>(values.data(), n);
    m.channels.push_back(name);
    const auto unit = units.find(name);
    m.units.push_back(unit == units.end() ? "1" : unit->second);
  }
  for (const auto& [name, unit] : units) {
    if (channels.count(name) == 0) {
      throw mbid::InputError("identify_arrays", "units/" + name, "a unit for no channel",
                             "units only for the given channels");
    }
  }
  m.source = "import";
  // Units as a file would state them ("deg", "mm", "g"): to SI as a read record is.
  mbid::records::ConvertToSi(&m, "identify_arrays");
  m.Validate("identify_arrays");
  return m;
}

}  // namespace mbid::python
