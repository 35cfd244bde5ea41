#include "erodem/io/setup.hpp"

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
  for (const auto& r : parameter_rasters()) {
    const std::string path = parameter_raster_path(r, p);
    if (!path.empty()) t.*r.values = parameter_raster(path, t, p, r.key, r.lo, r.hi);
  }
  if (!p.rain.grids.empty()) {
    t.rain_grids = read_raster_bands_on_grid(p.rain.grids, t.grid, p.dem.window, "rain.grids");
    for (std::size_t b = 0; b < t.rain_grids.size(); ++b)
      check_raster_values(t.rain_grids[b], t, p.rain.grids, "rain.grids",
                          "band " + std::to_string(b + 1) + " value", 0.0, HUGE_VAL);
  }
  const int factor = resample_factor(p.dem, t.grid);
  if (factor > 1) t = coarsen(t, factor);
  apply_boundary_codes(t, p.boundary.raster);
  return t;
}

Simulation make_simulation(const Params& p, const std::string& backend) {
  Terrain t = load_terrain(p);
  auto be = make_backend(backend, t, p);
  return Simulation(std::move(t), p, std::move(be));
}

}  // namespace erodem::io
