// erodem viewer — terrain classes (terrain_class.hpp): the model's rule and slope
// (kernels/common/terrain_class.h), on the float fields of a DEM or a result file.
#include "erodem/viz/terrain_class.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "common/terrain_class.h"

namespace erodem::viz {

const std::vector<std::string>& terrain_class_names() {
  static const std::vector<std::string> names{"grass", "mud", "rock", "snow", "water"};
  return names;
}

double cell_slope(const Grid& grid, const std::vector<float>& bed, int col, int row) {
  const std::size_t nx = static_cast<std::size_t>(grid.nx);
  const auto at = [&](int c, int r) -> double {
    return c >= 0 && c < grid.nx && r >= 0 && r < grid.ny
               ? bed[static_cast<std::size_t>(r) * nx + c]
               : NAN;
  };
  const double z = at(col, row);
  if (!std::isfinite(z)) return NAN;
  const double l = at(col - 1, row), r = at(col + 1, row), t = at(col, row - 1),
               b = at(col, row + 1);
  const auto dy_between = [&](int r0, int r1) {
    return 0.5 * (grid.dy[static_cast<std::size_t>(r0)] + grid.dy[static_cast<std::size_t>(r1)]);
  };
  const bool has_t = std::isfinite(t), has_b = std::isfinite(b);
  return cell::bed_slope_cell<double>(z, l, r, t, b, std::isfinite(l), std::isfinite(r), has_t,
                                      has_b, grid.dx[static_cast<std::size_t>(row)],
                                      has_t ? dy_between(row - 1, row) : 0.0,
                                      has_b ? dy_between(row, row + 1) : 0.0);
}

std::vector<float> classify_terrain(const Grid& grid, const std::vector<float>& bed,
                                    const std::vector<float>& wet, const ClassRule& rule,
                                    const std::vector<float>& snow) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (float z : bed)
    if (std::isfinite(z)) {
      lo = std::min(lo, static_cast<double>(z));
      hi = std::max(hi, static_cast<double>(z));
    }
  cell_params::TerrainClassParams<double> p{};
  p.snow_depth = rule.snow_depth;
  // a snow line from the bed's range only where the range is not empty
  p.snow_line = std::isfinite(rule.snow_line) ? rule.snow_line
                : hi > lo                     ? lo + rule.snow_fraction * (hi - lo)
                                              : std::numeric_limits<double>::max();
  p.water_wetness = rule.water_depth;
  p.rock_slope = rule.rock_slope;
  p.rock_elevation = std::numeric_limits<double>::lowest();
  p.mud_wetness = rule.mud_depth;
  std::vector<float> out(bed.size(), NAN);
  for (int r = 0; r < grid.ny; ++r)
    for (int c = 0; c < grid.nx; ++c) {
      const std::size_t i = static_cast<std::size_t>(r) * grid.nx + c;
      if (!std::isfinite(bed[i])) continue;
      const double w = wet.empty() ? 0.0 : wet[i], s = snow.empty() ? 0.0 : snow[i];
      out[i] = static_cast<float>(
          cell::terrain_class_of<double>(bed[i], cell_slope(grid, bed, c, r), w, s, p));
    }
  return out;
}

}  // namespace erodem::viz
