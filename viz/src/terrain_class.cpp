// erodem viewer — terrain classes (terrain_class.hpp).
#include "erodem/viz/terrain_class.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace erodem::viz {

const std::vector<std::string>& terrain_class_names() {
  static const std::vector<std::string> names{"grass", "mud", "rock", "snow"};
  return names;
}

namespace {

/// Derivative of the bed along one axis at cell index `k` of `n` (m per cell), central
/// where both neighbours are valid, one-sided beside an edge or nodata, 0 when alone.
template <class Get>
double difference(Get get, int k, int n) {
  const double c = get(k);
  const double lo = k > 0 ? get(k - 1) : NAN, hi = k + 1 < n ? get(k + 1) : NAN;
  if (std::isfinite(lo) && std::isfinite(hi)) return 0.5 * (hi - lo);
  if (std::isfinite(hi)) return hi - c;
  if (std::isfinite(lo)) return c - lo;
  return 0.0;
}

}  // namespace

double cell_slope(const Grid& grid, const std::vector<float>& bed, int col, int row) {
  const std::size_t nx = static_cast<std::size_t>(grid.nx);
  const double z = bed[static_cast<std::size_t>(row) * nx + col];
  if (!std::isfinite(z)) return NAN;
  const auto at = [&](int c, int r) -> double { return bed[static_cast<std::size_t>(r) * nx + c]; };
  const double dzdx = difference([&](int c) { return at(c, row); }, col, grid.nx) / grid.dx[row];
  const double dzdy = difference([&](int r) { return at(col, r); }, row, grid.ny) / grid.dy[row];
  return std::hypot(dzdx, dzdy);
}

std::vector<float> classify_terrain(const Grid& grid, const std::vector<float>& bed,
                                    const std::vector<float>& wet, const ClassRule& rule) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (float z : bed)
    if (std::isfinite(z)) {
      lo = std::min(lo, static_cast<double>(z));
      hi = std::max(hi, static_cast<double>(z));
    }
  const double snow_line =
      std::isfinite(rule.snow_line) ? rule.snow_line : lo + rule.snow_fraction * (hi - lo);
  std::vector<float> out(bed.size(), NAN);
  for (int r = 0; r < grid.ny; ++r)
    for (int c = 0; c < grid.nx; ++c) {
      const std::size_t i = static_cast<std::size_t>(r) * grid.nx + c;
      if (!std::isfinite(bed[i])) continue;
      TerrainClass k = TerrainClass::grass;
      if ((hi > lo || std::isfinite(rule.snow_line)) && bed[i] > snow_line)
        k = TerrainClass::snow;
      else if (cell_slope(grid, bed, c, r) > rule.rock_slope)
        k = TerrainClass::rock;
      else if (!wet.empty() && wet[i] > rule.mud_depth)
        k = TerrainClass::mud;
      out[i] = static_cast<float>(k);
    }
  return out;
}

}  // namespace erodem::viz
