// erodem — the padded initial state every backend starts from, built once on the host.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "erodem/grid.hpp"
#include "erodem/params.hpp"

namespace erodem {

/// A cell parameter of the padded raster (Manning n, hardness, the rain factor): a raster with
/// its halo, or, where the run gives none, one value everywhere (`cells` empty), which the
/// backends may hold as a constant instead of an array (docs/architecture.md "Uniform
/// parameters").
struct CellParameter {
  std::vector<double> cells;  ///< a value per padded cell, or empty: `uniform` everywhere
  double uniform = 0.0;
  bool is_uniform() const { return cells.empty(); }
};

/// The padded raster (W = nx + 2 by H = ny + 2, one ghost cell around the DEM; see
/// kernels/common/compat.h) of a run's initial state, in double. Backends round it to their
/// precision once, so every backend starts from the same numbers.
struct PaddedState {
  int nx = 0, ny = 0, W = 0, H = 0;
  std::vector<std::uint8_t> kind;    ///< ERODEM_CELL_* of every padded cell
  std::vector<double> dx, dy, area;  ///< per padded row (m, m, m^2); halo rows repeat
  std::vector<double> bed, depth;    ///< m; ghosts as the boundary kinds set them
  /// m of solid: 0, but sea nodata cells hold boundary.sediment_concentration of their depth
  std::vector<double> sediment;
  CellParameter manning, hardness, rain_factor;  ///< rasters or the scalar parameters
  /// boundary.periodic_x (boundary_codes.hpp periodic_x): the west ghost column holds the
  /// last DEM column and the east ghost column the first, kinds and every field, so the faces
  /// across the seam are computed as inside the grid (the backends keep the copies up to date,
  /// Backend halo exchange: process.hpp halo_fields).
  bool periodic_x = false;
  std::size_t at(int x, int y) const {
    return static_cast<std::size_t>(x) + static_cast<std::size_t>(y) * static_cast<std::size_t>(W);
  }
  std::size_t size() const { return static_cast<std::size_t>(W) * static_cast<std::size_t>(H); }
};

/// Cell kinds from the mask and the boundary parameters (halo by each edge's kind, nodata as
/// wall or sea), bed and initial water (computed in double: initial.water_level - bed, a
/// raster, or a uniform depth), sea ghosts over the lowest active neighbour, and the
/// parameter rasters with their halo. Throws erodem::Error(data) on rasters of the wrong size.
/// The padded rows [y0, y1) only (y1 < 0: to the last, H = ny + 2), H = y1 - y0 rows: a band
/// of the MPI decomposition with its halo rows, the same values as those rows of the whole
/// state, built without it (a rank holds its band's initial state, not the grid's).
PaddedState build_padded_state(const Terrain& terrain, const Params& params, int y0 = 0,
                               int y1 = -1);

/// The periodic halo of a padded field of W x H: ghost column 0 takes column W - 2, ghost
/// column W - 1 takes column 1, on every row (the corners too).
template <class T>
void copy_periodic_columns(T* f, int W, int H) {
  for (int y = 0; y < H; ++y) {
    T* row = f + static_cast<std::size_t>(y) * static_cast<std::size_t>(W);
    row[0] = row[W - 2];
    row[W - 1] = row[1];
  }
}

}  // namespace erodem
