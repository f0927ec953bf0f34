#pragma once

// The Python module's arguments: paths, scenarios, records and arrays as mbid's types, with
// one-line TypeErrors naming the call and the argument (pybind11's own list every overload over
// several lines) and mbid's InputErrors for bad values.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <map>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include "mbid/mbid.h"

namespace mbid::python {

namespace py = pybind11;

// A path given as str or os.PathLike (pathlib.Path), or nothing.
std::optional<std::string> AsPath(const py::handle& object);

// The Python type's name, for messages.
std::string TypeName(const py::handle& object);

// A path argument (str or os.PathLike), else a one-line TypeError.
std::string PathArgument(const py::object& object, const std::string& function);

// A scenario argument: an mbid.Scenario or the path of its file.
mbid::Scenario AsScenario(const py::object& object, const std::string& function);

// A record argument: an mbid.Record or the path of a record file.
mbid::Measurement AsRecord(const py::handle& object, const std::string& function,
                           const std::string& argument);

// update()'s records: a list (any iterable) of records or paths, or a single one. `paths` (if
// set) gets each record's file, "" for a Record object.
std::vector<mbid::Measurement> AsRecords(const py::object& object,
                                         std::vector<std::string>* paths = nullptr);

// identify_arrays: a uniformly sampled record from a time array and named channel arrays.
mbid::Measurement MakeRecord(const py::object& time_object,
                             const std::map<std::string, py::object>& channels,
                             const std::map<std::string, std::string>& units);

// A dict with str keys as a std::map, or a TypeError of one line naming the argument (pybind11's
// own for `{1: y}` was 4-6 lines listing the signature).
template <typename Value>
std::map<std::string, Value> StringKeyed(const py::object& object, const std::string& argument,
                                         const std::string& values) {
  if (!py::isinstance<py::dict>(object)) {
    throw py::type_error("identify_arrays(): " + argument + " is of type " + TypeName(object) +
                         "; expected a dict of names to " + values);
  }
  std::map<std::string, Value> map;
  for (const std::pair<py::handle, py::handle> item : py::reinterpret_borrow<py::dict>(object)) {
    const py::handle key = item.first;
    const py::handle value = item.second;
    if (!py::isinstance<py::str>(key)) {
      throw py::type_error("identify_arrays(): a key of " + argument + " is of type " +
                           TypeName(py::reinterpret_borrow<py::object>(key)) +
                           "; expected a str (a channel name)");
    }
    if constexpr (std::is_same_v<Value, std::string>) {
      if (!py::isinstance<py::str>(value)) {
        throw py::type_error(
            "identify_arrays(): " + argument + "['" + key.cast<std::string>() + "'] is of type " +
            TypeName(py::reinterpret_borrow<py::object>(value)) + "; expected a unit string");
      }
      map[key.cast<std::string>()] = value.cast<std::string>();
    } else {
      map[key.cast<std::string>()] = py::reinterpret_borrow<py::object>(value);
    }
  }
  return map;
}

}  // namespace mbid::python
