// The Python module `mbid` (its compiled part, mbid._mbid): the facade of <mbid/mbid.h> with
// records as numpy arrays and mbid's errors as Python exceptions with the same one-line text.
#include <glog/logging.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include "arguments.h"
#include "interruptible.h"
#include "mbid/mbid.h"
#include "mbid/records/records.h"
#include "mbid/validation/identification_settings.h"

namespace py = pybind11;
using namespace mbid::python;  // NOLINT: the module's own helpers (arguments.h, interruptible.h)

namespace {

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
        return mbid::python::Interruptible([&] { return mbid::Simulate(scenario); });
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
        return mbid::python::Interruptible([&] {
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
        return mbid::python::Interruptible([&] { return mbid::Identify(record, options); });
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
          return mbid::python::Interruptible([&] { return mbid::Update(scenario, records); });
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
        return mbid::python::Interruptible(
            [&] { return mbid::RunValidationCycle(scenario, options); });
      },
      py::arg("scenario"), py::arg("output_folder") = py::none(), py::arg("overwrite") = false,
      py::arg("quiet") = true,
      "The validation cycle of a Scenario (or its file) in memory: .verdict is 'passed', "
      "'failed' or 'inconclusive'.");
}
