#include "erodem/io/setup.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "erodem/backends.hpp"
#include "erodem/boundary_codes.hpp"
#include "erodem/error.hpp"
#include "erodem/io/raster.hpp"
#include "erodem/parallel.hpp"
#include "erodem/parameter_rasters.hpp"
#include "erodem/terrain_rows.hpp"
#include "erodem/terrain_synth.hpp"
#include "raster_gdal.hpp"

namespace erodem::io {

namespace {

/// Rows of DEM around a band's own that a rank reads beside them: the halo (2 rows), the row
/// beside it that the padded state's fixed-level cells read (initial_state.cpp), and the row
/// beyond that which the bed's slope reads (the initial snow, process_table.cpp).
constexpr int kBandMargin = 4;

/// Checks that the active cells of `v`, read from `path` for `key` (`what`: "value", or
/// "band k value"), hold finite values in [lo, hi]; Error(data) naming the first that does not.
void check_raster_values(const std::vector<double>& v, const Terrain& t, const std::string& path,
                         const std::string& key, const std::string& what, double lo, double hi) {
  const BadCell bad = first_bad_cell(
      t, [&](std::size_t i) { return v[t.held(i)]; },
      [&](std::size_t, double x) { return std::isfinite(x) && x >= lo && x <= hi; });
  if (bad.cell >= 0) {
    const auto i = static_cast<std::size_t>(bad.cell);
    throw Error(ExitCode::data, path + ": '" + key + "' " + what + " " + std::to_string(bad.value) +
                                    " at cell " + std::to_string(i % t.grid.nx) + ", " +
                                    std::to_string(i / t.grid.nx) + " is outside [" +
                                    std::to_string(lo) + ", " + std::to_string(hi) + "]");
  }
}

/// The rows of a raster on the terrain's grid to read: those the terrain holds.
std::array<int, 2> held_rows(const Terrain& t) {
  return t.banded ? std::array<int, 2>{t.row0, t.end_row()} : std::array<int, 2>{0, -1};
}

/// Reads a parameter raster and checks its active cells hold finite values in [lo, hi].
std::vector<double> parameter_raster(const std::string& path, const Terrain& t, const Params& p,
                                     const std::string& key, double lo, double hi) {
  auto v = read_raster_on_grid(path, t.grid, p.dem.window, key, held_rows(t));
  check_raster_values(v, t, path, key, "value", lo, hi);
  return v;
}

/// Whether each rank of this run reads or makes only its band's rows of the terrain (the DEM
/// or a synthetic terrain, every parameter raster, boundary.raster's codes, the gridded rain
/// and air temperature: docs/mpi.md): under MPI with more than one rank.
bool reads_band() {
  return parallel::size() > 1;
}

/// The rows of a grid of `ny` rows this rank reads or makes: its own and kBandMargin more each
/// way, of the rows coarsened by `factor` (dem.resample) when it is above 1, as rows of the
/// grid read (factor of them a coarse row; the last rank's also the rows beyond the last
/// whole block, which coarsening drops but reading checks).
struct BandRead {
  parallel::Band held, own;
};
BandRead band_read(int ny, int factor) {
  const int coarse = ny / factor;
  const parallel::Band own = parallel::band(coarse, parallel::rank(), parallel::size());
  const int h0 = std::max(0, own.row0 - kBandMargin), h1 = std::min(coarse, own.row1 + kBandMargin);
  const auto fine = [&](int row) { return row == coarse ? ny : row * factor; };
  return {{fine(h0), fine(h1)}, {fine(own.row0), fine(own.row1)}};
}

/// The note a rank's terrain of its rows leaves in the log (the same on every rank but its
/// rows).
std::string band_note(const Terrain& t, int ny, const char* what) {
  return fmt::format(
      "{}: each of the {} ranks {} its own rows and {} beside them, and those of the parameter "
      "rasters and gridded forcing (rank {}: rows {} to {} of {})",
      t.source, parallel::size(), what, kBandMargin, parallel::rank(), t.row0, t.end_row() - 1, ny);
}

/// The synthetic terrain of `dem` made by this rank (`band`'s rows), scaled by the ranges of
/// the whole grid (the ranks' own rows' ranges combined).
Terrain make_synthetic_band(const Params::Dem& dem, const BandRead& band) {
  SynthRows rows;
  rows.row0 = band.held.row0;
  rows.row1 = band.held.row1;
  rows.own0 = band.own.row0;
  rows.own1 = band.own.row1;
  rows.reduce = [](double& lo, double& hi) {
    lo = -parallel::max_over_ranks(-lo);
    hi = parallel::max_over_ranks(hi);
  };
  Terrain t = make_synthetic_terrain(dem, rows);
  t.banded = true;
  t.own0 = band.own.row0;
  t.own1 = band.own.row1;
  t.notes.push_back(band_note(t, dem.size, "made"));
  return t;
}

/// The DEM of `dem` (read at full resolution: `full`) read by this rank (`band`'s rows), its
/// mask of those rows, and the file's checksum rank 0's.
Terrain read_dem_band(const Params::Dem& dem, const Params::Dem& full, const BandRead& band) {
  Terrain t = read_dem(full, {band.held.row0, band.held.row1});
  t.banded = true;
  t.own0 = band.own.row0;
  t.own1 = band.own.row1;
  t.mask = rows_mask(std::move(t.mask));
  if (!any_active(t))  // read_dem's message for a whole grid of nodata
    throw Error(ExitCode::data, dem.path + ": no valid (non-nodata) cells" +
                                    (dem.window ? " in window " + window_text(*dem.window) : ""));
  t.source_sha256 = parallel::root_string(parallel::rank() == 0 ? file_sha256(dem.path) : "");
  t.notes.push_back(band_note(t, t.grid.ny, "read"));
  return t;
}

/// The terrain of `dem` (at full resolution: `full`) this rank reads or makes: its band's rows
/// (band_read, of the rows dem.resample coarsens the grid to), or the whole grid where the rows
/// cannot be chosen before reading: a resample factor that is an error, or that leaves no
/// row (one process meets that error after checking the data, and so does every rank).
Terrain terrain_band(const Params::Dem& dem, const Params::Dem& full) {
  const bool synthetic = !dem.synthetic.empty();
  // the grid (of a DEM: its window's, from reading its first row), as one process would have it
  const Grid grid = synthetic ? Grid::uniform(std::max(1, dem.size), std::max(1, dem.size),
                                              dem.cell_size > 0.0 ? dem.cell_size : 10.0)
                              : read_dem(full, {0, 1}).grid;
  const int ny = synthetic ? dem.size : grid.ny;
  int factor = 1;
  try {
    factor = resample_factor(dem, grid);
  } catch (const Error&) {
    factor = 0;
  }
  if (factor < 1 || ny / factor < 1)
    return synthetic ? make_synthetic_terrain(full) : read_dem(full);
  const BandRead band = band_read(ny, factor);
  return synthetic ? make_synthetic_band(full, band) : read_dem_band(dem, full, band);
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
  bands = read_raster_bands_on_grid(path, t.grid, p.dem.window, key, true, held_rows(t));
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

Terrain load_terrain(const Params& p, bool by_rows) {
  // Read at full resolution, with the parameter rasters, then average everything together.
  Params::Dem full = p.dem;
  full.resample = 0.0;
  full.resample_factor = 0;
  Terrain t = by_rows && reads_band()  ? terrain_band(p.dem, full)
              : full.synthetic.empty() ? read_dem(full)
                                       : make_synthetic_terrain(full);
  if (!any_active(t))
    throw Error(ExitCode::data, t.source + ": every cell is nodata; nothing to simulate");
  // a broken value (a float fill of -3.4e38, a wrong z_scale) stops here, naming the cell,
  // not as a NaN after the first step
  const BadCell high = first_bad_cell(
      t, [&](std::size_t i) { return t.bed[t.held(i)]; },
      [&](std::size_t, double z) { return std::abs(z) <= p.dem.elevation_limit; });
  if (high.cell >= 0)
    throw Error(ExitCode::data,
                fmt::format("{}: cell (col {}, row {}) has elevation {:.6g} m, beyond "
                            "dem.elevation_limit = {:.6g} m (check dem.z_scale, its nodata "
                            "value, or raise the limit)",
                            t.source, high.cell % t.grid.nx, high.cell / t.grid.nx, high.value,
                            p.dem.elevation_limit));
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
  Terrain t = load_terrain(p, true);
  auto be = make_backend(backend, t, p);
  return Simulation(std::move(t), p, std::move(be));
}

}  // namespace erodem::io
