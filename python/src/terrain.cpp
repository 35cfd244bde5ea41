// erodem — Python bindings: loading a DEM (erodem.read_dem).
#include "terrain.hpp"

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cmath>

#include "bindings.hpp"
#include "erodem/io/setup.hpp"
#include "erodem/schema.hpp"

namespace py = pybind11;

namespace erodem::python {

namespace {

/// Reads the DEM that `settings` (dem.* keys only) describe, with the GIL released.
PyTerrain load(const Settings& settings) {
  Params p;
  for (const auto& [key, text] : settings) {
    if (key.rfind("dem.", 0) != 0)
      throw Error(ExitCode::config, "read_dem: '" + key + "' is not a dem.* setting");
  }
  apply_settings(p, settings);
  validate(p, "read_dem");
  py::gil_scoped_release release;
  PyTerrain t;
  t.dem = p.dem;
  t.terrain = io::load_terrain(p);
  return t;
}

/// A row-major (ny, nx) numpy array of `values` converted to T (a copy).
template <class T, class V>
py::array_t<T> grid_array(const std::vector<V>& values, const Grid& g) {
  py::array_t<T> a({static_cast<py::ssize_t>(g.ny), static_cast<py::ssize_t>(g.nx)});
  T* out = a.mutable_data();
  for (std::size_t i = 0; i < values.size(); ++i) out[i] = static_cast<T>(values[i]);
  return a;
}

}  // namespace

void add_terrain_bindings(py::module_& m) {
  py::class_<PyTerrain>(m, "Terrain",
                        "A DEM on its grid, read with its dem.* settings (see erodem.read_dem).")
      .def(py::init(&load), py::arg("settings"),
           "Reads the DEM described by `settings`, a list of (dem.* key, TOML value text).")
      .def_property_readonly(
          "elevation",
          [](const PyTerrain& t) { return grid_array<float>(t.terrain.bed, t.terrain.grid); },
          "Bed elevation (m), float32 (ny, nx), row 0 north; NaN at nodata cells. A copy.")
      .def_property_readonly(
          "mask",
          [](const PyTerrain& t) {
            const Grid& g = t.terrain.grid;
            if (t.terrain.mask.empty()) {
              py::array_t<bool> a({static_cast<py::ssize_t>(g.ny), static_cast<py::ssize_t>(g.nx)});
              std::fill(a.mutable_data(), a.mutable_data() + g.cells(), true);
              return a;
            }
            return grid_array<bool>(t.terrain.mask, g);
          },
          "Active cells: bool (ny, nx), False where the DEM is nodata. A copy.")
      .def_property_readonly(
          "transform", [](const PyTerrain& t) { return t.terrain.grid.georef.transform; },
          "GDAL geotransform (x0, pixel width, 0, y0, 0, pixel height) of the top-left corner, "
          "in the CRS's units (degrees for geographic grids, else metres).")
      .def_property_readonly(
          "has_transform", [](const PyTerrain& t) { return t.terrain.grid.georef.has_transform; },
          "Whether the file carried a geotransform (False: a uniform grid of dem.cell_size).")
      .def_property_readonly(
          "crs", [](const PyTerrain& t) { return t.terrain.grid.georef.crs_wkt; },
          "The CRS as WKT ('' when unknown).")
      .def_property_readonly(
          "is_geographic", [](const PyTerrain& t) { return t.terrain.grid.georef.is_geographic; },
          "True for lat/lon grids (cell sizes from the ellipsoid, varying by row).")
      .def_property_readonly(
          "dx", [](const PyTerrain& t) { return t.terrain.grid.dx; },
          "East-west cell size of each row (m), a list of ny values.")
      .def_property_readonly(
          "dy", [](const PyTerrain& t) { return t.terrain.grid.dy; },
          "North-south cell size of each row (m), a list of ny values.")
      .def_property_readonly(
          "area", [](const PyTerrain& t) { return t.terrain.grid.area; },
          "Cell area of each row (m^2), a list of ny values.")
      .def_property_readonly(
          "shape",
          [](const PyTerrain& t) { return py::make_tuple(t.terrain.grid.ny, t.terrain.grid.nx); },
          "(ny, nx).")
      .def_property_readonly(
          "source", [](const PyTerrain& t) { return t.terrain.source; }, "The DEM path.")
      .def_property_readonly(
          "sha256", [](const PyTerrain& t) { return t.terrain.source_sha256; },
          "SHA-256 of the DEM file (lower-case hex).");
}

}  // namespace erodem::python
