#include "erodem/boundary_codes.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "erodem/error.hpp"
#include "erodem/simulation.hpp"

namespace erodem {

namespace {

int code_at(const Terrain& t, std::size_t i) {
  if (t.boundary_code.empty()) return kBoundaryAsEdge;
  const double v = t.boundary_code[i];  // a nodata cell's may be anything
  return v == 1 ? kBoundaryClosed : v == 2 ? kBoundaryOpen : v == 3 ? kBoundaryFixed : 0;
}

}  // namespace

void apply_boundary_codes(Terrain& t, const std::string& source) {
  if (t.boundary_code.empty()) return;
  const auto& g = t.grid;
  if (t.mask.empty()) t.mask.assign(g.cells(), 1);
  for (int r = 0; r < g.ny; ++r)
    for (int c = 0; c < g.nx; ++c) {
      const auto i = static_cast<std::size_t>(r) * g.nx + c;
      if (!t.active(i)) continue;
      const double v = t.boundary_code[i];
      const bool edge = c == 0 || r == 0 || c == g.nx - 1 || r == g.ny - 1;
      if (!(v == 0 || v == 1 || v == 2 || v == 3))
        throw Error(ExitCode::data,
                    fmt::format("{}: 'boundary.raster' value {} at cell {}, {} is not a boundary "
                                "code (0 as the edge says, 1 closed, 2 open, 3 fixed_level)",
                                source, v, c, r));
      if (v == kBoundaryOpen && !edge)
        throw Error(ExitCode::data,
                    fmt::format("{}: 'boundary.raster' code 2 (open) at cell {}, {}, inside the "
                                "grid: open applies to the grid's edge cells only",
                                source, c, r));
      if (!edge && (v == kBoundaryClosed || v == kBoundaryFixed)) t.mask[i] = 0;
    }
}

BoundaryKind ghost_condition(const Terrain& t, const Params& p, int col, int row, Side side) {
  const auto i = static_cast<std::size_t>(row) * t.grid.nx + col;
  switch (code_at(t, i)) {
    case kBoundaryClosed:
      return BoundaryKind::closed;
    case kBoundaryOpen:
      return BoundaryKind::open;
    case kBoundaryFixed:
      return BoundaryKind::fixed_level;
    default:
      break;
  }
  switch (side) {
    case Side::west:
      return p.boundary.west;
    case Side::east:
      return p.boundary.east;
    case Side::north:
      return p.boundary.north;
    case Side::south:
      break;
  }
  return p.boundary.south;
}

bool held_at_level(const Terrain& t, const Params& p, std::size_t i) {
  const int code = code_at(t, i);
  if (code == kBoundaryFixed) return true;
  return code != kBoundaryClosed && p.boundary.nodata == NodataKind::sea;
}

bool held_on_own_bed(const Terrain& t, std::size_t i) {
  return code_at(t, i) == kBoundaryFixed && std::isfinite(t.bed[i]);
}

double boundary_level(const Params& p, double t) {
  return p.boundary.stage.empty() ? p.boundary.sea_level : series_value(p.boundary.stage, t);
}

std::pair<double, double> boundary_level_range(const Params& p) {
  const auto& stage = p.boundary.stage;
  if (stage.empty()) return {p.boundary.sea_level, p.boundary.sea_level};
  const auto [lo, hi] = std::minmax_element(
      stage.begin(), stage.end(), [](const auto& a, const auto& b) { return a.value < b.value; });
  return {lo->value, hi->value};
}

}  // namespace erodem
