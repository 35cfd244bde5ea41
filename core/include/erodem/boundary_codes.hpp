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

/// The condition of the ghost beyond DEM cell (col, row) on `side`: the raster's code at the
/// cell where it has one (an edge cell), else the edge's (boundary.west, ...).
BoundaryKind ghost_condition(const Terrain& t, const Params& p, int col, int row, Side side);

/// Whether non-active DEM cell `i` is held at the level: coded fixed_level, or a nodata cell
/// with boundary.nodata = "sea" (and not coded closed).
bool held_at_level(const Terrain& t, const Params& p, std::size_t i);

/// Whether held cell `i` keeps its own bed (coded fixed_level) rather than a sea bed below its
/// neighbours (a nodata sea cell).
bool held_on_own_bed(const Terrain& t, std::size_t i);

/// The level of the fixed-level cells at time t (s): the stage hydrograph, or sea_level (m).
double boundary_level(const Params& p, double t);
/// The lowest and highest level the fixed-level cells take over the run (m).
std::pair<double, double> boundary_level_range(const Params& p);

}  // namespace erodem
