// erodem viewer — the world frame (frame.hpp).
#include "erodem/viz/frame.hpp"

#include <cmath>

namespace erodem::viz {

std::array<double, 2> cell_point(const Grid& grid, double col, double row) {
  const auto& t = grid.georef.transform;
  const double c = col + 0.5, r = row + 0.5;
  return {t[0] + c * t[1] + r * t[2], t[3] + c * t[4] + r * t[5]};
}

WorldFrame WorldFrame::for_grid(const Grid& grid) {
  WorldFrame f;
  const auto centre = cell_point(grid, 0.5 * (grid.nx - 1), 0.5 * (grid.ny - 1));
  f.x0 = centre[0];
  f.y0 = centre[1];
  const auto& t = grid.georef.transform;
  const int mid = grid.ny / 2;
  if (!grid.dx.empty() && std::abs(t[1]) > 0.0) f.sx = grid.dx[mid] / std::abs(t[1]);
  if (!grid.dy.empty() && std::abs(t[5]) > 0.0) f.sy = grid.dy[mid] / std::abs(t[5]);
  return f;
}

}  // namespace erodem::viz
