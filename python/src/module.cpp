// erodem — the Python extension module `erodem._erodem` (pybind11). A thin layer over the
// C++ API: parameters go through the one schema (apply_setting / load_config / validate),
// terrain through io::load_terrain, runs through Simulation and io::ResultWriter exactly as
// `erodem run` drives them. The public Python API is the package `erodem` on top of it
// (python/erodem/: _params.py, dem.py, simulation.py, results.py and sweep.py, re-exported
// by __init__.py); docs/python.md describes both.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "erodem/backends.hpp"

namespace py = pybind11;

PYBIND11_MODULE(_erodem, m) {
  m.doc() =
      "erodem's C++ core: terrain loading, simulations on the CPU and OpenCL backends, result "
      "files. Use it through the package `erodem`.";
  erodem::python::add_error_bindings(m);
  erodem::python::add_schema_bindings(m);
  erodem::python::add_terrain_bindings(m);
  erodem::python::add_simulation_bindings(m);
  // The OpenCL runtimes (contexts, built programs) that outlive the simulations are released
  // at interpreter exit: atexit runs at the start of the interpreter's finalisation, long
  // before the C++ static destructors, after which the OpenCL implementation may be gone
  // (backends.hpp). A simulation still alive then releases its runtime with itself.
  m.def("release_opencl_runtimes", &erodem::release_opencl_runtimes,
        "Releases the OpenCL contexts and programs kept for later simulations; returns how many "
        "are still held by live simulations. Called at interpreter exit.");
  py::module_::import("atexit").attr("register")(m.attr("release_opencl_runtimes"));
}
