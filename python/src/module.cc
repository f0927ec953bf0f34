// The Python module `mbid` (its compiled part, mbid._mbid): the facade of <mbid/mbid.h> with
// records as numpy arrays and mbid's errors as Python exceptions with the same one-line text.
#include <glog/logging.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>
#include <signal.h>

#include <atomic>
#include <cmath>
#include <limits>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include "mbid/common/stop.h"
#include "mbid/mbid.h"
#include "mbid/records/records.h"
#include "mbid/validation/identification_settings.h"

namespace py = pybind11;

namespace {

// Ctrl-C during a long call. Python runs its SIGINT handler between bytecodes, which a call in
// C++ never reaches: a run went on for 25 s, its gnuplot children (same process group) died, and
// a "gnuplot failed" RuntimeError came before the KeyboardInterrupt, raised later inside the
// user's own except block. For the call's length SIGINT asks mbid to stop (stop.h) instead; the
// call then unwinds within a moment, and Python's handler (KeyboardInterrupt by default) runs as
// the call returns, whatever the stopped computation threw.
std::atomic<bool> sigint_seen{false};

void OnSigint(int) {
  sigint_seen.store(true);
  mbid::RequestStop();
}

class StopOnSigint {
 public:
  StopOnSigint() {
    std::lock_guard<std::mutex> lock(Mutex());
    if (Depth()++ > 0) return;  // calls from several threads share one handler
    sigint_seen.store(false);
    mbid::ClearStopRequest();
    struct sigaction ours {};
    ours.sa_handler = OnSigint;
    sigemptyset(&ours.sa_mask);
    if (sigaction(SIGINT, nullptr, &Previous()) == 0 && Previous().sa_handler != SIG_IGN) {
      sigaction(SIGINT, &ours, nullptr);
      Installed() = true;
    }
  }
  ~StopOnSigint() { Restore(); }

  // Python's handler back; with the GIL held, raises what it raises for a SIGINT seen meanwhile.
  void Finish() {
    Restore();
    if (!sigint_seen.load()) return;
    PyErr_SetInterrupt();
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    // A handler of the user's that raised nothing: the computation was still cut short.
    throw std::runtime_error("mbid: interrupted by SIGINT");
  }

 private:
  void Restore() {
    if (restored_) return;
    restored_ = true;
    std::lock_guard<std::mutex> lock(Mutex());
    if (--Depth() > 0) return;
    if (Installed()) sigaction(SIGINT, &Previous(), nullptr);
    Installed() = false;
    mbid::ClearStopRequest();
  }
  static std::mutex& Mutex() {
    static std::mutex mutex;
    return mutex;
  }
  static int& Depth() {
    static int depth = 0;
    return depth;
  }
  static bool& Installed() {
    static bool installed = false;
    return installed;
  }
  static struct sigaction& Previous() {
    static struct sigaction previous {};
    return previous;
  }
  bool restored_ = false;
};

// Runs `call` without the GIL, stoppable by Ctrl-C (above).
template <typename Call>
auto Interruptible(Call&& call) -> decltype(call()) {
  StopOnSigint stop;
  try {
    auto result = [&] {
      py::gil_scoped_release release;
      return call();
    }();
    stop.Finish();
    return result;
  } catch (const py::error_already_set&) {
    throw;
  } catch (...) {
    stop.Finish();  // a SIGINT's KeyboardInterrupt over what the stopped computation threw
    throw;
  }
}

py::array_t<double> ToArray(const Eigen::VectorXd& v) {
  py::array_t<double> array(v.size());
  std::copy(v.data(), v.data() + v.size(), array.mutable_data());
  return array;
}

// A record as Python sees it: time and channels as numpy arrays (copies), SI units.
py::dict Channels(const mbid::Measurement& m) {
  py::dict channels;
  for (int c = 0; c < m.channel_count(); ++c) {
    channels[py::str(m.channels[static_cast<size_t>(c)])] = ToArray(m.values.col(c));
  }
  return channels;
}

py::dict Units(const mbid::Measurement& m) {
  py::dict units;
  for (size_t c = 0; c < m.channels.size(); ++c) units[py::str(m.channels[c])] = m.units[c];
  return units;
}

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
                                         std::vector<std::string>* paths = nullptr) {
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

}  // namespace

PYBIND11_MODULE(_mbid, m) {
  m.doc() = "mbid: multibody identification (simulate, identify, update, validate)";
  // Ceres logs a fit stopped by a failed simulation through glog on stderr; the results say
  // what failed (converged, credible, the message), as the command line does.
  if (!google::IsGoogleLoggingInitialized()) {
    FLAGS_minloglevel = google::GLOG_FATAL;
    google::InitGoogleLogging("mbid");
  }

  // The same one-line messages as the command line; InputError is a ValueError (bad input),
  // NumericalError a RuntimeError (a fit or integration that failed).
  static py::exception<mbid::InputError> input_error(m, "InputError", PyExc_ValueError);
  static py::exception<mbid::NumericalError> numerical_error(m, "NumericalError",
                                                             PyExc_RuntimeError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const mbid::InputError& e) {
      input_error(e.what());
    } catch (const mbid::NumericalError& e) {
      numerical_error(e.what());
    }
  });

  py::class_<mbid::Scenario>(m, "Scenario", "A scenario file, read strictly.")
      .def_readonly("name", &mbid::Scenario::name)
      .def_readonly("path", &mbid::Scenario::path)
      .def_readonly("yaml", &mbid::Scenario::yaml_text)
      .def("__repr__", [](const mbid::Scenario& s) { return "<mbid.Scenario '" + s.name + "'>"; });

  py::class_<mbid::Measurement>(m, "Record",
                                "A uniformly sampled record: .time (s) and .channels (SI units) "
                                "as numpy arrays.")
      .def_property_readonly("time",
                             [](const mbid::Measurement& r) { return ToArray(r.CalcTime()); })
      .def_property_readonly("channels", &Channels)
      .def_property_readonly("units", &Units)
      .def_readonly("sample_interval_s", &mbid::Measurement::sample_interval_s)
      .def_readonly("start_time_s", &mbid::Measurement::start_time_s)
      .def_property_readonly("samples", &mbid::Measurement::samples)
      .def("__repr__", [](const mbid::Measurement& r) {
        return "<mbid.Record " + std::to_string(r.samples()) + " samples x " +
               std::to_string(r.channel_count()) + " channels>";
      });

  using mbid::identification::IdentificationOptions;
  using mbid::identification::ReleaseMode;
  py::class_<IdentificationOptions>(
      m, "IdentificationOptions",
      "What identify() is told (as the scenario's identification: section and the identify "
      "command's flags): method, release, window, band, channels, modes.")
      .def(py::init<>())
      .def_property(
          "method",
          [](const IdentificationOptions& o) { return mbid::identification::MethodName(o.method); },
          [](IdentificationOptions& o, const std::string& name) {
            if (!mbid::identification::ParseMethod(name, &o.method)) {
              std::string known;
              for (const std::string& n : mbid::identification::MethodNames())
                known += (known.empty() ? "" : ", ") + n;
              throw mbid::InputError("IdentificationOptions", "method",
                                     "unknown method '" + name + "'", "one of " + known);
            }
          })
      .def_property(
          "release",
          [](const IdentificationOptions& o) {
            return o.release == ReleaseMode::kDetect       ? "detect"
                   : o.release == ReleaseMode::kGiven      ? "given"
                   : o.release == ReleaseMode::kForcingEnd ? "forcing end"
                                                           : "none";
          },
          [](IdentificationOptions& o, const std::string& mode) {
            if (mode == "detect") {
              o.release = ReleaseMode::kDetect;
            } else if (mode == "given") {
              o.release = ReleaseMode::kGiven;
            } else if (mode == "none") {
              o.release = ReleaseMode::kNone;
            } else {
              throw mbid::InputError("IdentificationOptions", "release",
                                     "unknown release mode '" + mode + "'",
                                     "detect, given (with release_time_s) or none");
            }
          })
      .def_property(
          "release_time_s", [](const IdentificationOptions& o) { return o.release_time_s; },
          [](IdentificationOptions& o, double t) {
            o.release_time_s = t;
            o.release = ReleaseMode::kGiven;  // a time is only read with kGiven
          })
      .def_readwrite("window_start_s", &IdentificationOptions::window_start_s)
      .def_readwrite("window_end_s", &IdentificationOptions::window_end_s)
      .def_readwrite("channels", &IdentificationOptions::channels)
      .def_readwrite("decimation", &IdentificationOptions::decimation)
      .def_readwrite("min_frequency_hz", &IdentificationOptions::min_frequency_hz)
      .def_readwrite("max_frequency_hz", &IdentificationOptions::max_frequency_hz)
      .def_readwrite("min_damping_ratio", &IdentificationOptions::min_damping_ratio)
      .def_readwrite("max_damping_ratio", &IdentificationOptions::max_damping_ratio)
      .def_readwrite("max_modes", &IdentificationOptions::max_modes)
      .def_readwrite("min_correlation", &IdentificationOptions::min_correlation)
      .def_readwrite("drop_insignificant", &IdentificationOptions::drop_insignificant)
      .def_readwrite("compute_spectrum", &IdentificationOptions::compute_spectrum)
      .def_readwrite("compute_stabilization", &IdentificationOptions::compute_stabilization)
      .def_readwrite("compute_uncertainty", &IdentificationOptions::compute_uncertainty)
      .def_readwrite("remove_drift", &IdentificationOptions::remove_drift)
      .def_readwrite("skip_clipped", &IdentificationOptions::skip_clipped)
      .def_property(
          "backbone",
          [](const IdentificationOptions& o) {
            return mbid::identification::BackboneModeName(o.backbone);
          },
          [](IdentificationOptions& o, const std::string& mode) {
            if (!mbid::identification::ParseBackboneMode(mode, &o.backbone)) {
              throw mbid::InputError("IdentificationOptions", "backbone",
                                     "unknown backbone mode '" + mode + "'",
                                     "clusters, always or never");
            }
          })
      .def("__repr__", [](const IdentificationOptions& o) {
        return "<mbid.IdentificationOptions method='" + mbid::identification::MethodName(o.method) +
               "'>";
      });

  py::class_<mbid::identification::IdentifiedMode>(m, "Mode")
      .def_readonly("frequency_hz", &mbid::identification::IdentifiedMode::frequency_hz)
      .def_readonly("decay_rate_per_s", &mbid::identification::IdentifiedMode::decay_rate_per_s)
      .def_readonly("damping_ratio", &mbid::identification::IdentifiedMode::damping_ratio)
      .def_readonly("undamped_frequency_hz",
                    &mbid::identification::IdentifiedMode::undamped_frequency_hz)
      .def_readonly("std_frequency_hz", &mbid::identification::IdentifiedMode::std_frequency_hz)
      .def_readonly("std_decay_rate_per_s",
                    &mbid::identification::IdentifiedMode::std_decay_rate_per_s)
      .def_readonly("significant", &mbid::identification::IdentifiedMode::significant)
      .def_readonly("combination", &mbid::identification::IdentifiedMode::combination)
      .def_property_readonly(
          "amplitude",
          [](const mbid::identification::IdentifiedMode& mode) { return ToArray(mode.amplitude); })
      .def_property_readonly(
          "phase_rad",
          [](const mbid::identification::IdentifiedMode& mode) { return ToArray(mode.phase_rad); })
      .def("__repr__", [](const mbid::identification::IdentifiedMode& mode) {
        return "<mbid.Mode " + std::to_string(mode.frequency_hz) + " Hz, damping ratio " +
               std::to_string(mode.damping_ratio) + ">";
      });

  py::class_<mbid::ModalResult>(m, "ModalResult")
      .def_readonly("modes", &mbid::ModalResult::modes)
      .def_readonly("reliable", &mbid::ModalResult::reliable)
      .def_readonly("reasons", &mbid::ModalResult::reasons)
      .def_readonly("warnings", &mbid::ModalResult::warnings)
      .def_readonly("method", &mbid::ModalResult::method)
      .def_readonly("channels", &mbid::ModalResult::channels)
      .def_readonly("release_time_s", &mbid::ModalResult::release_time_s)
      .def_readonly("release", &mbid::ModalResult::release)
      .def_readonly("next_excitation_s", &mbid::ModalResult::next_excitation_s)
      .def_readonly("start_time_s", &mbid::ModalResult::start_time_s)
      .def_readonly("sample_interval_s", &mbid::ModalResult::sample_interval_s)
      .def_readonly("model_order", &mbid::ModalResult::model_order)
      .def_property_readonly("correlation",
                             [](const mbid::ModalResult& r) { return ToArray(r.correlation); })
      .def_property_readonly(
          "residual_to_noise",
          [](const mbid::ModalResult& r) { return ToArray(r.residual_to_noise); })
      .def_property_readonly("residual_window_ratio", [](const mbid::ModalResult& r) {
        return ToArray(r.residual_window_ratio);
      });

  py::class_<mbid::ParameterValue>(m, "Parameter")
      .def_readonly("value", &mbid::ParameterValue::value)
      .def_readonly("std", &mbid::ParameterValue::std)
      .def_readonly("relative_std", &mbid::ParameterValue::relative_std)
      .def_readonly("interval_lower", &mbid::ParameterValue::interval_lower)
      .def_readonly("interval_upper", &mbid::ParameterValue::interval_upper)
      .def_readonly("profile_lower", &mbid::ParameterValue::profile_lower)
      .def_readonly("profile_upper", &mbid::ParameterValue::profile_upper)
      .def_readonly("profile_lower_open", &mbid::ParameterValue::profile_lower_open)
      .def_readonly("profile_upper_open", &mbid::ParameterValue::profile_upper_open)
      .def_readonly("determined", &mbid::ParameterValue::determined)
      .def_readonly("why_undetermined", &mbid::ParameterValue::why_undetermined)
      .def_readonly("units", &mbid::ParameterValue::units)
      .def_readonly("test", &mbid::ParameterValue::test)
      .def("__repr__", [](const mbid::ParameterValue& p) {
        return "<mbid.Parameter " + std::to_string(p.value) + " +- " + std::to_string(p.std) + " " +
               p.units + ">";
      });

  py::class_<mbid::UpdateResult>(m, "UpdateResult")
      .def_readonly("parameters", &mbid::UpdateResult::parameters)
      .def_readonly("converged", &mbid::UpdateResult::converged)
      .def_readonly("credible", &mbid::UpdateResult::credible)
      .def_readonly("credibility", &mbid::UpdateResult::credibility)
      .def_readonly("non_unique", &mbid::UpdateResult::non_unique)
      .def_readonly("undetermined", &mbid::UpdateResult::undetermined)
      .def_readonly("start", &mbid::UpdateResult::start)
      .def_readonly("chi_square_per_dof", &mbid::UpdateResult::chi_square_per_dof)
      .def_readonly("release_time_s", &mbid::UpdateResult::release_time_s)
      .def_readonly("release", &mbid::UpdateResult::release);

  py::class_<mbid::ValidationResult>(m, "ValidationResult")
      .def_property_readonly(
          "verdict", [](const mbid::ValidationResult& r) { return mbid::ToString(r.verdict); })
      .def_readonly("reasons", &mbid::ValidationResult::reasons)
      .def_readonly("min_correlation", &mbid::ValidationResult::min_correlation)
      .def_readonly("correlation", &mbid::ValidationResult::correlation)
      .def_readonly("identified", &mbid::ValidationResult::identified)
      .def_readonly("updated", &mbid::ValidationResult::updated);

  // Paths as str or os.PathLike (pathlib.Path); a scenario or record argument may be one.
  m.def(
      "load_scenario",
      [](const py::object& path) {
        return mbid::LoadScenario(PathArgument(path, "load_scenario"));
      },
      py::arg("path"), "Reads a scenario file.");
  m.def("load_scenario_text", &mbid::LoadScenarioFromText, py::arg("yaml"),
        py::arg("source") = "scenario", "A scenario from YAML text.");
  m.def(
      "default_scenario_path",
      [](const std::string& hint) { return mbid::DefaultScenarioPath(hint); },
      py::arg("data_dir_hint") = "", "The built-in reference scenario's file.");
  m.def(
      "simulate",
      [](const py::object& scenario_object) {
        const mbid::Scenario scenario = AsScenario(scenario_object, "simulate");
        return Interruptible([&] { return mbid::Simulate(scenario); });
      },
      py::arg("scenario"), "Simulates the scenario's test (a Scenario or its file): a Record.");
  m.def(
      "read_record",
      [](const py::object& path) { return mbid::ReadRecord(PathArgument(path, "read_record")); },
      py::arg("path"), "Reads a record file (CSV, HDF5, MAT, UFF58, LVM), SI units.");
  m.def(
      "identify",
      [](const py::object& record_object, const IdentificationOptions& options,
         const py::object& scenario_object) {
        const mbid::Measurement record = AsRecord(record_object, "identify", "record");
        std::optional<mbid::Scenario> scenario;
        if (!scenario_object.is_none()) scenario = AsScenario(scenario_object, "identify");
        // A record file mbid simulated carries its test, as `mbid identify` reads it.
        IdentificationOptions applied = options;
        const std::optional<std::string> path = AsPath(record_object);
        if (!scenario && path) {
          std::string said;
          applied = mbid::validation::RecordFileOptions(mbid::validation::ReadRecordScenario(*path),
                                                        *path, options, &said);
        }
        return Interruptible([&] {
          return scenario ? mbid::IdentifyTest(record, *scenario, applied)
                          : mbid::Identify(record, applied);
        });
      },
      py::arg("record"), py::arg("options") = IdentificationOptions(),
      py::arg("scenario") = py::none(),
      "Identifies the modes of a free-decay record (a Record or its file; options: "
      "IdentificationOptions); with the scenario of its test, after an impulse or burst from "
      "where the forcing ends.");
  m.def(
      "identify_arrays",
      [](const py::object& time, const py::object& channels, const py::object& units,
         const IdentificationOptions& options) {
        const mbid::Measurement record =
            MakeRecord(time, StringKeyed<py::object>(channels, "channels", "arrays"),
                       StringKeyed<std::string>(units, "units", "unit strings"));
        return Interruptible([&] { return mbid::Identify(record, options); });
      },
      py::arg("time"), py::arg("channels"), py::arg("units") = py::dict(),
      py::arg("options") = IdentificationOptions(),
      "Identifies the modes of a free decay given as arrays: time (s, uniform) and {name: "
      "values}.");
  m.def(
      "update",
      [](const py::object& scenario_object, const py::object& records_object) {
        const mbid::Scenario scenario = AsScenario(scenario_object, "update");
        std::vector<std::string> paths;
        const std::vector<mbid::Measurement> records = AsRecords(records_object, &paths);
        try {
          return Interruptible([&] { return mbid::Update(scenario, records); });
        } catch (const mbid::InputError& error) {
          // The library names a record by its place ("record 1"); a file given by its path is
          // named by it, as the command line does.
          for (size_t i = 0; i < paths.size(); ++i) {
            if (!paths[i].empty() && error.source() == "record " + std::to_string(i + 1)) {
              throw mbid::InputError(paths[i], error.field(), error.problem(), error.expected());
            }
          }
          throw;
        }
      },
      py::arg("scenario"), py::arg("records"),
      "Tunes the scenario's model (a Scenario or its file) to the records (Records or their "
      "files): .parameters['c_alpha'].value, .std.");
  m.def(
      "run",
      [](const py::object& scenario_object, const py::object& output_folder, bool overwrite,
         bool quiet) {
        const mbid::Scenario scenario = AsScenario(scenario_object, "run");
        mbid::ValidationOptions options;
        // None: in memory (a default path would come back from Python as ".").
        if (!output_folder.is_none()) {
          const std::optional<std::string> path = AsPath(output_folder);
          if (!path) {
            throw py::type_error("run(): output_folder is of type " + TypeName(output_folder) +
                                 "; expected None, a str or os.PathLike");
          }
          options.output_folder = *path;
        }
        options.overwrite = overwrite;
        options.quiet = quiet;
        return Interruptible([&] { return mbid::RunValidationCycle(scenario, options); });
      },
      py::arg("scenario"), py::arg("output_folder") = py::none(), py::arg("overwrite") = false,
      py::arg("quiet") = true,
      "The validation cycle of a Scenario (or its file) in memory: .verdict is 'passed', "
      "'failed' or 'inconclusive'.");
}
