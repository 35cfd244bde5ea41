// erodem — Python bindings: error translation and the parameter schema.
#include <pybind11/stl.h>

#include <string>

#include "bindings.hpp"
#include "erodem/error.hpp"
#include "erodem/fields.hpp"
#include "erodem/io/config.hpp"
#include "erodem/schema.hpp"
#include "erodem/units.hpp"

namespace py = pybind11;

namespace erodem::python {

namespace {

/// erodem.UnstableError, created once at import.
PyObject* g_unstable_error = nullptr;

/// The message of a configuration error as Python users see it: apply_setting() names its
/// source "--set"; from Python the value came from a keyword, so "--set: 'key': ..." reads
/// "parameter 'key': ...".
std::string python_message(const Error& e) {
  std::string msg = e.what();
  const std::string set_prefix = "--set: ";
  if (msg.rfind(set_prefix, 0) == 0) msg = "parameter " + msg.substr(set_prefix.size());
  return msg;
}

/// Raises `type(message)` with the attribute `exit_code`.
void raise_with_code(PyObject* type, const std::string& message, ExitCode code) {
  py::object exc = py::reinterpret_borrow<py::object>(type)(message);
  exc.attr("exit_code") = static_cast<int>(code);
  PyErr_SetObject(type, exc.ptr());
}

}  // namespace

void apply_settings(Params& p, const Settings& settings) {
  for (const auto& [key, text] : settings) apply_setting(p, key, text);
}

void add_error_bindings(py::module_& m) {
  g_unstable_error =
      PyErr_NewExceptionWithDoc("erodem._erodem.UnstableError",
                                "The simulation went unstable (NaN, negative depth or CFL "
                                "violated); the message names the step, time and cell.",
                                PyExc_RuntimeError, nullptr);
  m.add_object("UnstableError", py::handle(g_unstable_error));
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const Error& e) {
      const std::string msg = python_message(e);
      switch (e.code()) {
        case ExitCode::config:
        case ExitCode::usage:
        case ExitCode::data:
          raise_with_code(PyExc_ValueError, msg, e.code());
          break;
        case ExitCode::no_input:
          raise_with_code(PyExc_FileNotFoundError, msg, e.code());
          break;
        case ExitCode::cant_create:
        case ExitCode::io:
          raise_with_code(PyExc_OSError, msg, e.code());
          break;
        case ExitCode::unstable:
          raise_with_code(g_unstable_error, msg, e.code());
          break;
        default:
          raise_with_code(PyExc_RuntimeError, msg, e.code());
      }
    }
  });
}

void add_schema_bindings(py::module_& m) {
  m.def("parameter_keys", &parameter_keys, "All dotted parameter keys, in schema order.");
  m.def(
      "field_names",
      [] {
        std::vector<std::string> names;
        for (const auto& f : field_table()) names.emplace_back(f.name);
        return names;
      },
      "The names of every field, in the order of the C++ field table (fields.cpp).");
  m.def(
      "parameter_info",
      [](const std::string& key) {
        const ParameterInfo i = parameter_info(key);
        py::dict d;
        d["key"] = i.key;
        d["type"] = i.type;
        d["unit"] = i.unit;
        d["accepted"] = i.accepted;
        d["default"] = i.default_value;
        d["doc"] = i.doc;
        return d;
      },
      py::arg("key"),
      "What the schema knows about one parameter: key, type, SI unit, accepted range, default "
      "(TOML text) and doc line. Unknown key -> ValueError.");
  m.def("quoted_string", &quoted_string, py::arg("s"),
        "`s` as a TOML basic string: in double quotes, with \", \\ and control characters "
        "escaped (\\n, \\t, \\r, \\uXXXX), as the schema writes strings "
        "(--dump-config).");
  m.def(
      "duration_seconds",
      [](const std::string& key, const std::string& text) {
        return parse_quantity(text, Dimension::time, key, "parameter");
      },
      py::arg("key"), py::arg("text"),
      "A duration (\"10 min\", \"600\") in seconds; ValueError naming `key` otherwise.");
  m.def(
      "resolve_config",
      [](const std::string& config_path, const Settings& settings) {
        Params p = config_path.empty() ? Params() : load_config(config_path);
        apply_settings(p, settings);
        validate(p, config_path.empty() ? "parameters" : config_path);
        return dump_toml(p);
      },
      py::arg("config_path"), py::arg("settings"),
      "The fully resolved configuration (TOML text) of a config file (\"\" for none) with "
      "settings applied; errors as for Simulation.");
}

}  // namespace erodem::python
