// erodem viewer — the terrain-class view: snow, water, rock, mud or grass per cell. A run
// that stored its terrain_class field (terrain_classes.enabled) is shown as it was computed;
// a DEM or a run without it is classified here by the model's rule (kernels/common/
// terrain_class.h, docs/model.md section 3.12), with a snow line from the bed's range.
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include "erodem/grid.hpp"

namespace erodem::viz {

/// Terrain classes, stored as float codes 0..4 in the `terrain_class` field (the model's
/// ERODEM_CLASS_* codes).
enum class TerrainClass { grass = 0, mud = 1, rock = 2, snow = 3, water = 4 };

/// The class names, by code ("grass", "mud", "rock", "snow", "water").
const std::vector<std::string>& terrain_class_names();

/// Thresholds of the classification: the model's rule (terrain_class_of, first match wins)
/// with its default thresholds, and a snow line from the bed's range where none is given:
/// 1. snow: a pack (when the file has one) above `snow_depth`, or the bed above `snow_line`
///    (m) when it is set (finite), else above `min + snow_fraction * (max - min)` of the
///    grid's bed range;
/// 2. water: wet above `water_depth`; 3. rock: slope steeper than `rock_slope`;
/// 4. mud: wet above `mud_depth` (wet: the wetness, or the water depth where there is none);
/// 5. grass: everything else.
struct ClassRule {
  double snow_fraction = 0.75;  ///< snow line as a fraction of the bed range (1)
  double snow_line = NAN;       ///< absolute snow line (m); NaN = use snow_fraction
  double snow_depth = 0.01;     ///< snow water equivalent that makes a cell snow (m)
  double water_depth = 0.3;     ///< wetness or water depth that makes a cell water (m)
  double rock_slope = 0.7;      ///< steepest slope of grass or mud (m/m; 0.7 is 35 degrees)
  double mud_depth = 0.01;      ///< wetness or water depth that makes a cell mud (m)
};

/// The class of every cell (row-major, NaN where the bed is NaN). `bed` in metres on
/// `grid` (whose per-row dx, dy in metres give the slopes, by central differences, one-
/// sided at edges and beside nodata); `wet` is the wetness or water depth (m) on the same
/// grid, or empty for a dry terrain (a DEM); `snow` the snow water equivalent (m), or empty.
std::vector<float> classify_terrain(const Grid& grid, const std::vector<float>& bed,
                                    const std::vector<float>& wet, const ClassRule& rule = {},
                                    const std::vector<float>& snow = {});

/// Slope magnitude (m/m) of cell (col, row): the model's bed_slope_cell, central differences
/// over the finite neighbours, one-sided beside an edge or nodata; NaN when the cell is.
double cell_slope(const Grid& grid, const std::vector<float>& bed, int col, int row);

}  // namespace erodem::viz
