// erodem — Python bindings: loading a DEM (erodem.read_dem).
#include "terrain.hpp"

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "bindings.hpp"
#include "erodem/error.hpp"
#include "erodem/io/geodesy.hpp"
#include "erodem/io/raster.hpp"
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

/// A terrain from elevations in memory (erodem.DEM.from_array, which checks the arguments
/// first): `z` (ny, nx) in m, row 0 north, NaN at nodata. With `has_transform`, `transform`
/// is the GDAL geotransform of the top-left corner in the units of `crs` (degrees for a
/// geographic CRS: cell sizes and areas then come from its ellipsoid, as read_dem computes
/// them; metres without a CRS); else the cells are squares of `cell_size` m. `source` names
/// it (as the path of a file would) and `sha256` is the checksum of its values.
PyTerrain from_array(const py::array_t<double, py::array::c_style | py::array::forcecast>& z,
                     const std::array<double, 6>& transform, bool has_transform, double cell_size,
                     const std::string& crs, const std::string& source, const std::string& sha256) {
  if (z.ndim() != 2 || z.shape(0) < 1 || z.shape(1) < 1)
    throw Error(ExitCode::config, "DEM.from_array: 'z' must be a non-empty 2-D array");
  PyTerrain out;
  out.in_memory = true;
  out.dem.path = source;  // names it in messages and in the config a result file records
  Terrain& t = out.terrain;
  Grid& g = t.grid;
  const int ny = static_cast<int>(z.shape(0)), nx = static_cast<int>(z.shape(1));
  io::CrsInfo info;
  if (!crs.empty()) {
    try {
      info = io::describe_crs(crs);
    } catch (const Error& e) {
      throw Error(ExitCode::config, "DEM.from_array: 'crs' " + crs + ": " + e.what());
    }
  }
  if (has_transform) {
    if (transform[2] != 0.0 || transform[4] != 0.0)
      throw Error(ExitCode::config,
                  "DEM.from_array: 'transform': rotated geotransforms are not supported");
    g.nx = nx;
    g.ny = ny;
    g.georef.transform = transform;
    g.georef.has_transform = true;
    g.georef.crs_wkt = info.wkt;
    if (info.geographic) {
      g.georef.is_geographic = true;
      const double deg = info.unit_factor;
      io::set_geographic_rows(g, info.ellipsoid, transform[3] * deg, transform[5] * deg,
                              transform[1] * deg, "DEM.from_array");
    } else {
      const double unit = crs.empty() ? 1.0 : info.unit_factor;
      const double dx = std::fabs(transform[1]) * unit, dy = std::fabs(transform[5]) * unit;
      if (!(std::isfinite(dx) && dx > 0.0 && std::isfinite(dy) && dy > 0.0))
        throw Error(ExitCode::config,
                    "DEM.from_array: 'transform': the pixel sizes must be finite and non-zero");
      g.dx.assign(static_cast<std::size_t>(ny), dx);
      g.dy.assign(static_cast<std::size_t>(ny), dy);
      g.area.assign(static_cast<std::size_t>(ny), dx * dy);
    }
  } else {
    if (!(std::isfinite(cell_size) && cell_size > 0.0))
      throw Error(ExitCode::config, "DEM.from_array: 'cell_size' must be a positive length (m)");
    if (info.geographic)
      throw Error(ExitCode::config,
                  "DEM.from_array: 'crs' " + crs +
                      " is geographic (lat/lon): give 'transform' in degrees instead of "
                      "'cell_size'");
    g = Grid::uniform(nx, ny, cell_size);
    g.georef.has_transform = false;
    if (!crs.empty()) {
      g.georef.crs_wkt = info.wkt;
      for (double* v : {&g.georef.transform[0], &g.georef.transform[1], &g.georef.transform[3],
                        &g.georef.transform[5]})
        *v /= info.unit_factor;
    }
  }
  g.validate();
  t.bed.assign(z.data(), z.data() + z.size());
  std::vector<std::uint8_t> mask(t.bed.size(), 1);
  std::size_t n_valid = 0;
  for (std::size_t i = 0; i < t.bed.size(); ++i) {
    if (std::isfinite(t.bed[i])) {
      ++n_valid;
    } else {
      mask[i] = 0;
      t.bed[i] = std::nan("");
    }
  }
  if (n_valid == 0)
    throw Error(ExitCode::config, "DEM.from_array: 'z' has no finite value (every cell nodata)");
  if (n_valid < t.bed.size()) t.mask = std::move(mask);
  t.source = source;
  t.source_sha256 = sha256;
  return out;
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
      .def_static("from_array", &from_array, py::arg("z"), py::arg("transform"),
                  py::arg("has_transform"), py::arg("cell_size"), py::arg("crs"), py::arg("source"),
                  py::arg("sha256"),
                  "A terrain from elevations in memory (see erodem.DEM.from_array).")
      .def_property_readonly(
          "in_memory", [](const PyTerrain& t) { return t.in_memory; },
          "Built from an array (DEM.from_array) rather than read from a file.")
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
