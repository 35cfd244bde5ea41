// erodem — Python bindings: Simulation (step, advance with the GIL released, fields as numpy
// views, ledger, result files, restart), thin over io::RunSession, the run driver of
// `erodem run`: the same code writes both result files.
#include "erodem/simulation.hpp"

#include <fmt/format.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <memory>
#include <utility>

#include "bindings.hpp"
#include "erodem/error.hpp"
#include "erodem/io/config.hpp"
#include "erodem/io/results.hpp"
#include "erodem/io/run_session.hpp"
#include "erodem/parameter_rasters.hpp"
#include "erodem/schema.hpp"
#include "erodem/terrain_rows.hpp"
#include "terrain.hpp"

namespace py = pybind11;

namespace erodem::python {

namespace {

/// A DEM from an array has no file to read the parameter rasters on its grid with: raster
/// files are refused at once, naming the parameter.
void check_no_rasters(const Params& p) {
  std::string key;
  for (const auto& r : parameter_rasters())
    if (key.empty() && !parameter_raster_path(r, p).empty()) key = r.key;
  if (key.empty() && !p.rain.grids.empty()) key = "rain.grids";
  if (key.empty() && !p.snow.temperature_grids.empty()) key = "snow.temperature_grids";
  if (!key.empty())
    throw Error(ExitCode::config,
                fmt::format("parameter '{}': a raster file needs a DEM read from a file "
                            "(erodem.read_dem); this DEM comes from an array (DEM.from_array). "
                            "Give a uniform value, or write the DEM to a GeoTIFF and read it",
                            key));
}

/// A simulation driven from Python: an io::RunSession. Not thread-safe: one call at a time
/// (a second thread calling advance() while one runs gets RuntimeError).
class PySimulation {
 public:
  /// The config is `config_path` ("" for none) or, with `config_from_restart`, the stored
  /// run's (`restart`'s config_toml); then `settings` are applied; with `terrain` its dem.*
  /// settings replace the config's, and its terrain is used as it is (unless parameter
  /// rasters must be read on its grid). `restart` ("FILE.h5[:TIME]", or "") continues a
  /// stored run. Built with the GIL released.
  PySimulation(const std::string& config_path, const Settings& settings, const PyTerrain* terrain,
               const std::string& backend, const std::string& restart, bool config_from_restart,
               const std::string& command_line) {
    Params p = !config_path.empty()  ? load_config(config_path)
               : config_from_restart ? io::stored_params(restart)
                                     : Params();
    apply_settings(p, settings);
    if (terrain) p.dem = terrain->dem;
    if (terrain && terrain->in_memory) check_no_rasters(p);
    validate(p, !config_path.empty()  ? config_path
                : config_from_restart ? io::split_restart(restart).first + " (config_toml)"
                                      : "parameters");
    io::SessionOptions options;
    options.backend = backend;
    options.command_line = command_line;
    options.restart = restart;
    options.restart_label = "restart";
    options.write = false;  // a file is opened by run(output=...)
    options.terrain = terrain ? &terrain->terrain : nullptr;
    py::gil_scoped_release release;
    session_ = std::make_unique<io::RunSession>(std::move(p), std::move(options));
  }

  io::RunSession& session() { return *session_; }
  const io::RunSession& session() const { return *session_; }
  Simulation& sim() { return session_->sim(); }
  const Simulation& sim() const { return session_->sim(); }

  /// Runs up to `max_steps` steps, stopping at the configured end when `to_end` and once the
  /// time reaches `until_time` (s), with the GIL released in chunks of about `chunk_seconds`
  /// of wall time (RunSession::advance). Between chunks it checks for signals: a pending
  /// Ctrl-C raises KeyboardInterrupt there, between two whole steps. An open result file
  /// records every step as `erodem run` does. With `once`, returns after the first chunk.
  /// Returns the steps run.
  long advance(long max_steps, bool to_end, double until_time, double chunk_seconds, bool once);

  /// Opens a result file with the simulation's output settings changed by `settings`
  /// (output.* keys only) and takes its first snapshot (the current state).
  void open_output(const Settings& settings, bool overwrite) {
    Params p = sim().params();
    for (const auto& [key, text] : settings) {
      if (key.rfind("output.", 0) != 0)
        throw Error(ExitCode::config, "run: '" + key + "' is not an output.* setting");
    }
    apply_settings(p, settings);
    validate(p, "run");
    py::gil_scoped_release release;
    session_->open_output(p, overwrite);
  }

  /// The largest max_depth over the steps run through advance() (m).
  double peak_depth() const { return peak_depth_; }

  /// Field `name` as numpy: a view of the backend's host memory where there is one (CPU),
  /// else a read-only copy (OpenCL, derived fields). `self` becomes the view's base.
  py::array field(const py::object& self, const std::string& name) {
    const FieldId id = field_info(name).id;
    const Grid& g = sim().grid();
    const HostView v = sim().backend().host_view(id);
    const std::vector<py::ssize_t> shape{g.ny, g.nx};
    if (v.data) {
      const py::dtype dt = v.element_size == 4 ? py::dtype::of<float>() : py::dtype::of<double>();
      const std::vector<py::ssize_t> strides{
          static_cast<py::ssize_t>(v.row_stride * static_cast<std::ptrdiff_t>(v.element_size)),
          static_cast<py::ssize_t>(v.element_size)};
      return py::array(dt, shape, strides, v.data, self);
    }
    const std::vector<double> values = sim().field(id);
    py::array out;
    if (sim().params().numerics.precision == Precision::float32) {
      py::array_t<float> a(shape);
      std::transform(values.begin(), values.end(), a.mutable_data(),
                     [](double x) { return static_cast<float>(x); });
      out = a;
    } else {
      py::array_t<double> a(shape);
      std::copy(values.begin(), values.end(), a.mutable_data());
      out = a;
    }
    out.attr("setflags")(py::arg("write") = false);
    return out;
  }

  /// Replaces field `name` with `values` (ny, nx) on any backend (an upload on OpenCL).
  void set_field(const std::string& name,
                 const py::array_t<double, py::array::c_style | py::array::forcecast>& a) {
    const FieldInfo& info = field_info(name);
    const Grid& g = sim().grid();
    if (a.ndim() != 2 || a.shape(0) != g.ny || a.shape(1) != g.nx)
      throw Error(ExitCode::config,
                  fmt::format("field '{}': expected an array of shape ({}, {}), got {}", name, g.ny,
                              g.nx, shape_text(a)));
    if (info.id == FieldId::erosion)
      throw Error(ExitCode::config,
                  "field 'erosion' is derived (initial_bed - bed); set bed or initial_bed");
    std::vector<double> v(a.data(), a.data() + a.size());
    sim().backend().set_field(info.id, v);
  }

  /// (eroded, deposited) volume (m^3): the sums over active cells of max(erosion, 0) * area
  /// and max(-erosion, 0) * area, with erosion = initial bed - bed.
  std::pair<double, double> erosion_volumes() const {
    const std::vector<double> e = sim().field(FieldId::erosion);
    const Grid& g = sim().grid();
    const std::vector<std::uint8_t> on = active_grid(sim().terrain());
    double eroded = 0.0, deposited = 0.0;
    for (int r = 0; r < g.ny; ++r) {
      for (int c = 0; c < g.nx; ++c) {
        const std::size_t i = static_cast<std::size_t>(r) * g.nx + c;
        if (!on[i] || !std::isfinite(e[i])) continue;
        if (e[i] > 0)
          eroded += e[i] * g.area[r];
        else
          deposited -= e[i] * g.area[r];
      }
    }
    return {eroded, deposited};
  }

 private:
  static std::string shape_text(const py::array& a) {
    std::string s = "(";
    for (py::ssize_t k = 0; k < a.ndim(); ++k) s += (k ? ", " : "") + std::to_string(a.shape(k));
    return s + (a.ndim() == 1 ? ",)" : ")");
  }

  std::unique_ptr<io::RunSession> session_;
  std::atomic<bool> busy_{false};
  double peak_depth_ = 0.0;
};

long PySimulation::advance(long max_steps, bool to_end, double until_time, double chunk_seconds,
                           bool once) {
  if (busy_.exchange(true))
    throw Error(ExitCode::usage, "the simulation is already running in another thread");
  struct Clear {
    std::atomic<bool>& flag;
    ~Clear() { flag = false; }
  } clear{busy_};
  const long first = sim().steps_done();
  const auto on_step = [this](const Simulation& s) {
    peak_depth_ = std::max(peak_depth_, s.diagnostics().max_depth);
  };
  for (;;) {
    io::Limits limits;
    limits.max_steps = max_steps - (sim().steps_done() - first);
    limits.to_end = to_end;
    limits.until_time = until_time;
    limits.wall_seconds = std::max(chunk_seconds, 0.0);
    io::Stop stop;
    {
      py::gil_scoped_release release;
      stop = session_->advance(limits, {}, on_step);
    }
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    if (once || stop != io::Stop::wall) break;
  }
  return sim().steps_done() - first;
}

py::dict ledger_dict(const Ledger& l) {
  py::dict d;
  for (const auto& e : ledger_entries()) d[e.name] = l.*e.member;
  d["closure_error"] = l.closure_error();
  d["relative_closure_error"] = l.relative_closure_error();
  d["material_closure_error"] = l.material_closure_error();
  d["relative_material_closure_error"] = l.relative_material_closure_error();
  d["water_moved"] = l.water_moved();
  d["material_moved"] = l.material_moved();
  return d;
}

py::dict diagnostics_dict(const Diagnostics& g) {
  py::dict d;
  for (const auto& s : diagnostics_series()) d[s.name] = g.*s.member;
  return d;
}

}  // namespace

void add_simulation_bindings(py::module_& m) {
  py::class_<PySimulation>(m, "Simulation", "The C++ simulation behind erodem.Simulation.")
      .def(py::init<const std::string&, const Settings&, const PyTerrain*, const std::string&,
                    const std::string&, bool, const std::string&>(),
           py::arg("config_path"), py::arg("settings"), py::arg("terrain"), py::arg("backend"),
           py::arg("restart"), py::arg("config_from_restart"), py::arg("command_line"))
      .def("advance", &PySimulation::advance, py::arg("max_steps"), py::arg("to_end"),
           py::arg("until_time"), py::arg("chunk_seconds"), py::arg("once"))
      .def("open_output", &PySimulation::open_output, py::arg("settings"), py::arg("overwrite"))
      .def("finish_output",
           [](PySimulation& s) {
             py::gil_scoped_release release;
             s.session().finish();
           })
      .def("abandon_output",
           [](PySimulation& s) {
             py::gil_scoped_release release;
             s.session().abandon();
           })
      .def("close_output", [](PySimulation& s) { s.session().close_output(); })
      .def_property_readonly("output_open",
                             [](const PySimulation& s) { return s.session().writing(); })
      .def_property_readonly("output_path",
                             [](const PySimulation& s) {
                               const auto* w = s.session().writer();
                               return w ? w->path() : std::string();
                             })
      .def_property_readonly("output_partial",
                             [](const PySimulation& s) {
                               const auto* w = s.session().writer();
                               return w ? w->partial() : std::string();
                             })
      .def_property_readonly("restart_from",
                             [](const PySimulation& s) { return s.session().restart_from(); })
      .def_property_readonly("warnings",
                             [](const PySimulation& s) { return s.session().warnings(); })
      .def(
          "field",
          [](const py::object& self, const std::string& name) {
            return self.cast<PySimulation&>().field(self, name);
          },
          py::arg("name"))
      .def("set_field", &PySimulation::set_field, py::arg("name"), py::arg("values"))
      .def("erosion_volumes", &PySimulation::erosion_volumes)
      .def_property_readonly("peak_depth", &PySimulation::peak_depth)
      .def_property_readonly("finished", [](const PySimulation& s) { return s.sim().finished(); })
      .def_property_readonly("progress", [](const PySimulation& s) { return s.sim().progress(); })
      .def_property_readonly("time", [](const PySimulation& s) { return s.sim().time(); })
      .def_property_readonly("steps_done",
                             [](const PySimulation& s) { return s.sim().steps_done(); })
      .def_property_readonly("next_dt", [](const PySimulation& s) { return s.sim().next_dt(); })
      .def_property_readonly("ledger",
                             [](const PySimulation& s) { return ledger_dict(s.sim().ledger()); })
      .def_property_readonly("ledger_text",
                             [](const PySimulation& s) { return s.sim().ledger().format(); })
      .def_property_readonly(
          "diagnostics",
          [](const PySimulation& s) { return diagnostics_dict(s.sim().diagnostics()); })
      .def_property_readonly("sections",
                             [](const PySimulation& s) {
                               py::dict d;
                               const Simulation& sim = s.sim();
                               for (std::size_t k = 0; k < sim.sections().size(); ++k) {
                                 const SectionState& st = sim.sections()[k];
                                 py::dict row;
                                 row["discharge"] = st.discharge;
                                 row["sediment_flux"] = st.sediment_flux;
                                 row["volume"] = st.volume;
                                 row["sediment_volume"] = st.sediment_volume;
                                 row["peak_discharge"] = st.peak_discharge;
                                 row["peak_time"] = st.peak_time;
                                 row["outlet"] = static_cast<bool>(sim.section_layout().outlet[k]);
                                 d[py::str(sim.section_layout().names[k])] = row;
                               }
                               return d;
                             })
      .def_property_readonly("backend",
                             [](const PySimulation& s) { return s.sim().backend().name(); })
      .def_property_readonly("device",
                             [](const PySimulation& s) { return s.sim().backend().device(); })
      .def_property_readonly("config_toml",
                             [](const PySimulation& s) { return dump_toml(s.sim().params()); })
      .def_property_readonly("configured_steps",
                             [](const PySimulation& s) { return s.sim().params().time.steps; })
      .def_property_readonly("configured_duration",
                             [](const PySimulation& s) { return s.sim().params().time.duration; })
      .def_property_readonly("shape",
                             [](const PySimulation& s) {
                               return py::make_tuple(s.sim().grid().ny, s.sim().grid().nx);
                             })
      .def_property_readonly("area", [](const PySimulation& s) { return s.sim().grid().area; })
      .def_property_readonly(
          "active",
          [](const PySimulation& s) {
            const Grid& g = s.sim().grid();
            const std::vector<std::uint8_t> on = active_grid(s.sim().terrain());
            py::array_t<bool> a({static_cast<py::ssize_t>(g.ny), static_cast<py::ssize_t>(g.nx)});
            bool* out = a.mutable_data();
            for (std::size_t i = 0; i < g.cells(); ++i) out[i] = on[i] != 0;
            return a;
          },
          "Active cells: bool (ny, nx), False at the DEM's nodata cells. A copy.");
}

}  // namespace erodem::python
