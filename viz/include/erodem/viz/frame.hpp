// erodem viewer — the world frame: where a grid's CRS coordinates are drawn.
#pragma once

#include <array>

#include "erodem/grid.hpp"

namespace erodem::viz {

/// Maps CRS coordinates (x, y) of a grid to the viewer's world coordinates in metres and
/// back. The world origin is the grid's centre, so that large CRS coordinates (UTM
/// northings of millions of metres) keep their precision in the renderer's float32.
///
/// Scale: one CRS unit is `sx` metres east-west and `sy` metres north-south, taken from the
/// grid's own cell sizes at the centre row (`dx / |pixel width|`, `dy / |pixel height|`).
/// So a projected CRS in metres draws 1:1, one in feet is converted to metres, and a
/// geographic (lat/lon) grid is drawn in a local equirectangular projection about its
/// centre (metres per degree of longitude and latitude at the centre row, from the
/// geodesic cell sizes). Elevations are metres in every case, so the vertical
/// exaggeration means the same for projected and geographic grids.
struct WorldFrame {
  double x0 = 0.0, y0 = 0.0;  ///< CRS coordinates of the world origin (CRS units)
  double sx = 1.0, sy = 1.0;  ///< metres per CRS unit, east-west and north-south (m)

  /// The frame of `grid`: origin at its centre, scales from its centre row.
  static WorldFrame for_grid(const Grid& grid);
  /// World (m) of CRS point (x, y).
  std::array<double, 2> to_world(double x, double y) const {
    return {(x - x0) * sx, (y - y0) * sy};
  }
  /// CRS point of world point (wx, wy) (m).
  std::array<double, 2> to_crs(double wx, double wy) const { return {wx / sx + x0, wy / sy + y0}; }
};

/// CRS coordinates of a fractional cell position: (col, row) = (0, 0) is the centre of the
/// first cell, (0.5, 0) its east edge. The grid's geotransform is used as it is.
std::array<double, 2> cell_point(const Grid& grid, double col, double row);

}  // namespace erodem::viz
