#include "erodem/io/setup.hpp"

#include <fmt/format.h>

#include <cmath>

#include "erodem/backends.hpp"
#include "erodem/boundary_codes.hpp"
#include "erodem/error.hpp"
#include "erodem/io/raster.hpp"
#include "erodem/parameter_rasters.hpp"
#include "erodem/terrain_synth.hpp"

namespace erodem::io {

namespace {

/// Checks that the active cells of `v`, read from `path` for `key` (`what`: "value", or
/// "band k value"), hold finite values in [lo, hi]; Error(data) naming the first that does not.
void check_raster_values(const std::vector<double>& v, const Terrain& t, const std::string& path,
                         const std::string& key, const std::string& what, double lo, double hi) {
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (!t.active(i)) continue;
    if (!(std::isfinite(v[i]) && v[i] >= lo && v[i] <= hi))
      throw Error(ExitCode::data, path + ": '" + key + "' " + what + " " + std::to_string(v[i]) +
                                      " at cell " + std::to_string(i % t.grid.nx) + ", " +
                                      std::to_string(i / t.grid.nx) + " is outside [" +
                                      std::to_string(lo) + ", " + std::to_string(hi) + "]");
  }
}

/// Reads a parameter raster and checks its active cells hold finite values in [lo, hi].
std::vector<double> parameter_raster(const std::string& path, const Terrain& t, const Params& p,
                                     const std::string& key, double lo, double hi) {
  auto v = read_raster_on_grid(path, t.grid, p.dem.window, key);
  check_raster_values(v, t, path, key, "value", lo, hi);
  return v;
}

/// The bands of a gridded forcing (`key`: rain.grids, snow.temperature_grids) read from
/// `path` on the terrain's grid, plus `offset`, each band's active cells checked to hold finite
/// values in [lo, hi], and their times (s): `times` (its key `times_key`) when given, one per
/// band, else `start` plus the file's time coordinate (relative to band 1), else none (start +
/// k interval).
void load_band_series(const std::string& path, const std::string& key,
                      const std::vector<double>& times, const std::string& times_key, double start,
                      double offset, double lo, double hi, const Terrain& t, const Params& p,
                      std::vector<std::vector<double>>& bands, std::vector<double>& band_times) {
  bands = read_raster_bands_on_grid(path, t.grid, p.dem.window, key);
  if (offset != 0.0)
    for (auto& band : bands)
      for (double& v : band) v += offset;
  for (std::size_t b = 0; b < bands.size(); ++b)
    check_raster_values(bands[b], t, path, key, "band " + std::to_string(b + 1) + " value", lo, hi);
  if (!times.empty()) {
    if (times.size() != bands.size())
      throw config_error(times_key, "lists " + std::to_string(times.size()) + " times, but " +
                                        path + " has " + std::to_string(bands.size()) + " bands");
    band_times = times;
    return;
  }
  band_times = read_band_times(path, key);
  for (double& time : band_times) time += start;
}

/// What to add to the values of temperature grids for degrees C, from their band's units:
/// 0 for none or degrees C, -273.15 for kelvin (ERA5's t2m); other units are an error.
double celsius_offset(const std::string& path, const std::string& key) {
  const std::string units = read_band_units(path, key);
  for (const char* c :
       {"", "degC", "C", "deg_C", "degrees_C", "degree_Celsius", "celsius", "Celsius", "°C"})
    if (units == c) return 0.0;
  for (const char* k : {"K", "kelvin", "Kelvin", "degK", "deg_K", "degrees_K"})
    if (units == k) return -273.15;
  throw Error(ExitCode::data,
              key + ": " + path + ": its units '" + units + "' are neither degrees C nor kelvin");
}

}  // namespace

Terrain load_terrain(const Params& p) {
  // Read at full resolution, with the parameter rasters, then average everything together.
  Params::Dem full = p.dem;
  full.resample = 0.0;
  full.resample_factor = 0;
  Terrain t = full.synthetic.empty() ? read_dem(full) : make_synthetic_terrain(full);
  bool any_active = false;
  for (std::size_t i = 0; i < t.grid.cells() && !any_active; ++i) any_active = t.active(i);
  if (!any_active)
    throw Error(ExitCode::data, t.source + ": every cell is nodata; nothing to simulate");
  // a broken value (a float fill of -3.4e38, a wrong z_scale) stops here, naming the cell,
  // not as a NaN after the first step
  for (int r = 0; r < t.grid.ny; ++r)
    for (int c = 0; c < t.grid.nx; ++c) {
      const std::size_t i = static_cast<std::size_t>(r) * t.grid.nx + c;
      if (t.active(i) && !(std::abs(t.bed[i]) <= p.dem.elevation_limit))
        throw Error(ExitCode::data,
                    fmt::format("{}: cell (col {}, row {}) has elevation {:.6g} m, beyond "
                                "dem.elevation_limit = {:.6g} m (check dem.z_scale, its nodata "
                                "value, or raise the limit)",
                                t.source, c, r, t.bed[i], p.dem.elevation_limit));
    }
  for (const auto& r : parameter_rasters()) {
    const std::string path = parameter_raster_path(r, p);
    if (!path.empty()) t.*r.values = parameter_raster(path, t, p, r.key, r.lo, r.hi);
  }
  if (!p.rain.grids.empty())
    load_band_series(p.rain.grids, "rain.grids", p.rain.grid_times, "rain.grid_times",
                     p.rain.grid_start, 0.0, 0.0, HUGE_VAL, t, p, t.rain_grids, t.rain_grid_times);
  // degrees C (from kelvin where the band's units say so): [-100, 100] holds every air
  // temperature measured, and no temperature in kelvin
  if (p.snow.enabled && !p.snow.temperature_grids.empty()) {
    const std::string& path = p.snow.temperature_grids;
    load_band_series(path, "snow.temperature_grids", p.snow.temperature_grid_times,
                     "snow.temperature_grid_times", p.snow.temperature_grid_start,
                     celsius_offset(path, "snow.temperature_grids"), -100.0, 100.0, t, p,
                     t.temperature_grids, t.temperature_grid_times);
  }
  // a global grid holding both -180 and +180: the column 360 degrees east of the first is the
  // first again, and the periodic edges join the grid without it
  if (repeats_first_column(t.grid)) {
    const Grid& g = t.grid;
    const double first = g.cell_center(0, 0)[0], last = g.cell_center(g.nx - 1, 0)[0];
    drop_last_column(t);
    t.notes.push_back(fmt::format(
        "{}: its last column (longitude {:.6g}) repeats the first (longitude {:.6g}, 360 "
        "degrees west of it): dropped, {} columns remain",
        t.source, last, first, t.grid.nx));
  }
  const int factor = resample_factor(p.dem, t.grid);
  if (factor > 1) t = coarsen(t, factor);
  if (const int capped = apply_latitude_cap(t, p))
    t.notes.push_back(
        fmt::format("boundary.latitude_cap = {:.6g} degrees: the {} rows poleward of it are walls",
                    *p.boundary.latitude_cap, capped));
  apply_boundary_codes(t, p.boundary.raster);
  return t;
}

Simulation make_simulation(const Params& p, const std::string& backend) {
  Terrain t = load_terrain(p);
  auto be = make_backend(backend, t, p);
  return Simulation(std::move(t), p, std::move(be));
}

}  // namespace erodem::io
