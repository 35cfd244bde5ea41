// erodem — the faces of the cross-sections and outlets (sections.hpp).
#include "erodem/sections.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <utility>

#include "erodem/error.hpp"
#include "erodem/terrain_rows.hpp"

namespace erodem {
namespace {

using Point = std::array<double, 2>;

/// Fractional (col, row) of CRS point p: the inverse of the geotransform (Grid::locate's).
Point grid_coordinates(const Grid& g, const Point& p) {
  const auto& t = g.georef.transform;
  const double det = t[1] * t[5] - t[2] * t[4];
  const double px = p[0] - t[0], py = p[1] - t[3];
  return {(t[5] * px - t[2] * py) / det, (-t[4] * px + t[1] * py) / det};
}

std::string extent_text(const Grid& g) {
  const Point a = g.cell_center(0, 0), b = g.cell_center(g.nx - 1, g.ny - 1);
  const auto& t = g.georef.transform;
  return fmt::format(
      "x {:.10g} .. {:.10g}, y {:.10g} .. {:.10g}", std::min(a[0], b[0]) - 0.5 * std::abs(t[1]),
      std::max(a[0], b[0]) + 0.5 * std::abs(t[1]), std::min(a[1], b[1]) - 0.5 * std::abs(t[5]),
      std::max(a[1], b[1]) + 0.5 * std::abs(t[5]));
}

/// Which side of the line through p with direction d point q lies: > 0 left, else right.
double side(const Point& p, const Point& d, const Point& q) {
  return d[0] * (q[1] - p[1]) - d[1] * (q[0] - p[0]);
}

void add_section(const Grid& g, const SectionSpec& spec, const std::string& key, int index,
                 SectionLayout& out) {
  std::vector<Point> in_grid;
  for (std::size_t v = 0; v < spec.vertices.size(); ++v) {
    const Point c = grid_coordinates(g, spec.vertices[v]);
    if (!(c[0] >= 0 && c[1] >= 0 && c[0] <= g.nx && c[1] <= g.ny))
      throw config_error(fmt::format("{}.line[{}]", key, v),
                         fmt::format("({:.10g}, {:.10g}) is outside the grid ({})",
                                     spec.vertices[v][0], spec.vertices[v][1], extent_text(g)));
    in_grid.push_back(c);
  }
  const std::size_t before = out.faces.size();
  const std::size_t segments = spec.vertices.size() - 1;
  for (std::size_t s = 0; s < segments; ++s) {
    const Point p = spec.vertices[s], q = spec.vertices[s + 1];
    const Point d{q[0] - p[0], q[1] - p[1]};
    const double len2 = d[0] * d[0] + d[1] * d[1];
    if (len2 == 0) continue;
    const bool last = s + 1 == segments;
    // the cells whose centres may join across this segment
    const int c0 =
        std::max(0, static_cast<int>(std::floor(std::min(in_grid[s][0], in_grid[s + 1][0]))) - 1);
    const int c1 = std::min(
        g.nx - 1, static_cast<int>(std::floor(std::max(in_grid[s][0], in_grid[s + 1][0]))) + 1);
    const int r0 =
        std::max(0, static_cast<int>(std::floor(std::min(in_grid[s][1], in_grid[s + 1][1]))) - 1);
    const int r1 = std::min(
        g.ny - 1, static_cast<int>(std::floor(std::max(in_grid[s][1], in_grid[s + 1][1]))) + 1);
    for (int row = r0; row <= r1; ++row)
      for (int col = c0; col <= c1; ++col)
        for (int axis = 0; axis < 2; ++axis) {
          const int col_b = col + (axis == 0), row_b = row + (axis == 1);
          if (col_b >= g.nx || row_b >= g.ny) continue;
          const Point a = g.cell_center(col, row), b = g.cell_center(col_b, row_b);
          const double sa = side(p, d, a), sb = side(p, d, b);
          const bool left_a = sa > 0, left_b = sb > 0;
          if (left_a == left_b) continue;
          // where the centres' link meets the line, along the segment
          const double u = sa / (sa - sb);
          const Point x{a[0] + u * (b[0] - a[0]), a[1] + u * (b[1] - a[1])};
          const double t = ((x[0] - p[0]) * d[0] + (x[1] - p[1]) * d[1]) / len2;
          if (!(t >= 0 && (last ? t <= 1 : t < 1))) continue;
          out.faces.push_back(Face{col, row, axis});
          out.section.push_back(index);
          out.sign.push_back(left_a ? 1.0 : -1.0);  // positive from a (west/north) to b
        }
  }
  if (out.faces.size() == before)
    throw config_error(key + ".line",
                       "crosses no face between two cell centres (draw it across the flow, "
                       "longer than a cell)");
}

void add_outlet(const Terrain& terrain, const OutletSpec& spec, const std::string& key, int index,
                SectionLayout& out) {
  const Grid& g = terrain.grid;
  // whether each cell it asks about is active, asked of every rank's rows at once (a terrain
  // read by rows holds its band's mask alone: terrain_rows.hpp)
  const auto inside = [&](int col, int row) {
    return col >= 0 && row >= 0 && col < g.nx && row < g.ny;
  };
  const auto cell = [&](int col, int row) { return static_cast<std::int64_t>(row) * g.nx + col; };
  std::vector<std::int64_t> asked;
  std::map<std::int64_t, bool> on;
  const auto ask = [&](int col, int row) {
    if (inside(col, row)) asked.push_back(cell(col, row));
  };
  const auto answer = [&] {
    const std::vector<std::uint8_t> a = cells_active(terrain, asked);
    for (std::size_t k = 0; k < asked.size(); ++k) on[asked[k]] = a[k] != 0;
  };
  auto active = [&](int col, int row) { return inside(col, row) && on.at(cell(col, row)); };
  auto add = [&](int col, int row, int axis, double sign) {
    out.faces.push_back(Face{col, row, axis});
    out.section.push_back(index);
    out.sign.push_back(sign);
  };
  const std::size_t before = out.faces.size();
  if (!spec.edge.empty()) {
    if (spec.edge == "east" || spec.edge == "west") {
      const bool east = spec.edge == "east";
      const int col = east ? g.nx - 1 : 0;
      for (int row = 0; row < g.ny; ++row) ask(col, row);
      answer();
      for (int row = 0; row < g.ny; ++row)
        if (active(col, row)) add(east ? col : -1, row, 0, east ? 1.0 : -1.0);
    } else {
      const bool south = spec.edge == "south";
      const int row = south ? g.ny - 1 : 0;
      for (int col = 0; col < g.nx; ++col) ask(col, row);
      answer();
      for (int col = 0; col < g.nx; ++col)
        if (active(col, row)) add(col, south ? row : -1, 1, south ? 1.0 : -1.0);
    }
    if (out.faces.size() == before)
      throw config_error(key + ".edge", "the " + spec.edge + " edge has no active cell");
    return;
  }
  int col = 0, row = 0;
  if (!g.locate(spec.point[0], spec.point[1], col, row))
    throw config_error(key + ".point", fmt::format("({:.10g}, {:.10g}) is outside the grid ({})",
                                                   spec.point[0], spec.point[1], extent_text(g)));
  for (const auto& [dc, dr] : {std::pair{0, 0}, {-1, 0}, {1, 0}, {0, -1}, {0, 1}})
    ask(col + dc, row + dr);
  answer();
  if (!active(col, row))
    throw config_error(key + ".point",
                       fmt::format("the cell under it (col {}, row {}) is nodata", col, row));
  if (!active(col - 1, row)) add(col - 1, row, 0, -1.0);
  if (!active(col + 1, row)) add(col, row, 0, 1.0);
  if (!active(col, row - 1)) add(col, row - 1, 1, -1.0);
  if (!active(col, row + 1)) add(col, row, 1, 1.0);
  if (out.faces.size() == before)
    throw config_error(key + ".point",
                       fmt::format("the cell under it (col {}, row {}) has no face with the "
                                   "outside (the grid's edge or a nodata cell)",
                                   col, row));
}

}  // namespace

SectionLayout layout_sections(const Terrain& terrain, const Params& params) {
  SectionLayout out;
  for (std::size_t k = 0; k < params.section.size(); ++k) {
    out.names.push_back(params.section[k].name);
    out.outlet.push_back(false);
    add_section(terrain.grid, params.section[k], fmt::format("section[{}]", k),
                static_cast<int>(out.names.size() - 1), out);
  }
  for (std::size_t k = 0; k < params.outlet.size(); ++k) {
    out.names.push_back(params.outlet[k].name);
    out.outlet.push_back(true);
    add_outlet(terrain, params.outlet[k], fmt::format("outlet[{}]", k),
               static_cast<int>(out.names.size() - 1), out);
  }
  return out;
}

}  // namespace erodem
