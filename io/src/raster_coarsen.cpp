// erodem — resampling a DEM (raster.hpp): the factor dem.resample asks for, and block
// averages of the bed and the parameter rasters onto the coarser grid.
#include <ogr_srs_api.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "erodem/error.hpp"
#include "erodem/io/raster.hpp"
#include "erodem/parameter_rasters.hpp"
#include "raster_gdal.hpp"

namespace erodem::io {

int resample_factor(const Params::Dem& dem, const Grid& grid) {
  if (dem.resample_factor > 0) return dem.resample_factor;
  if (!(dem.resample > 0.0)) return 1;
  if (grid.georef.is_geographic)
    throw config_error("dem.resample",
                       "a cell size in metres cannot coarsen the geographic (lat/lon) grid of " +
                           dem.path +
                           ", whose east-west cell size varies by row; give an "
                           "integer factor (dem.resample = 4)");
  const double cell = grid.dx.empty() ? 0.0 : grid.dx[0];
  const double f = dem.resample / cell;
  const long n = std::lround(f);
  if (n < 1 || std::fabs(f - static_cast<double>(n)) > 1e-6 * f)
    throw config_error("dem.resample",
                       std::to_string(dem.resample) + " m is not a whole multiple of the " +
                           std::to_string(cell) + " m cell of " + dem.path + "; the nearest is " +
                           std::to_string(std::max(1L, n) * cell) +
                           " m (or give an integer factor)");
  return static_cast<int>(n);
}

Terrain coarsen(const Terrain& fine, int factor) {
  const Grid& g = fine.grid;
  if (factor < 1) throw config_error("dem.resample", "the factor must be at least 1");
  const int nx = g.nx / factor, ny = g.ny / factor;
  if (nx < 1 || ny < 1)
    throw config_error("dem.resample", "a factor of " + std::to_string(factor) +
                                           " leaves no cell of the " + std::to_string(g.nx) +
                                           " x " + std::to_string(g.ny) + " grid");
  Terrain t;
  // a band's rows (an MPI rank's: Terrain::banded): those coarse rows whose blocks it holds,
  // and it owns those of its own blocks (load_terrain reads whole blocks)
  if (fine.banded) {
    t.banded = true;
    t.row0 = fine.row0 / factor;
    t.row1 = std::min(ny, fine.end_row() / factor);
    t.own0 = fine.own0 / factor;
    t.own1 = std::min(ny, fine.own1 / factor);
  }
  const int r0 = t.row0, r1 = t.banded ? t.row1 : ny;
  t.source =
      fine.source + " (averaged " + std::to_string(factor) + "x" + std::to_string(factor) + ")";
  t.source_sha256 = fine.source_sha256;
  t.notes = fine.notes;
  Grid& c = t.grid;
  c.nx = nx;
  c.ny = ny;
  c.georef = g.georef;
  for (int k : {1, 2, 4, 5}) c.georef.transform[k] *= factor;
  for (int r = 0; r < ny; ++r) {
    double dx = 0, dy = 0, area = 0;
    for (int k = 0; k < factor; ++k) {
      dx += g.dx[r * factor + k] / factor;
      dy += g.dy[r * factor + k];
      area += g.area[r * factor + k] * factor;
    }
    c.dx.push_back(dx * factor);
    c.dy.push_back(dy);
    c.area.push_back(area);
  }
  if (c.georef.is_geographic) {
    // Exact sizes of the coarse cells, from the ellipsoid of the grid's CRS.
    Srs srs = parse_srs(c.georef.crs_wkt);
    if (!srs) throw Error(ExitCode::internal, t.source + ": geographic grid without a usable CRS");
    set_geographic_grid(c, static_cast<OGRSpatialReferenceH>(srs.get()), c.georef.transform,
                        t.source);
  }
  // Block averages over the valid cells; a block with none stays nodata. One helper serves
  // the bed and every parameter raster, so they average over the same cells.
  auto block_mean = [&](const std::vector<double>& v, int r, int col, double& mean) {
    double sum = 0;
    int n = 0;
    for (int i = 0; i < factor; ++i)
      for (int j = 0; j < factor; ++j) {
        const auto k = static_cast<std::size_t>(r * factor + i) * g.nx + (col * factor + j);
        if (!fine.active(k)) continue;
        sum += v[fine.held(k)];
        ++n;
      }
    mean = n > 0 ? sum / n : 0.0;
    return n > 0;
  };
  t.bed.assign(t.held_cells(), std::nan(""));
  std::vector<std::uint8_t> mask(t.held_cells(), 0);
  bool any_masked = false;
  for (int r = r0; r < r1; ++r)
    for (int col = 0; col < nx; ++col) {
      const auto o = static_cast<std::size_t>(r - r0) * nx + col;
      double mean = 0;
      if (block_mean(fine.bed, r, col, mean)) {
        t.bed[o] = mean;
        mask[o] = 1;
      } else {
        any_masked = true;
      }
    }
  if (any_masked) t.mask = std::move(mask);  // of the rows it holds (a band's on a banded one)
  // Parameter rasters on the fine grid (0 where a block has no valid cell).
  auto average = [&](const std::vector<double>& v) {
    std::vector<double> out;
    if (v.empty()) return out;
    out.assign(t.held_cells(), 0.0);
    for (int r = r0; r < r1; ++r)
      for (int col = 0; col < nx; ++col)
        block_mean(v, r, col, out[static_cast<std::size_t>(r - r0) * nx + col]);
    return out;
  };
  // Codes (boundary.raster) are not averaged: a block takes its most frequent code over its
  // valid cells, the larger on a tie (so a block half held at the level is held).
  auto mode = [&](const std::vector<double>& v) {
    std::vector<double> out;
    if (v.empty()) return out;
    out.assign(t.held_cells(), 0.0);
    for (int r = r0; r < r1; ++r)
      for (int col = 0; col < nx; ++col) {
        int count[4] = {0, 0, 0, 0};
        for (int i = 0; i < factor; ++i)
          for (int j = 0; j < factor; ++j) {
            const auto k = static_cast<std::size_t>(r * factor + i) * g.nx + (col * factor + j);
            if (fine.active(k)) ++count[std::clamp(static_cast<int>(v[fine.held(k)]), 0, 3)];
          }
        int best = 0;
        for (int code = 1; code < 4; ++code)
          if (count[code] >= count[best]) best = code;
        out[static_cast<std::size_t>(r - r0) * nx + col] = count[best] > 0 ? best : 0;
      }
    return out;
  };
  for (const auto& r : parameter_rasters())
    t.*r.values = r.categorical ? mode(fine.*r.values) : average(fine.*r.values);
  for (const auto& band : fine.rain_grids) t.rain_grids.push_back(average(band));
  for (const auto& band : fine.temperature_grids) t.temperature_grids.push_back(average(band));
  t.rain_grid_times = fine.rain_grid_times;
  t.temperature_grid_times = fine.temperature_grid_times;
  return t;
}

}  // namespace erodem::io
