// erodem — the raster grid: sizes, per-row cell sizes and areas, georeferencing.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace erodem {

/// Georeferencing carried with the data (never a silent default: `has_transform`
/// says whether the source file had one).
struct Georef {
  /// GDAL geotransform: x0, pixel width, row rotation, y0, column rotation, pixel height
  /// (negative for north-up). Coordinates are of the top-left corner of cell (0, 0).
  std::array<double, 6> transform{0.0, 1.0, 0.0, 0.0, 0.0, -1.0};
  std::string crs_wkt;         ///< WKT of the CRS, empty when unknown
  bool has_transform = false;  ///< the source carried a geotransform
  bool is_geographic = false;  ///< lat/lon degrees (cell sizes from the ellipsoid)
};

/// A regular raster of `nx` columns by `ny` rows, row-major, row 0 at the north edge.
/// Cell sizes are in metres and may vary by row (geographic grids).
struct Grid {
  int nx = 0;
  int ny = 0;
  std::vector<double> dx;    ///< east-west cell size of each row (m)
  std::vector<double> dy;    ///< north-south cell size of each row (m)
  std::vector<double> area;  ///< cell area of each row (m^2)
  Georef georef;

  /// A projected grid of square cells of `cell` metres, origin at (0, ny*cell).
  static Grid uniform(int nx, int ny, double cell);

  std::size_t cells() const { return static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny); }
  double dx_min() const;  ///< smallest cell size in either direction (m)
  /// Centre of cell (col, row) in the grid's CRS.
  std::array<double, 2> cell_center(int col, int row) const;
  /// The cell containing CRS point (x, y); false when it is outside the grid.
  bool locate(double x, double y, int& col, int& row) const;
  /// Throws erodem::Error when sizes are inconsistent or non-positive.
  void validate() const;
};

/// Host-side inputs of a run, on one grid, all in SI units, row-major (ny, nx).
/// Optional rasters are empty when the scalar parameter applies.
struct Terrain {
  Grid grid;
  std::vector<double> bed;               ///< bed elevation (m)
  std::vector<std::uint8_t> mask;        ///< 1 = active cell, 0 = nodata; empty = all active
  std::vector<double> water_depth;       ///< initial depth (m)
  std::vector<double> manning_n;         ///< Manning n (s m^-1/3)
  std::vector<double> hardness;          ///< erodibility R in [0, 1]; empty: scalar or "noise"
  std::vector<double> rain_factor;       ///< rain multiplier (1)
  std::vector<double> soil_thickness;    ///< loose layer over the bedrock (m): erosion's initial
                                         ///< soil_thickness field (process_table.cpp)
  std::vector<double> ksat;              ///< infiltration K_sat (m/s)
  std::vector<double> suction;           ///< infiltration suction head psi (m)
  std::vector<double> moisture_deficit;  ///< infiltration delta theta (1)
  std::vector<double> soil_depth;        ///< infiltration soil depth L (m)
  std::vector<double> boundary_code;     ///< boundary.raster's codes (boundary_codes.hpp)
  /// rain.grids' bands, each a rate in the bands' units (times rain.grid_scale: m/s)
  std::vector<std::vector<double>> rain_grids;
  /// rain.grids' band times (s) from rain.grid_times or the file's time coordinate; empty =
  /// rain.grid_start + k rain.grid_interval
  std::vector<double> rain_grid_times;
  /// snow.temperature_grids' bands (degrees C) and their times (s), as rain.grids'
  std::vector<std::vector<double>> temperature_grids;
  std::vector<double> temperature_grid_times;
  std::vector<double> snow_initial;  ///< the initial snow water equivalent S_0 (m)
  std::string source;                ///< DEM path or generator description
  std::string source_sha256;         ///< checksum of the DEM file, when read from one
  /// What reading it changed, for the log (the repeated column of a global grid dropped, the
  /// rows of boundary.latitude_cap): one line each.
  std::vector<std::string> notes;

  /// The grid rows [row0, row1) the per-cell arrays hold (the bed, the mask, the parameter
  /// rasters, the initial fields): every row, but on a rank of an MPI
  /// run that read only its band's rows (`banded`, io::load_terrain, docs/mpi.md). row1 < 0:
  /// grid.ny.
  int row0 = 0;
  int row1 = -1;
  /// Whether this process read only its band's rows (every rank of the run alike), and the
  /// rows [own0, own1) it owns then (inside [row0, row1); the ranks' own rows cover the grid
  /// once, in rank order: terrain_rows.hpp own_rows).
  bool banded = false;
  int own0 = 0, own1 = 0;

  /// Whether grid cell `i` (global, row-major) is active: of a row the terrain holds (a banded
  /// terrain's mask holds its rows alone; the whole grid's answers come from terrain_rows.hpp,
  /// collectively). Throws ExitCode::internal for a row a banded terrain does not hold.
  bool active(std::size_t i) const {
    if (banded && held(i) >= held_cells()) not_held(i);
    return mask.empty() || mask[held(i)] != 0;
  }
  /// The last row (exclusive) the per-cell arrays hold.
  int end_row() const { return row1 < 0 ? grid.ny : row1; }
  /// Whether the per-cell arrays hold grid row `r`.
  bool holds_row(int r) const { return r >= row0 && r < end_row(); }
  /// The index in the per-cell arrays of grid cell `i` (global, row-major), of a row they hold.
  std::size_t held(std::size_t i) const {
    return i - static_cast<std::size_t>(row0) * static_cast<std::size_t>(grid.nx);
  }
  /// The cells the per-cell arrays hold (their size where given).
  std::size_t held_cells() const {
    return static_cast<std::size_t>(end_row() - row0) * static_cast<std::size_t>(grid.nx);
  }

  /// Throws the internal error of active() asked about a row this terrain does not hold.
  [[noreturn]] void not_held(std::size_t i) const;

  /// Frees the per-cell inputs (the bed, the parameter rasters, the rain and temperature
  /// bands, the initial snow) once a backend holds them: the grid, the mask, the band times,
  /// the source and the notes stay. Simulation calls it at the end of its constructor (8 B
  /// per cell of the bed in double, and 8 B per cell of each raster and band).
  void release_cell_inputs() {
    for (auto* v : {&bed, &water_depth, &manning_n, &hardness, &rain_factor, &soil_thickness, &ksat,
                    &suction, &moisture_deficit, &soil_depth, &boundary_code, &snow_initial})
      std::vector<double>().swap(*v);
    std::vector<std::vector<double>>().swap(rain_grids);
    std::vector<std::vector<double>>().swap(temperature_grids);
  }
};

}  // namespace erodem
