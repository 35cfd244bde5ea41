#include "erodem/initial_state.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <type_traits>

#include "common/compat.h"
#include "erodem/boundary_codes.hpp"
#include "erodem/error.hpp"
#include "erodem/terrain_synth.hpp"

namespace erodem {

namespace {

std::uint8_t cell_kind(BoundaryKind b) {
  switch (b) {
    case BoundaryKind::open:
      return ERODEM_CELL_OPEN;
    case BoundaryKind::fixed_level:
      return ERODEM_CELL_FIXED;
    case BoundaryKind::closed:
    case BoundaryKind::periodic:  // build_padded_state copies the columns instead
      break;
  }
  return ERODEM_CELL_WALL;
}

}  // namespace

PaddedState build_padded_state(const Terrain& terrain, const Params& params, int y0, int y1) {
  const auto& g = terrain.grid;
  g.validate();
  const std::size_t cells = terrain.held_cells();  // the rows the terrain holds
  auto check_size = [&](const std::vector<double>& v, const char* what) {
    if (!v.empty() && v.size() != cells)
      throw Error(ExitCode::data,
                  fmt::format("{}: {} values for {} rows of a grid of {} x {}", what, v.size(),
                              terrain.end_row() - terrain.row0, g.nx, g.ny));
  };
  if (terrain.bed.size() != cells) throw Error(ExitCode::data, "bed: missing");
  check_size(terrain.water_depth, "initial water depth");
  check_size(terrain.manning_n, "flow.manning_n");
  check_size(terrain.hardness, "erosion.hardness");
  check_size(terrain.rain_factor, "rain.raster");

  const int nx = g.nx, ny = g.ny, W = nx + 2, H = ny + 2;
  if (y1 < 0) y1 = H;
  if (!(0 <= y0 && y0 < y1 && y1 <= H))
    throw Error(ExitCode::internal,
                fmt::format("padded state: rows [{}, {}) of a grid of {} padded rows", y0, y1, H));
  // Built on the rows [a, b): the rows asked for and one beside them each way, which the cells
  // held at the level read (their active neighbours' beds); cut to [y0, y1) at the end.
  const int a = std::max(0, y0 - 1), b = std::min(H, y1 + 1);
  PaddedState s;
  s.nx = nx;
  s.ny = b - a - 2;
  s.W = W;
  s.H = b - a;
  const std::size_t n = s.size();
  // the cell at column x of padded row y (of the whole grid), and DEM cell (c, r)
  const auto at = [&s, a](int x, int y) { return s.at(x, y - a); };
  const auto dem = [nx](int c, int r) { return static_cast<std::size_t>(r) * nx + c; };
  // the DEM rows [r0, r1) on the rows [a, b), and the same as padded rows [first, last]
  const int r0 = std::max(0, a - 1), r1 = std::min(ny, b - 1);
  // a terrain read by rows (an MPI rank's band: io::load_terrain) holds them all
  if (!(terrain.holds_row(r0) && terrain.holds_row(r1 - 1)))
    throw Error(ExitCode::internal,
                fmt::format("padded state: DEM rows [{}, {}) of a terrain holding rows [{}, {})",
                            r0, r1, terrain.row0, terrain.end_row()));
  const int first = r0 + 1, last = r1;

  // Geometry per padded row; halo rows repeat their neighbours.
  s.dx.resize(s.H);
  s.dy.resize(s.H);
  s.area.resize(s.H);
  for (int y = a; y < b; ++y) {
    const int r = std::clamp(y - 1, 0, ny - 1);
    s.dx[y - a] = g.dx[r];
    s.dy[y - a] = g.dy[r];
    s.area[y - a] = g.area[r];
  }

  // Cell kinds: DEM cells active, or not (a wall, or held at the level: boundary_codes.hpp);
  // halo by the edge's condition there (the edge's, or boundary.raster's at the edge cell).
  s.kind.assign(n, ERODEM_CELL_WALL);
  for (int r = r0; r < r1; ++r)
    for (int c = 0; c < nx; ++c) {
      const auto i = dem(c, r);
      s.kind[at(c + 1, r + 1)] = terrain.active(i)                   ? ERODEM_CELL_ACTIVE
                                 : held_at_level(terrain, params, i) ? ERODEM_CELL_FIXED
                                                                     : ERODEM_CELL_WALL;
    }
  for (int y = first; y <= last; ++y) {
    if (s.kind[at(1, y)] == ERODEM_CELL_ACTIVE)
      s.kind[at(0, y)] = cell_kind(ghost_condition(terrain, params, 0, y - 1, Side::west));
    if (s.kind[at(nx, y)] == ERODEM_CELL_ACTIVE)
      s.kind[at(nx + 1, y)] =
          cell_kind(ghost_condition(terrain, params, nx - 1, y - 1, Side::east));
  }
  for (int x = 1; x <= nx; ++x) {
    if (a == 0 && s.kind[at(x, 1)] == ERODEM_CELL_ACTIVE)
      s.kind[at(x, 0)] = cell_kind(ghost_condition(terrain, params, x - 1, 0, Side::north));
    if (b == H && s.kind[at(x, ny)] == ERODEM_CELL_ACTIVE)
      s.kind[at(x, ny + 1)] =
          cell_kind(ghost_condition(terrain, params, x - 1, ny - 1, Side::south));
  }

  // Bed and initial water (computed in double; backends round once).
  s.bed.assign(n, 0.0);
  s.depth.assign(n, 0.0);
  for (int r = r0; r < r1; ++r)
    for (int c = 0; c < nx; ++c) {
      const auto i = dem(c, r);
      const auto p = at(c + 1, r + 1);
      if (s.kind[p] != ERODEM_CELL_ACTIVE) continue;
      s.bed[p] = terrain.bed[terrain.held(i)];
      if (!terrain.water_depth.empty())
        s.depth[p] = terrain.water_depth[terrain.held(i)];
      else if (params.initial.water_level)
        s.depth[p] = std::max(0.0, *params.initial.water_level - s.bed[p]);
      else
        s.depth[p] = params.initial.water_depth.value;
    }
  // Cells held at the level: nodata sea cells over a bed no higher than their active
  // neighbours nor the lowest level (so the sea never runs dry), cells coded fixed_level on
  // their own bed; each holds the level at t = 0 and the sediment its water carries in. (On
  // the DEM rows among those asked for: the rows beside them are built.)
  s.sediment.assign(n, 0.0);
  const double sea = boundary_level(params, 0.0), lowest = boundary_level_range(params).first;
  for (int y = std::max(1, y0); y <= std::min(ny, y1 - 1); ++y)
    for (int x = 1; x <= nx; ++x) {
      const auto p = at(x, y);
      if (s.kind[p] == ERODEM_CELL_ACTIVE) continue;
      const auto i = dem(x - 1, y - 1);
      double low = lowest;
      for (auto q : {p - 1, p + 1, p - W, p + W})
        if (s.kind[q] == ERODEM_CELL_ACTIVE) low = std::min(low, s.bed[q]);
      if (held_on_own_bed(terrain, i)) low = terrain.bed[terrain.held(i)];
      s.bed[p] = s.kind[p] == ERODEM_CELL_FIXED ? low : 0.0;
      s.depth[p] = s.kind[p] == ERODEM_CELL_FIXED ? std::max(sea - low, 0.0) : 0.0;
      if (params.erosion.enabled)
        s.sediment[p] = params.boundary.sediment_concentration * s.depth[p];
    }

  // Rasters or scalars; halo cells copy the nearest DEM cell (Manning n is read at faces).
  // (A scalar stays one value: CellParameter::is_uniform.)
  // (`first_row`: the DEM row of the raster's first row, where it holds only some rows)
  auto raster_or = [&](const std::vector<double>& raster, double scalar, int first_row) {
    CellParameter out;
    out.uniform = scalar;
    if (raster.empty()) return out;
    out.cells.assign(n, scalar);
    for (int y = a; y < b; ++y)
      for (int x = 0; x < W; ++x) {
        const int r = std::clamp(y - 1, 0, ny - 1), c = std::clamp(x - 1, 0, nx - 1);
        out.cells[at(x, y)] = raster[dem(c, r - first_row)];
      }
    return out;
  };
  s.manning = raster_or(terrain.manning_n, params.flow.manning_n.value, terrain.row0);
  // erosion.hardness = "noise": the noise field stands where a hardness raster would, made for
  // the DEM rows these padded rows read only (scaled to the range of the whole grid's active
  // cells, which hardness_noise_rows finds a block of rows at a time)
  if (params.erosion.hardness_noise && !terrain.hardness.empty())
    throw config_error("erosion.hardness",
                       "is \"noise\", but the terrain carries a hardness raster; give one");
  if (params.erosion.hardness_noise) {
    s.hardness = raster_or(hardness_noise_rows(terrain, params.erosion, r0, r1),
                           params.erosion.hardness.value, r0);
  } else {
    s.hardness = raster_or(terrain.hardness, params.erosion.hardness.value, terrain.row0);
  }
  s.rain_factor = raster_or(terrain.rain_factor, 1.0, terrain.row0);
  s.periodic_x = periodic_x(terrain, params);
  if (s.periodic_x && nx < 2)
    throw config_error("boundary.periodic_x",
                       fmt::format("joins the east and west edges of a grid of {} column; it "
                                   "needs at least 2",
                                   nx));
  if (s.periodic_x) {
    // the ghost columns repeat the opposite DEM columns (the corners the ghost rows' ends)
    copy_periodic_columns(s.kind.data(), W, s.H);
    for (auto* f :
         {&s.bed, &s.depth, &s.sediment, &s.manning.cells, &s.hardness.cells, &s.rain_factor.cells})
      if (!f->empty()) copy_periodic_columns(f->data(), W, s.H);
  }

  // The rows asked for: [y0, y1) of [a, b).
  const auto cut = [&](auto& v, std::size_t per_row) {
    v.erase(v.begin() + static_cast<std::ptrdiff_t>(per_row) * (y1 - a), v.end());
    v.erase(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(per_row) * (y0 - a));
  };
  const auto row = static_cast<std::size_t>(W);
  cut(s.kind, row);
  for (auto* f :
       {&s.bed, &s.depth, &s.sediment, &s.manning.cells, &s.hardness.cells, &s.rain_factor.cells})
    if (!f->empty()) cut(*f, row);
  for (auto* f : {&s.dx, &s.dy, &s.area}) cut(*f, 1);
  s.H = y1 - y0;
  s.ny = s.H - 2;
  return s;
}

}  // namespace erodem
