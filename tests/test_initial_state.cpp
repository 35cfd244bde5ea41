// erodem — the padded initial state of a band of rows (build_padded_state's rows [y0, y1),
// what an MPI rank builds for its band and halo) against the same rows of the whole state.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "common/compat.h"
#include "erodem/boundary_codes.hpp"
#include "erodem/error.hpp"
#include "erodem/initial_state.hpp"
#include "scenarios.hpp"

namespace erodem::test {
namespace {

/// Whether two vectors hold the same bits (NaN included).
template <class T>
bool same_bits(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() &&
         (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

/// The padded rows [y0, y1) of the whole state `s`.
template <class T>
std::vector<T> rows_of(const std::vector<T>& v, std::size_t per_row, int y0, int y1) {
  return std::vector<T>(v.begin() + static_cast<std::ptrdiff_t>(per_row) * y0,
                        v.begin() + static_cast<std::ptrdiff_t>(per_row) * y1);
}

struct Case {
  const char* name;
  Terrain terrain;
  Params params;
};

/// Terrains whose padded state has something at every kind of row a band can start or end
/// on: nodata sea cells (their bed from the active neighbours above and below), cells coded
/// fixed_level and closed by a boundary raster, a fixed-level north edge and an open south
/// one (the ghost rows), rasters of Manning n and rain factor (their halo copies), the
/// periodic columns, and hardness noise (scaled over the whole grid).
std::vector<Case> cases() {
  const int nx = 9, ny = 8;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  Terrain base = flat_terrain(nx, ny, 10.0);
  for (int r = 0; r < ny; ++r)
    for (int c = 0; c < nx; ++c)
      base.bed[static_cast<std::size_t>(r) * nx + c] = 3.0 + 0.7 * r + 0.3 * std::sin(1.3 * c + r);
  Params p = default_params();
  p.erosion.enabled = true;
  p.boundary.north = BoundaryKind::fixed_level;
  p.boundary.south = BoundaryKind::open;
  p.boundary.east = p.boundary.west = BoundaryKind::closed;
  p.boundary.sea_level = 5.0;
  p.boundary.sediment_concentration = 0.01;

  std::vector<Case> out;
  {
    Case k{"nodata sea, boundary codes, rasters", base, p};
    k.params.boundary.nodata = NodataKind::sea;
    k.terrain.mask.assign(k.terrain.grid.cells(), 1);
    for (const auto& [c, r] : std::vector<std::pair<int, int>>{
             {0, 0}, {4, 1}, {4, 2}, {7, 3}, {2, 4}, {3, 4}, {8, 7}, {5, 6}})
      k.terrain.mask[static_cast<std::size_t>(r) * nx + c] = 0;
    k.terrain.boundary_code.assign(k.terrain.grid.cells(), kBoundaryAsEdge);
    k.terrain.boundary_code[static_cast<std::size_t>(5) * nx + 1] = kBoundaryFixed;
    k.terrain.boundary_code[static_cast<std::size_t>(3) * nx + 6] = kBoundaryClosed;
    k.terrain.mask[static_cast<std::size_t>(3) * nx + 6] = 0;
    k.terrain.manning_n.resize(k.terrain.grid.cells());
    k.terrain.rain_factor.resize(k.terrain.grid.cells());
    for (std::size_t i = 0; i < k.terrain.grid.cells(); ++i) {
      k.terrain.manning_n[i] = 0.02 + 0.001 * static_cast<double>(i);
      k.terrain.rain_factor[i] = 0.5 + 0.01 * static_cast<double>(i);
    }
    k.terrain.bed[static_cast<std::size_t>(2) * nx + 3] = nan;  // a nodata bed under the mask
    k.terrain.mask[static_cast<std::size_t>(2) * nx + 3] = 0;
    out.push_back(k);
  }
  {
    Case k{"periodic east-west, initial water level", base, p};
    k.params.boundary.periodic_x = true;
    k.params.initial.water_level = 6.0;
    out.push_back(k);
  }
  {
    Case k{"hardness noise", base, p};
    k.params.erosion.hardness_noise = true;
    k.params.erosion.noise_scale = 30.0;
    out.push_back(k);
  }
  return out;
}

/// Whether parameter `band` is rows [y0, y1) of `whole`: both one value (the same bits), or
/// both per cell and those rows.
bool same_parameter(const CellParameter& band, const CellParameter& whole, std::size_t W, int y0,
                    int y1) {
  if (band.is_uniform() || whole.is_uniform())
    return band.is_uniform() && whole.is_uniform() &&
           same_bits(std::vector<double>{band.uniform}, std::vector<double>{whole.uniform});
  return same_bits(band.cells, rows_of(whole.cells, W, y0, y1));
}

TEST(InitialState, ABandIsThoseRowsOfTheWholeState) {
  // Every band [y0, y1) of the padded rows (ny + 2 = 10: 55 bands, from one row to all) must
  // give those rows of the whole state, bit for bit, in every field and in the rows' geometry.
  // A band that built its held cells without the row beside it (a sea cell's bed from its
  // active neighbours), its ghost rows without the DEM row next to them, or its rasters'
  // halo from the band's own edge rather than the grid's, differs at some band.
  for (const Case& k : cases()) {
    const PaddedState whole = build_padded_state(k.terrain, k.params);
    const auto W = static_cast<std::size_t>(whole.W);
    int bands = 0, differ = 0;
    for (int y0 = 0; y0 < whole.H; ++y0)
      for (int y1 = y0 + 1; y1 <= whole.H; ++y1) {
        const PaddedState band = build_padded_state(k.terrain, k.params, y0, y1);
        ++bands;
        const bool same = band.H == y1 - y0 && band.ny == y1 - y0 - 2 && band.W == whole.W &&
                          band.nx == whole.nx && band.periodic_x == whole.periodic_x &&
                          same_bits(band.kind, rows_of(whole.kind, W, y0, y1)) &&
                          same_bits(band.bed, rows_of(whole.bed, W, y0, y1)) &&
                          same_bits(band.depth, rows_of(whole.depth, W, y0, y1)) &&
                          same_bits(band.sediment, rows_of(whole.sediment, W, y0, y1)) &&
                          same_parameter(band.manning, whole.manning, W, y0, y1) &&
                          same_parameter(band.hardness, whole.hardness, W, y0, y1) &&
                          same_parameter(band.rain_factor, whole.rain_factor, W, y0, y1) &&
                          same_bits(band.dx, rows_of(whole.dx, 1, y0, y1)) &&
                          same_bits(band.dy, rows_of(whole.dy, 1, y0, y1)) &&
                          same_bits(band.area, rows_of(whole.area, 1, y0, y1));
        if (!same) {
          ++differ;
          ADD_FAILURE() << k.name << ": rows [" << y0 << ", " << y1 << ") differ";
        }
      }
    std::printf("[initial state] %s: %d of %d bands differ from the whole state's rows (bound 0)\n",
                k.name, differ, bands);
  }
  // The cases mean something only if they hold what they say: sea cells held at the level
  // with sediment, and hardness that varies.
  const std::vector<Case> all = cases();
  const Case& sea = all[0];
  const PaddedState s = build_padded_state(sea.terrain, sea.params);
  int held = 0;
  for (std::size_t p = 0; p < s.size(); ++p)
    held += s.kind[p] == ERODEM_CELL_FIXED && s.sediment[p] > 0;
  // (6: the nodata cells of the rows whose bed lies below the 5 m sea, rows 0 to 2 and 4)
  EXPECT_GE(held, 5) << "DEM cells held at the sea level with water and sediment";
  const PaddedState noise = build_padded_state(all[2].terrain, all[2].params);
  ASSERT_FALSE(noise.hardness.is_uniform());
  EXPECT_NE(noise.hardness.cells[noise.at(2, 2)], noise.hardness.cells[noise.at(6, 7)]);
}

TEST(InitialState, RowsOutsideTheGridAreRefused) {
  const Case k = cases()[1];
  for (const auto& [y0, y1] : std::vector<std::pair<int, int>>{{-1, 3}, {3, 3}, {5, 2}, {0, 11}})
    EXPECT_THROW(build_padded_state(k.terrain, k.params, y0, y1), Error) << y0 << ", " << y1;
}

}  // namespace
}  // namespace erodem::test
