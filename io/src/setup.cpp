#include "erodem/io/setup.hpp"

#include <cmath>

#include "erodem/backends.hpp"
#include "erodem/error.hpp"
#include "erodem/io/raster.hpp"
#include "erodem/terrain_synth.hpp"

namespace erodem::io {

namespace {

/// Reads a parameter raster and checks its active cells hold finite values in [lo, hi].
std::vector<double> parameter_raster(const std::string& path, const Terrain& t, const Params& p,
                                     const std::string& key, double lo, double hi) {
  auto v = read_raster_on_grid(path, t.grid, p.dem.window, key);
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (!t.active(i)) continue;
    if (!(std::isfinite(v[i]) && v[i] >= lo && v[i] <= hi))
      throw Error(ExitCode::data, path + ": '" + key + "' value " + std::to_string(v[i]) +
                                      " at cell " + std::to_string(i % t.grid.nx) + ", " +
                                      std::to_string(i / t.grid.nx) + " is outside [" +
                                      std::to_string(lo) + ", " + std::to_string(hi) + "]");
  }
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
  const double inf = HUGE_VAL;
  if (p.initial.water_depth.is_raster())
    t.water_depth =
        parameter_raster(p.initial.water_depth.path, t, p, "initial.water_depth", 0.0, inf);
  if (p.flow.manning_n.is_raster())
    t.manning_n = parameter_raster(p.flow.manning_n.path, t, p, "flow.manning_n", 0.0, 1.0);
  if (p.erosion.hardness.is_raster())
    t.hardness = parameter_raster(p.erosion.hardness.path, t, p, "erosion.hardness", 0.0, 1.0);
  if (p.erosion.soil_thickness.is_raster())
    t.soil_thickness =
        parameter_raster(p.erosion.soil_thickness.path, t, p, "erosion.soil_thickness", 0.0, inf);
  if (!p.rain.raster.empty())
    t.rain_factor = parameter_raster(p.rain.raster, t, p, "rain.raster", 0.0, inf);
  const int factor = resample_factor(p.dem, t.grid);
  return factor > 1 ? coarsen(t, factor) : t;
}

Simulation make_simulation(const Params& p, const std::string& backend) {
  Terrain t = load_terrain(p);
  auto be = make_backend(backend, t, p);
  return Simulation(std::move(t), p, std::move(be));
}

}  // namespace erodem::io
