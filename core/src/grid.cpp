#include "erodem/grid.hpp"

#include <algorithm>
#include <cmath>

#include "erodem/error.hpp"

namespace erodem {

Grid Grid::uniform(int nx, int ny, double cell) {
  Grid g;
  g.nx = nx;
  g.ny = ny;
  g.dx.assign(static_cast<std::size_t>(ny), cell);
  g.dy.assign(static_cast<std::size_t>(ny), cell);
  g.area.assign(static_cast<std::size_t>(ny), cell * cell);
  g.georef.transform = {0.0, cell, 0.0, ny * cell, 0.0, -cell};
  return g;
}

double Grid::dx_min() const {
  double m = HUGE_VAL;
  for (int r = 0; r < ny; ++r) m = std::min({m, dx[r], dy[r]});
  return m;
}

std::array<double, 2> Grid::cell_center(int col, int row) const {
  const auto& t = georef.transform;
  const double c = col + 0.5, r = row + 0.5;
  return {t[0] + c * t[1] + r * t[2], t[3] + c * t[4] + r * t[5]};
}

bool Grid::locate(double x, double y, int& col, int& row) const {
  const auto& t = georef.transform;
  // Invert the affine transform.
  const double det = t[1] * t[5] - t[2] * t[4];
  if (det == 0.0) return false;
  const double px = x - t[0], py = y - t[3];
  const double c = (t[5] * px - t[2] * py) / det;
  const double r = (-t[4] * px + t[1] * py) / det;
  if (!(c >= 0.0 && r >= 0.0 && c < nx && r < ny)) return false;
  col = static_cast<int>(c);
  row = static_cast<int>(r);
  return true;
}

void Grid::validate() const {
  if (nx < 1 || ny < 1)
    throw Error(ExitCode::data, "grid: size " + std::to_string(nx) + " x " + std::to_string(ny) +
                                    " must be at least 1 x 1");
  const auto n = static_cast<std::size_t>(ny);
  if (dx.size() != n || dy.size() != n || area.size() != n)
    throw Error(ExitCode::internal, "grid: per-row cell sizes do not match the row count");
  for (int r = 0; r < ny; ++r)
    if (!(std::isfinite(dx[r]) && dx[r] > 0 && std::isfinite(dy[r]) && dy[r] > 0 &&
          std::isfinite(area[r]) && area[r] > 0))
      throw Error(ExitCode::data,
                  "grid: row " + std::to_string(r) + " has a non-positive or non-finite cell size");
}

void Terrain::not_held(std::size_t i) const {
  const auto nx = static_cast<std::size_t>(grid.nx);
  throw Error(ExitCode::internal,
              "terrain: cell (col " + std::to_string(i % nx) + ", row " + std::to_string(i / nx) +
                  ") asked of a band holding rows " + std::to_string(row0) + " to " +
                  std::to_string(end_row() - 1) + " (terrain_rows.hpp answers for the grid)");
}

}  // namespace erodem
