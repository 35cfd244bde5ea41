// erodem viewer — the terrain-class view: snow, rock, mud or grass per cell.
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include "erodem/grid.hpp"

namespace erodem::viz {

/// Terrain classes, stored as float codes 0..3 in the `terrain_class` view field.
enum class TerrainClass { grass = 0, mud = 1, rock = 2, snow = 3 };

/// The class names, by code ("grass", "mud", "rock", "snow").
const std::vector<std::string>& terrain_class_names();

/// Thresholds of the classification. Rules, first match wins:
/// 1. snow: bed above `snow_line` (m) when it is set (finite), else above
///    `min + snow_fraction * (max - min)` of the grid's bed range;
/// 2. rock: slope steeper than `rock_slope`;
/// 3. mud: wet, i.e. wetness (or, when there is none, water depth) above `mud_depth`;
/// 4. grass: everything else.
struct ClassRule {
  double snow_fraction = 0.75;  ///< snow line as a fraction of the bed range (1)
  double snow_line = NAN;       ///< absolute snow line (m); NaN = use snow_fraction
  double rock_slope = 0.7;      ///< steepest slope of grass or mud (m/m; 0.7 is 35 degrees)
  double mud_depth = 0.01;      ///< wetness or water depth that makes a cell mud (m)
};

/// The class of every cell (row-major, NaN where the bed is NaN). `bed` in metres on
/// `grid` (whose per-row dx, dy in metres give the slopes, by central differences, one-
/// sided at edges and beside nodata); `wet` is the wetness or water depth (m) on the same
/// grid, or empty for a dry terrain (a DEM).
std::vector<float> classify_terrain(const Grid& grid, const std::vector<float>& bed,
                                    const std::vector<float>& wet, const ClassRule& rule = {});

/// Slope magnitude (m/m) of cell (col, row) by central differences; NaN when the cell is.
double cell_slope(const Grid& grid, const std::vector<float>& bed, int col, int row);

}  // namespace erodem::viz
