// erodem — Python bindings: Simulation (step, advance with the GIL released, fields as numpy
// views, ledger) and ResultWriter (result files written exactly as `erodem run` writes them).
#include "erodem/simulation.hpp"

#include <fmt/format.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <memory>
#include <optional>

#include "bindings.hpp"
#include "erodem/backends.hpp"
#include "erodem/error.hpp"
#include "erodem/io/config.hpp"
#include "erodem/io/results.hpp"
#include "erodem/io/setup.hpp"
#include "erodem/schema.hpp"
#include "terrain.hpp"

namespace py = pybind11;

namespace erodem::python {

namespace {

/// Whether `p` reads any parameter raster (those are loaded on the DEM's grid by
/// io::load_terrain, so a DEM read without them cannot be reused as it is).
bool has_parameter_rasters(const Params& p) {
  return p.initial.water_depth.is_raster() || p.flow.manning_n.is_raster() ||
         p.erosion.hardness.is_raster() || !p.rain.raster.empty();
}

class PyWriter;

/// A simulation driven from Python. Not thread-safe: one call at a time (a second thread
/// calling advance() while one runs gets RuntimeError).
class PySimulation {
 public:
  /// `config_path` ("" for none) is read first, then `settings` are applied; with `terrain`
  /// its dem.* settings replace the config's, and its terrain is used as it is (unless
  /// parameter rasters must be read on its grid). Built with the GIL released.
  PySimulation(const std::string& config_path, const Settings& settings, const PyTerrain* terrain,
               const std::string& backend) {
    Params p = config_path.empty() ? Params() : load_config(config_path);
    apply_settings(p, settings);
    if (terrain) p.dem = terrain->dem;
    validate(p, config_path.empty() ? "parameters" : config_path);
    py::gil_scoped_release release;
    if (terrain && !has_parameter_rasters(p)) {
      Terrain t = terrain->terrain;
      auto be = make_backend(backend, t, p);
      sim_ = std::make_unique<Simulation>(std::move(t), p, std::move(be));
    } else {
      sim_ = std::make_unique<Simulation>(io::make_simulation(p, backend));
    }
  }

  Simulation& sim() { return *sim_; }
  const Simulation& sim() const { return *sim_; }

  /// Runs up to `max_steps` steps, stopping at the configured end when `to_end` and once the
  /// time reaches `until_time` (s), with the GIL released in chunks of about `chunk_seconds`
  /// of wall time. Between chunks it checks for signals: a pending Ctrl-C raises
  /// KeyboardInterrupt there, between two whole steps. `writer` (optional) records every
  /// step as `erodem run` does. With `once`, returns after the first chunk. Returns the steps
  /// run.
  long advance(long max_steps, bool to_end, double until_time, PyWriter* writer,
               double chunk_seconds, bool once);

  /// The largest max_depth over the steps run through advance() (m).
  double peak_depth() const { return peak_depth_; }

  /// Field `name` as numpy: a view of the backend's host memory where there is one (CPU),
  /// else a read-only copy (OpenCL, derived fields). `self` becomes the view's base.
  py::array field(const py::object& self, const std::string& name) {
    const FieldId id = field_info(name).id;
    const Grid& g = sim_->grid();
    const HostView v = sim_->backend().host_view(id);
    const std::vector<py::ssize_t> shape{g.ny, g.nx};
    if (v.data) {
      const py::dtype dt = v.element_size == 4 ? py::dtype::of<float>() : py::dtype::of<double>();
      const std::vector<py::ssize_t> strides{
          static_cast<py::ssize_t>(v.row_stride * static_cast<std::ptrdiff_t>(v.element_size)),
          static_cast<py::ssize_t>(v.element_size)};
      return py::array(dt, shape, strides, v.data, self);
    }
    const std::vector<double> values = sim_->field(id);
    py::array out;
    if (sim_->params().numerics.precision == Precision::float32) {
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
    const Grid& g = sim_->grid();
    if (a.ndim() != 2 || a.shape(0) != g.ny || a.shape(1) != g.nx)
      throw Error(ExitCode::config,
                  fmt::format("field '{}': expected an array of shape ({}, {}), got {}", name, g.ny,
                              g.nx, shape_text(a)));
    if (info.id == FieldId::erosion)
      throw Error(ExitCode::config,
                  "field 'erosion' is derived (initial_bed - bed); set bed or initial_bed");
    std::vector<double> v(a.data(), a.data() + a.size());
    sim_->backend().set_field(info.id, v);
  }

  /// (eroded, deposited) volume (m^3): the sums over active cells of max(erosion, 0) * area
  /// and max(-erosion, 0) * area, with erosion = initial bed - bed.
  std::pair<double, double> erosion_volumes() const {
    const std::vector<double> e = sim_->field(FieldId::erosion);
    const Grid& g = sim_->grid();
    const Terrain& t = sim_->terrain();
    double eroded = 0.0, deposited = 0.0;
    for (int r = 0; r < g.ny; ++r) {
      for (int c = 0; c < g.nx; ++c) {
        const std::size_t i = static_cast<std::size_t>(r) * g.nx + c;
        if (!t.active(i) || !std::isfinite(e[i])) continue;
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

  std::unique_ptr<Simulation> sim_;
  std::atomic<bool> busy_{false};
  double peak_depth_ = 0.0;
};

/// A result file being written for a PySimulation: io::ResultWriter with the simulation's
/// output settings, changed by `settings` (output.* keys). Takes the first snapshot (the
/// current state) when created, as `erodem run` does at t = 0.
class PyWriter {
 public:
  PyWriter(PySimulation& s, const Settings& settings, bool overwrite,
           const std::string& command_line) {
    Params p = s.sim().params();
    for (const auto& [key, text] : settings) {
      if (key.rfind("output.", 0) != 0)
        throw Error(ExitCode::config, "run: '" + key + "' is not an output.* setting");
    }
    apply_settings(p, settings);
    validate(p, "run");
    io::Provenance prov = io::Provenance::of(s.sim(), command_line);
    prov.config_toml = dump_toml(p);
    py::gil_scoped_release release;
    writer_ = std::make_unique<io::ResultWriter>(p.output.path, s.sim().grid(), p, prov, overwrite);
    writer_->snapshot(s.sim());
  }

  io::ResultWriter& writer() {
    if (!writer_) throw Error(ExitCode::usage, "the result file is closed already");
    return *writer_;
  }
  /// Appends a snapshot of the current state (unless this step has one).
  void snapshot(PySimulation& s) {
    py::gil_scoped_release release;
    if (writer().last_snapshot_step() != s.sim().steps_done()) writer().snapshot(s.sim());
  }
  /// The last snapshot, the .xmf sidecar, and the rename into place.
  void finish(PySimulation& s) {
    py::gil_scoped_release release;
    writer().finish(s.sim());
    writer_.reset();
  }
  /// Closes the file without renaming it: it stays at `partial`.
  void close() { writer_.reset(); }
  std::string path() const { return path_or_empty(&io::ResultWriter::path); }
  std::string partial() const { return path_or_empty(&io::ResultWriter::partial); }
  bool open() const { return static_cast<bool>(writer_); }

 private:
  std::string path_or_empty(const std::string& (io::ResultWriter::*get)() const) const {
    return writer_ ? (writer_.get()->*get)() : std::string();
  }
  std::unique_ptr<io::ResultWriter> writer_;
};

long PySimulation::advance(long max_steps, bool to_end, double until_time, PyWriter* writer,
                           double chunk_seconds, bool once) {
  if (busy_.exchange(true))
    throw Error(ExitCode::usage, "the simulation is already running in another thread");
  struct Clear {
    std::atomic<bool>& flag;
    ~Clear() { flag = false; }
  } clear{busy_};
  io::ResultWriter* w = writer ? &writer->writer() : nullptr;
  using Clock = std::chrono::steady_clock;
  const auto chunk = std::chrono::duration<double>(std::max(chunk_seconds, 0.0));
  long done = 0;
  const auto more = [&] {
    return done < max_steps && !(to_end && sim_->finished()) && sim_->time() < until_time;
  };
  while (more()) {
    {
      py::gil_scoped_release release;
      const auto start = Clock::now();
      try {
        do {
          sim_->step();
          ++done;
          peak_depth_ = std::max(peak_depth_, sim_->diagnostics().max_depth);
          if (w) w->step_done(*sim_);
        } while (more() && Clock::now() - start < chunk);
      } catch (const Error& e) {
        if (!w || e.code() != ExitCode::unstable) throw;
        // As `erodem run`: keep the failing step (diagnostics and state) in the partial file.
        try {
          w->record_step(*sim_);
          w->snapshot(*sim_);
        } catch (const Error&) {  // the partial file keeps the earlier snapshots
        }
        throw Error(e.code(), fmt::format("{}; the results up to step {} (t = {:.6g} s) are in "
                                          "{}; {} was not created",
                                          e.what(), sim_->steps_done(), sim_->time(), w->partial(),
                                          w->path()));
      }
    }
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    if (once) break;
  }
  return done;
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
      .def(py::init<const std::string&, const Settings&, const PyTerrain*, const std::string&>(),
           py::arg("config_path"), py::arg("settings"), py::arg("terrain"), py::arg("backend"))
      .def("advance", &PySimulation::advance, py::arg("max_steps"), py::arg("to_end"),
           py::arg("until_time"), py::arg("writer"), py::arg("chunk_seconds"), py::arg("once"))
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
      .def_property_readonly("area", [](const PySimulation& s) { return s.sim().grid().area; });

  py::class_<PyWriter>(m, "ResultWriter", "A result file being written for a Simulation.")
      .def(py::init<PySimulation&, const Settings&, bool, const std::string&>(), py::arg("sim"),
           py::arg("settings"), py::arg("overwrite"), py::arg("command_line"))
      .def("snapshot", &PyWriter::snapshot, py::arg("sim"))
      .def("finish", &PyWriter::finish, py::arg("sim"))
      .def("close", &PyWriter::close)
      .def_property_readonly("path", &PyWriter::path)
      .def_property_readonly("partial", &PyWriter::partial)
      .def_property_readonly("open", &PyWriter::open);
}

}  // namespace erodem::python
