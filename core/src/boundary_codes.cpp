#include "erodem/boundary_codes.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "erodem/error.hpp"
#include "erodem/simulation.hpp"
#include "erodem/terrain_rows.hpp"

namespace erodem {

namespace {

int code_at(const Terrain& t, std::size_t i) {
  if (t.boundary_code.empty()) return kBoundaryAsEdge;
  const double v = t.boundary_code[t.held(i)];  // a nodata cell's may be anything
  return v == 1 ? kBoundaryClosed : v == 2 ? kBoundaryOpen : v == 3 ? kBoundaryFixed : 0;
}

}  // namespace

void apply_boundary_codes(Terrain& t, const std::string& source) {
  if (t.boundary_code.empty()) return;
  const auto& g = t.grid;
  const auto code = [&t](std::size_t i) { return t.boundary_code[t.held(i)]; };
  const auto edge = [&g](std::size_t i) {
    const auto c = static_cast<int>(i % static_cast<std::size_t>(g.nx)),
               r = static_cast<int>(i / static_cast<std::size_t>(g.nx));
    return c == 0 || r == 0 || c == g.nx - 1 || r == g.ny - 1;
  };
  const auto is_code = [](double v) { return v == 0 || v == 1 || v == 2 || v == 3; };
  const BadCell bad = first_bad_cell(t, code, [&](std::size_t i, double v) {
    return is_code(v) && !(v == kBoundaryOpen && !edge(i));
  });
  if (bad.cell >= 0) {
    const auto c = bad.cell % g.nx, r = bad.cell / g.nx;
    const double v = bad.value;
    if (!is_code(v))
      throw Error(ExitCode::data,
                  fmt::format("{}: 'boundary.raster' value {} at cell {}, {} is not a boundary "
                              "code (0 as the edge says, 1 closed, 2 open, 3 fixed_level)",
                              source, v, c, r));
    throw Error(ExitCode::data,
                fmt::format("{}: 'boundary.raster' code 2 (open) at cell {}, {}, inside the "
                            "grid: open applies to the grid's edge cells only",
                            source, c, r));
  }
  // interior cells coded closed or fixed_level leave the domain (on the rows the terrain
  // holds, as it holds their codes: an MPI rank's band's, Terrain::banded)
  if (t.mask.empty()) t.mask.assign(t.held_cells(), 1);
  const auto nx = static_cast<std::size_t>(g.nx);
  for (std::size_t i = static_cast<std::size_t>(t.row0) * nx;
       i < static_cast<std::size_t>(t.end_row()) * nx; ++i)
    if (t.active(i) && !edge(i) && (code(i) == kBoundaryClosed || code(i) == kBoundaryFixed))
      t.mask[t.held(i)] = 0;
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
  return code_at(t, i) == kBoundaryFixed && std::isfinite(t.bed[t.held(i)]);
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
  const int nx = t.grid.nx;
  // every row an array holds (the whole grid's, or a band's: Terrain::row0), each nx long
  auto trim = [&](auto& v) {
    if (v.empty()) return;  // not given
    const std::size_t rows = v.size() / static_cast<std::size_t>(nx);
    std::size_t k = 0;
    for (std::size_t r = 0; r < rows; ++r)
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
    // (the mask and the codes of the rows the terrain holds: an MPI rank's band's,
    // Terrain::banded; every rank has codes once a row is capped, so every rank checks them
    // together: apply_boundary_codes)
    if (t.boundary_code.empty()) t.boundary_code.assign(t.held_cells(), kBoundaryAsEdge);
    if (!t.holds_row(r)) continue;
    if (t.mask.empty()) t.mask.assign(t.held_cells(), 1);
    for (int c = 0; c < g.nx; ++c) {
      const auto i = t.held(static_cast<std::size_t>(r) * g.nx + c);
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
