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
  // joined edges: the ghost repeats the opposite DEM cell, whatever the codes or edges say
  if ((side == Side::west || side == Side::east) && periodic_x(t, p)) return BoundaryKind::periodic;
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

namespace {

/// How many columns of longitude a lat/lon grid's columns cover, beyond 360 degrees, and
/// whether it is a lat/lon grid with an untilted transform at all.
bool excess_columns(const Grid& g, double& excess) {
  const auto& tr = g.georef.transform;
  if (!g.georef.is_geographic || tr[1] == 0.0 || tr[2] != 0.0) return false;
  excess = (g.nx * std::fabs(tr[1]) - 360.0) / std::fabs(tr[1]);
  return true;
}

}  // namespace

bool spans_360(const Grid& g) {
  double excess = 0.0;
  return excess_columns(g, excess) && std::fabs(excess) <= 1e-3;
}

bool repeats_first_column(const Grid& g) {
  double excess = 0.0;
  return excess_columns(g, excess) && g.nx > 2 && std::fabs(excess - 1.0) <= 1e-3;
}

void drop_last_column(Terrain& t) {
  const int nx = t.grid.nx, ny = t.grid.ny;
  auto trim = [&](auto& v) {
    if (v.size() != static_cast<std::size_t>(nx) * ny) return;  // empty: not given
    std::size_t k = 0;
    for (int r = 0; r < ny; ++r)
      for (int c = 0; c < nx - 1; ++c) v[k++] = v[static_cast<std::size_t>(r) * nx + c];
    v.resize(k);
  };
  for (auto* v :
       {&t.bed, &t.water_depth, &t.manning_n, &t.hardness, &t.rain_factor, &t.soil_thickness,
        &t.ksat, &t.suction, &t.moisture_deficit, &t.soil_depth, &t.boundary_code, &t.snow_initial})
    trim(*v);
  trim(t.mask);
  for (auto& band : t.rain_grids) trim(band);
  for (auto& band : t.temperature_grids) trim(band);
  t.grid.nx = nx - 1;
}

bool periodic_x(const Terrain& t, const Params& p) {
  if (p.boundary.periodic_x) return *p.boundary.periodic_x;
  return (p.boundary.east == BoundaryKind::periodic && p.boundary.west == BoundaryKind::periodic) ||
         spans_360(t.grid);
}

int apply_latitude_cap(Terrain& t, const Params& p) {
  if (!p.boundary.latitude_cap) return 0;
  const double cap = *p.boundary.latitude_cap;
  const Grid& g = t.grid;
  if (!g.georef.is_geographic)
    throw config_error("boundary.latitude_cap",
                       fmt::format("{} is on a projected grid; the cap applies to lat/lon grids, "
                                   "whose cells narrow towards the poles",
                                   t.source));
  int capped = 0;
  for (int r = 0; r < g.ny; ++r) {
    if (!(std::fabs(g.cell_center(0, r)[1]) > cap)) continue;
    ++capped;
    if (t.mask.empty()) t.mask.assign(g.cells(), 1);
    if (t.boundary_code.empty()) t.boundary_code.assign(g.cells(), kBoundaryAsEdge);
    for (int c = 0; c < g.nx; ++c) {
      const auto i = static_cast<std::size_t>(r) * g.nx + c;
      t.mask[i] = 0;
      t.boundary_code[i] = kBoundaryClosed;
    }
  }
  if (capped == g.ny)
    throw config_error("boundary.latitude_cap",
                       fmt::format("{} degrees leaves no row of {} (every row lies poleward of it)",
                                   cap, t.source));
  return capped;
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
