// erodem — where the model's boundaries are: the conditions of the edges (boundary.north, ...)
// and, cell by cell, of boundary.raster's codes, and the level of the fixed-level cells
// (boundary.sea_level or the stage hydrograph boundary.stage). The one place that says which
// ghost or cell is closed, open or held at the level: the backends' initial state and the
// time step's coast cells ask it.
#pragma once

#include <cstddef>
#include <utility>

#include "erodem/grid.hpp"
#include "erodem/params.hpp"

namespace erodem {

/// boundary.raster's codes (Terrain::boundary_code).
enum BoundaryCode : int {
  kBoundaryAsEdge = 0,
  kBoundaryClosed = 1,
  kBoundaryOpen = 2,
  kBoundaryFixed = 3
};

/// A side of a cell: the ghost beyond an edge cell lies west, east, north (row -1) or south.
enum class Side { west, east, north, south };

/// Checks boundary.raster's codes on the active cells (whole numbers 0 to 3; open only on the
/// grid's edge cells: Error(data) naming `source`, the cell and the code) and takes the
/// interior cells coded closed or fixed_level out of the active domain (a wall, or a cell held
/// at the level on its own bed). No-op without codes.
void apply_boundary_codes(Terrain& t, const std::string& source);

/// The condition of the ghost beyond DEM cell (col, row) on `side`: periodic west and east
/// where the edges are joined (periodic_x), else the raster's code at the cell where it has one
/// (an edge cell), else the edge's (boundary.west, ...).
BoundaryKind ghost_condition(const Terrain& t, const Params& p, int col, int row, Side side);

/// Whether non-active DEM cell `i` is held at the level: coded fixed_level, or a nodata cell
/// with boundary.nodata = "sea" (and not coded closed).
bool held_at_level(const Terrain& t, const Params& p, std::size_t i);

/// Whether held cell `i` keeps its own bed (coded fixed_level) rather than a sea bed below its
/// neighbours (a nodata sea cell).
bool held_on_own_bed(const Terrain& t, std::size_t i);

// ---- periodic east-west edges and the polar rows (docs/model.md "Boundaries") ----------

/// Whether a lat/lon grid's columns span 360 degrees of longitude exactly (to a thousandth of
/// a column): a global grid whose east edge is its west edge.
bool spans_360(const Grid& g);
/// Whether a lat/lon grid's last column repeats its first (the columns span 360 degrees plus
/// one column: many global grids hold both -180 and +180).
bool repeats_first_column(const Grid& g);
/// Drops the last column of the terrain and of every raster it carries (the repeated column
/// of repeats_first_column); the transform and the per-row sizes stay.
void drop_last_column(Terrain& t);

/// Whether the east and west edges are joined: boundary.periodic_x where set, else on where
/// boundary.east and .west are both "periodic" or the grid spans 360 degrees (spans_360).
bool periodic_x(const Terrain& t, const Params& p);

/// boundary.latitude_cap: makes the rows of a lat/lon grid whose centre lies poleward of
/// +-cap walls (nodata, coded closed: never sea) and returns how many rows it took; 0 without
/// a cap. A cap on a projected grid, or one that leaves no row: Error(config) naming the key.
int apply_latitude_cap(Terrain& t, const Params& p);

/// The level of the fixed-level cells at time t (s): the stage hydrograph, or sea_level (m).
double boundary_level(const Params& p, double t);
/// The lowest and highest level the fixed-level cells take over the run (m).
std::pair<double, double> boundary_level_range(const Params& p);

}  // namespace erodem
