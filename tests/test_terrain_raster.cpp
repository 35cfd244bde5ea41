// Tests of synthetic terrain (erodem::generate_terrain) and GDAL raster I/O (erodem::io).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <numeric>
#include <string>
#include <vector>

#include "erodem/error.hpp"
#include "erodem/grid.hpp"
#include "erodem/io/raster.hpp"
#include "erodem/params.hpp"
#include "erodem/terrain_synth.hpp"
#include "temp_dir.hpp"

namespace fs = std::filesystem;
using erodem::ExitCode;
using erodem::SynthKind;

namespace {

const std::string kShared = ERODEM_SHARED_DIR;
const std::string kVolcano = kShared + "/data/dem/volcano/volcano_northup_10m.tif";
const std::string kTujunga = kShared + "/data/dem/big_tujunga/srtm_bigtujunga30m_utm11.tif";
const std::string kPuget = kShared + "/data/dem/puget_sound/ps_height_1k.png";

/// Runs `f` and returns the exit code of the erodem::Error it throws (fails if none).
template <class F>
ExitCode code_of(F&& f, std::string* message = nullptr) {
  try {
    f();
  } catch (const erodem::Error& e) {
    if (message) *message = e.what();
    std::printf("  expected error (%d): %s\n", static_cast<int>(e.code()), e.what());
    return e.code();
  }
  ADD_FAILURE() << "no erodem::Error thrown";
  return ExitCode::ok;
}

struct Range {
  double lo = HUGE_VAL, hi = -HUGE_VAL;
  std::size_t valid = 0;
};
Range range_of(const erodem::Terrain& t) {
  Range r;
  for (std::size_t i = 0; i < t.bed.size(); ++i)
    if (t.active(i)) {
      r.lo = std::min(r.lo, t.bed[i]);
      r.hi = std::max(r.hi, t.bed[i]);
      ++r.valid;
    }
  return r;
}

double at(const std::vector<double>& h, int nx, int col, int row) {
  return h[static_cast<std::size_t>(row) * nx + col];
}

}  // namespace

// ---- synthetic terrain -----------------------------------------------------------------

TEST(TerrainSynth, KindNames) {
  ASSERT_EQ(erodem::synth_kind_names().size(), 7u);
  for (const auto& name : erodem::synth_kind_names())
    EXPECT_EQ(erodem::to_string(erodem::synth_kind_from_string(name)), name);
  EXPECT_EQ(erodem::synth_kind_from_string("diamond_square"), SynthKind::diamond_square);
  std::string msg;
  EXPECT_EQ(code_of([] { erodem::synth_kind_from_string("perlin"); }, &msg), ExitCode::usage);
  EXPECT_NE(msg.find("perlin"), std::string::npos);
  EXPECT_NE(msg.find("fbm"), std::string::npos);
  EXPECT_NE(msg.find("ridge"), std::string::npos);
}

TEST(TerrainSynth, ReproducibleAndSeedDependent) {
  for (const auto& name : erodem::synth_kind_names()) {
    const SynthKind k = erodem::synth_kind_from_string(name);
    const auto a = erodem::generate_terrain(k, 97, 64, 10.0, 100.0, 42);
    const auto b = erodem::generate_terrain(k, 97, 64, 10.0, 100.0, 42);
    const auto c = erodem::generate_terrain(k, 97, 64, 10.0, 100.0, 43);
    ASSERT_EQ(a.size(), 97u * 64u);
    EXPECT_EQ(0, std::memcmp(a.data(), b.data(), a.size() * sizeof(double))) << name;
    std::size_t differ = 0;
    for (std::size_t i = 0; i < a.size(); ++i) differ += a[i] != c[i];
    EXPECT_GT(differ, a.size() / 2) << name;
    // A digest of the output, to compare across machines and compilers.
    unsigned long long hash = 1469598103934665603ULL;
    for (double v : a) {
      unsigned long long bits;
      std::memcpy(&bits, &v, sizeof bits);
      hash = (hash ^ bits) * 1099511628211ULL;
    }
    std::printf("  %-15s seed 42 97x64: h[0]=%.17g h[mid]=%.17g fnv=%016llx\n", name.c_str(), a[0],
                a[a.size() / 2], hash);
    // Golden digests (GCC 12 and Clang 14/15, x86-64, -O0..-O3, with and without FMA): the
    // same seed must give the same bits on every machine and compiler.
    static const std::map<std::string, unsigned long long> golden{
        {"fbm", 0xb5dc6b4238ac0ab8ULL},
        {"ridged", 0xef7d764c1be54217ULL},
        {"diamond_square", 0x0c3957a172e78952ULL},
        {"hill", 0x2d58d81031c987d6ULL},
        {"lake", 0xe0683092735bfc3fULL},
        {"valley", 0x2330c7f4d68cdeb8ULL},
        {"ridge", 0xb465b808701f6a02ULL}};
    EXPECT_EQ(hash, golden.at(name)) << name << ": output bits changed";
  }
}

// generate_terrain_rows (an MPI rank's band of a synthetic terrain, docs/mpi.md): each band's
// rows, scaled by the whole grid's ranges combined from every band's own rows, must be the
// whole grid's rows bit for bit, for every kind made by rows and for bands with and without
// the grid's first or last row. The ranks' combination (an allreduce of min and max) is
// played here in passes: the k-th range a band reports is combined over the bands, then given
// back to every band as its k-th range in the next pass. A band scaled by its own range
// instead differs (checked below), so the bound 0 catches a range taken from the band alone.
TEST(TerrainSynth, RowsAreTheWholeGridsRows) {
  const int nx = 97, ny = 64, margin = 4;
  const std::vector<std::array<int, 2>> own{{0, 21}, {21, 42}, {42, 64}};
  for (const auto& name : erodem::synth_kind_names()) {
    const SynthKind k = erodem::synth_kind_from_string(name);
    const auto whole = erodem::generate_terrain(k, nx, ny, 10.0, 100.0, 42);
    std::vector<std::pair<double, double>> known;  // the grid's ranges, in call order
    std::vector<std::vector<double>> rows(own.size());
    for (int pass = 0; pass < 3; ++pass) {
      std::pair<double, double> next{HUGE_VAL, -HUGE_VAL};  // the next range, combined
      for (std::size_t b = 0; b < own.size(); ++b) {
        std::size_t call = 0;
        const erodem::RangeReduce reduce = [&](double& lo, double& hi) {
          if (call < known.size()) {
            lo = known[call].first;
            hi = known[call].second;
          } else if (call == known.size()) {
            next = {std::min(next.first, lo), std::max(next.second, hi)};
          }
          ++call;
        };
        rows[b] = erodem::generate_terrain_rows(
            k, nx, ny, 100.0, 42, std::max(0, own[b][0] - margin), std::min(ny, own[b][1] + margin),
            own[b][0], own[b][1], reduce);
      }
      if (next.first <= next.second) known.push_back(next);
    }
    std::size_t differ = 0;  // values of the bands' rows that differ from the grid's
    for (std::size_t b = 0; b < own.size(); ++b) {
      const int r0 = std::max(0, own[b][0] - margin), r1 = std::min(ny, own[b][1] + margin);
      ASSERT_EQ(rows[b].size(), static_cast<std::size_t>(r1 - r0) * nx) << name;
      for (std::size_t i = 0; i < rows[b].size(); ++i)
        differ += std::memcmp(&rows[b][i], &whole[static_cast<std::size_t>(r0) * nx + i],
                              sizeof(double)) != 0;
    }
    EXPECT_EQ(differ, 0u) << name;
    // scaled by its own rows' ranges alone, the middle band is not the grid's
    const auto alone = erodem::generate_terrain_rows(k, nx, ny, 100.0, 42, 17, 46, 21, 42, nullptr);
    std::size_t differ_alone = 0;
    for (std::size_t i = 0; i < alone.size(); ++i) differ_alone += alone[i] != whole[17 * nx + i];
    EXPECT_GT(differ_alone, alone.size() / 2) << name;
    std::printf(
        "  %-7s rows by 3 bands: %zu ranges combined, %zu values differ (bound 0); "
        "scaled by the middle band's own ranges: %zu of %zu differ\n",
        name.c_str(), known.size(), differ, differ_alone, alone.size());
  }
}

// Diamond-square by rows makes each level's lattice on the rows the finer levels read only,
// with each point's displacement drawn by its index in the whole grid's order: any window of
// rows must be the whole grid's rows bit for bit (bound 0: one misplaced draw, a row of a
// lattice not made, a neighbour read from the wrong level changes values), on grids that
// fill their 2^k + 1 lattice or are cropped from it, thin in either direction. The whole
// grid's range (which scales the heights) is taken from the rows version over every row and
// given to each window.
TEST(TerrainSynth, DiamondSquareRowsOfAnyWindow) {
  std::size_t windows = 0, compared = 0, differ = 0;
  for (const auto& [nx, ny] : std::vector<std::array<int, 2>>{
           {1, 1}, {3, 200}, {200, 3}, {97, 64}, {129, 129}, {130, 40}, {33, 65}}) {
    const auto whole = erodem::generate_terrain(SynthKind::diamond_square, nx, ny, 10.0, 80.0, 9);
    double lo = 0, hi = 0;
    const erodem::RangeReduce keep = [&](double& l, double& h) { lo = l, hi = h; };
    const auto all = erodem::generate_terrain_rows(SynthKind::diamond_square, nx, ny, 80.0, 9, 0,
                                                   ny, 0, ny, keep);
    ASSERT_EQ(all.size(), whole.size());
    for (std::size_t i = 0; i < all.size(); ++i) differ += all[i] != whole[i];
    const erodem::RangeReduce give = [&](double& l, double& h) { l = lo, h = hi; };
    for (const int r0 : {0, 1, 2, ny / 2 - 1, ny / 2, ny / 2 + 1, ny - 2, ny - 1})
      for (const int len : {1, 2, 5, 30}) {
        if (r0 < 0 || r0 + len > ny) continue;
        const auto rows = erodem::generate_terrain_rows(SynthKind::diamond_square, nx, ny, 80.0, 9,
                                                        r0, r0 + len, r0, r0 + len, give);
        ASSERT_EQ(rows.size(), static_cast<std::size_t>(len) * nx);
        ++windows;
        for (std::size_t i = 0; i < rows.size(); ++i, ++compared)
          differ += std::memcmp(&rows[i], &whole[static_cast<std::size_t>(r0) * nx + i],
                                sizeof(double)) != 0;
      }
  }
  std::printf("  diamond-square: %zu windows of rows, %zu values, %zu differ (bound 0)\n", windows,
              compared, differ);
  EXPECT_EQ(differ, 0u);
  EXPECT_GE(windows, 140u);
}

TEST(TerrainSynth, RangeAndErrors) {
  for (const auto& name : erodem::synth_kind_names()) {
    const auto h =
        erodem::generate_terrain(erodem::synth_kind_from_string(name), 65, 65, 5.0, 250.0, 7);
    const auto mm = std::minmax_element(h.begin(), h.end());
    EXPECT_EQ(*mm.first, 0.0) << name;
    EXPECT_EQ(*mm.second, 250.0) << name;
    for (double v : h) ASSERT_TRUE(std::isfinite(v) && v >= 0.0 && v <= 250.0) << name;
  }
  // Degenerate but legal sizes.
  EXPECT_EQ(erodem::generate_terrain(SynthKind::fbm, 1, 1, 1.0, 1.0, 1).size(), 1u);
  EXPECT_EQ(erodem::generate_terrain(SynthKind::diamond_square, 3, 200, 1.0, 1.0, 1).size(), 600u);
  EXPECT_EQ(code_of([] { erodem::generate_terrain(SynthKind::fbm, 0, 5, 1.0, 1.0, 1); }),
            ExitCode::usage);
  EXPECT_EQ(code_of([] { erodem::generate_terrain(SynthKind::fbm, 5, 5, 0.0, 1.0, 1); }),
            ExitCode::usage);
  EXPECT_EQ(code_of([] { erodem::generate_terrain(SynthKind::fbm, 5, 5, 1.0, -1.0, 1); }),
            ExitCode::usage);
}

TEST(TerrainSynth, Shapes) {
  const int n = 128;
  const double relief = 100.0;
  auto gen = [&](SynthKind k) { return erodem::generate_terrain(k, n, n, 10.0, relief, 3); };

  // hill: the highest cell near the middle, the edges low.
  {
    const auto h = gen(SynthKind::hill);
    const auto imax = static_cast<int>(std::max_element(h.begin(), h.end()) - h.begin());
    const int c = imax % n, r = imax / n;
    std::printf("  hill: max at (%d, %d), corner %.2f m\n", c, r, at(h, n, 0, 0));
    EXPECT_NEAR(c, n / 2, n / 10);
    EXPECT_NEAR(r, n / 2, n / 10);
    EXPECT_LT(at(h, n, 0, 0), 0.2 * relief);
  }
  // lake: the minimum inside, below every edge cell by a clear margin (closed depression).
  {
    const auto h = gen(SynthKind::lake);
    const auto imin = static_cast<int>(std::min_element(h.begin(), h.end()) - h.begin());
    const int c = imin % n, r = imin / n;
    double edge_min = HUGE_VAL, rim_min = HUGE_VAL;
    for (int i = 0; i < n; ++i)
      edge_min = std::min(
          {edge_min, at(h, n, i, 0), at(h, n, i, n - 1), at(h, n, 0, i), at(h, n, n - 1, i)});
    // The lowest point of the rim circle (radius 0.3 of the extent) is the spill level.
    for (int k = 0; k < 360; ++k) {
      const double a = k * 3.14159265358979 / 180.0;
      const int cc = static_cast<int>(n / 2 + 0.3 * n * std::cos(a));
      const int rr = static_cast<int>(n / 2 + 0.3 * n * std::sin(a));
      rim_min = std::min(rim_min, at(h, n, cc, rr));
    }
    std::printf("  lake: min %.2f m at (%d, %d), rim spill %.2f m, edge min %.2f m\n", h[imin], c,
                r, rim_min, edge_min);
    EXPECT_NEAR(c, n / 2, n / 8);
    EXPECT_NEAR(r, n / 2, n / 8);
    EXPECT_GT(edge_min, h[imin] + 0.3 * relief);
    EXPECT_GT(rim_min, h[imin] + 0.7 * relief);
    EXPECT_GT(rim_min, edge_min);
  }
  // valley: slopes down along x; the axis lower than the sides.
  {
    const auto h = gen(SynthKind::valley);
    auto col_mean = [&](int c) {
      double s = 0;
      for (int r = 0; r < n; ++r) s += at(h, n, c, r);
      return s / n;
    };
    const double west = at(h, n, 2, n / 2), east = at(h, n, n - 3, n / 2);
    std::printf("  valley: axis west %.2f m, east %.2f m; column means %.2f -> %.2f m\n", west,
                east, col_mean(0), col_mean(n - 1));
    EXPECT_GT(col_mean(0), col_mean(n - 1));
    EXPECT_GT(west, east + 0.3 * relief);
    for (int c = 0; c < n; c += 8) {
      EXPECT_LT(at(h, n, c, n / 2), at(h, n, c, 0)) << c;
      EXPECT_LT(at(h, n, c, n / 2), at(h, n, c, n - 1)) << c;
    }
    // The thalweg (lowest cell of each column) descends overall and lies near the axis.
    double prev = HUGE_VAL;
    int rises = 0;
    for (int c = 0; c < n; ++c) {
      double lo = HUGE_VAL;
      int rlo = 0;
      for (int r = 0; r < n; ++r)
        if (at(h, n, c, r) < lo) lo = at(h, n, c, r), rlo = r;
      EXPECT_NEAR(rlo, n / 2, n / 10) << c;
      rises += lo > prev;
      prev = lo;
    }
    EXPECT_LT(rises, n / 4);
  }
  // ridge: the diagonal high, the off-diagonal corners low.
  {
    const auto h = gen(SynthKind::ridge);
    double diag = 0.0;
    for (int i = 0; i < n; ++i) diag += at(h, n, i, i) / n;
    std::printf("  ridge: diagonal mean %.2f m, corners %.2f, %.2f m\n", diag, at(h, n, n - 1, 0),
                at(h, n, 0, n - 1));
    EXPECT_GT(diag, 0.7 * relief);
    EXPECT_LT(at(h, n, n - 1, 0), 0.15 * relief);
    EXPECT_LT(at(h, n, 0, n - 1), 0.15 * relief);
  }
  // fbm / ridged / diamond_square: rough, not constant, spatially correlated.
  for (SynthKind k : {SynthKind::fbm, SynthKind::ridged, SynthKind::diamond_square}) {
    const auto h = gen(k);
    double mean = std::accumulate(h.begin(), h.end(), 0.0) / h.size();
    double var = 0.0, dvar = 0.0;
    for (int r = 0; r < n; ++r)
      for (int c = 0; c < n; ++c) {
        var += (at(h, n, c, r) - mean) * (at(h, n, c, r) - mean);
        if (c + 1 < n)
          dvar += (at(h, n, c + 1, r) - at(h, n, c, r)) * (at(h, n, c + 1, r) - at(h, n, c, r));
      }
    var /= h.size();
    dvar /= h.size();
    std::printf("  %s: mean %.2f m, std %.2f m, neighbour-difference rms %.2f m\n",
                erodem::to_string(k).c_str(), mean, std::sqrt(var), std::sqrt(dvar));
    EXPECT_GT(std::sqrt(var), 0.08 * relief);
    EXPECT_LT(std::sqrt(dvar), 0.5 * std::sqrt(var));  // neighbours are correlated
  }
}

TEST(TerrainSynth, MakeSyntheticTerrain) {
  erodem::Params::Dem dem;
  dem.synthetic = "ridged";
  dem.size = 64;
  dem.seed = 5;
  const auto t = erodem::make_synthetic_terrain(dem);
  EXPECT_EQ(t.grid.nx, 64);
  EXPECT_EQ(t.grid.ny, 64);
  EXPECT_EQ(t.grid.dx[0], 10.0);
  EXPECT_EQ(t.bed.size(), 64u * 64u);
  EXPECT_TRUE(t.mask.empty());
  EXPECT_NE(t.source.find("synthetic:ridged"), std::string::npos);
  EXPECT_NE(t.source.find("seed=5"), std::string::npos);
  std::printf("  source: %s\n", t.source.c_str());
  t.grid.validate();
  EXPECT_EQ(t.bed, erodem::generate_terrain(SynthKind::ridged, 64, 64, 10.0, 100.0, 5));

  dem.cell_size = 2.5;
  dem.relief = 30.0;
  const auto t2 = erodem::make_synthetic_terrain(dem);
  EXPECT_EQ(t2.grid.dx[0], 2.5);
  EXPECT_EQ(*std::max_element(t2.bed.begin(), t2.bed.end()), 30.0);

  dem.synthetic = "mountain";
  EXPECT_EQ(code_of([&] { erodem::make_synthetic_terrain(dem); }), ExitCode::config);
  dem.synthetic = "fbm";
  dem.size = 0;
  EXPECT_EQ(code_of([&] { erodem::make_synthetic_terrain(dem); }), ExitCode::config);
}

// ---- raster I/O ------------------------------------------------------------------------

TEST(Raster, Sha256KnownVectors) {
  EXPECT_EQ(erodem::io::sha256_hex("", 0),
            "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(erodem::io::sha256_hex("abc", 3),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  const std::string s = "abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq";
  EXPECT_EQ(erodem::io::sha256_hex(s.data(), s.size()),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  const std::string m(1000000, 'a');
  EXPECT_EQ(erodem::io::sha256_hex(m.data(), m.size()),
            "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

TEST(Raster, GeoTiffRoundTrip) {
  erodem::test::TempDir dir;
  // A projected grid with a real CRS and an odd origin.
  erodem::Grid g = erodem::Grid::uniform(37, 23, 30.0);
  g.georef.transform = {376313.655454263, 30.0, 0.0, 3807917.82762838, 0.0, -30.0};
  g.georef.has_transform = true;
  erodem::Params::Dem crs_dem;  // borrow the CRS of the Big Tujunga DEM
  crs_dem.path = kTujunga;
  g.georef.crs_wkt = erodem::io::read_dem(crs_dem).grid.georef.crs_wkt;
  ASSERT_FALSE(g.georef.crs_wkt.empty());

  std::vector<float> v(g.cells());
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = 100.0f + 0.37f * static_cast<float>(i);
  v[5] = std::numeric_limits<float>::quiet_NaN();
  const std::string out = dir.file("bed.tif");
  erodem::io::write_geotiff(out, g, v, "bed elevation (m)");
  // Nothing else is left in the directory (no temporary file, no .aux.xml).
  EXPECT_EQ(std::distance(fs::directory_iterator(dir.path), fs::directory_iterator()), 1);

  erodem::Params::Dem dem;
  dem.path = out;
  const auto t = erodem::io::read_dem(dem);
  EXPECT_EQ(t.grid.nx, 37);
  EXPECT_EQ(t.grid.ny, 23);
  EXPECT_EQ(t.grid.georef.transform, g.georef.transform);
  EXPECT_TRUE(t.grid.georef.has_transform);
  EXPECT_FALSE(t.grid.georef.is_geographic);
  EXPECT_NE(t.grid.georef.crs_wkt.find("UTM zone 11N"), std::string::npos);
  EXPECT_EQ(t.grid.dx[0], 30.0);
  EXPECT_EQ(t.grid.dy[0], 30.0);
  EXPECT_EQ(t.grid.area[0], 900.0);
  ASSERT_EQ(t.mask.size(), v.size());
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (i == 5) {
      EXPECT_EQ(t.mask[i], 0);
      EXPECT_TRUE(std::isnan(t.bed[i]));
    } else {
      EXPECT_EQ(t.mask[i], 1);
      EXPECT_EQ(t.bed[i], static_cast<double>(v[i])) << i;
    }
  }
  EXPECT_EQ(t.source_sha256.size(), 64u);
  EXPECT_EQ(t.source_sha256, erodem::io::file_sha256(out));

  // Overwriting an existing file replaces it whole.
  std::vector<float> w(g.cells(), 7.0f);
  erodem::io::write_geotiff(out, g, w, "constant");
  const auto t2 = erodem::io::read_dem(dem);
  EXPECT_TRUE(t2.mask.empty());
  EXPECT_EQ(t2.bed[5], 7.0);
  EXPECT_NE(t2.source_sha256, t.source_sha256);

  // The same file as a parameter raster on the grid, and with a window.
  const auto p = erodem::io::read_raster_on_grid(out, t.grid, std::nullopt, "flow.manning_n");
  EXPECT_EQ(p.size(), g.cells());
  erodem::Grid sub = erodem::Grid::uniform(10, 5, 30.0);
  sub.georef = t.grid.georef;
  sub.georef.transform[0] += 3 * 30.0;
  sub.georef.transform[3] -= 2 * 30.0;
  EXPECT_EQ(
      erodem::io::read_raster_on_grid(out, sub, std::array<int, 4>{3, 2, 10, 5}, "rain.raster")
          .size(),
      50u);
  std::string msg;
  EXPECT_EQ(
      code_of([&] { erodem::io::read_raster_on_grid(out, sub, std::nullopt, "erosion.hardness"); },
              &msg),
      ExitCode::data);
  EXPECT_NE(msg.find("erosion.hardness"), std::string::npos);
  EXPECT_NE(msg.find("37 x 23"), std::string::npos);
  EXPECT_NE(msg.find("10 x 5"), std::string::npos);
  // Same size but shifted: the geotransforms disagree.
  erodem::Grid shifted_grid = t.grid;
  shifted_grid.georef.transform[0] += 30.0;
  EXPECT_EQ(code_of([&] {
              erodem::io::read_raster_on_grid(out, shifted_grid, std::nullopt, "rain.raster");
            }),
            ExitCode::data);
  EXPECT_EQ(code_of([&] {
              erodem::io::read_raster_on_grid(dir.file("none.tif"), t.grid, std::nullopt,
                                              "rain.raster");
            }),
            ExitCode::no_input);
}

TEST(Raster, SyntheticTerrainRoundTripWithoutCrs) {
  erodem::test::TempDir dir;
  erodem::Params::Dem sdem;
  sdem.synthetic = "lake";
  sdem.size = 33;
  const auto t = erodem::make_synthetic_terrain(sdem);
  std::vector<float> v(t.bed.begin(), t.bed.end());
  const std::string out = dir.file("lake.tif");
  erodem::io::write_geotiff(out, t.grid, v, "synthetic lake", -9999.0);
  erodem::Params::Dem dem;
  dem.path = out;
  const auto r = erodem::io::read_dem(dem);  // no CRS, but erodem's metre tag: no cell_size
  EXPECT_EQ(r.grid.georef.transform, t.grid.georef.transform);
  EXPECT_EQ(r.grid.dx[0], 10.0);
  EXPECT_TRUE(r.grid.georef.crs_wkt.empty());
  EXPECT_TRUE(r.mask.empty());
  for (std::size_t i = 0; i < v.size(); ++i) ASSERT_EQ(r.bed[i], static_cast<double>(v[i]));
}

TEST(Raster, WriteFailures) {
  erodem::test::TempDir dir;
  const erodem::Grid g = erodem::Grid::uniform(4, 3, 1.0);
  std::vector<float> v(12, 1.0f);
  EXPECT_EQ(code_of([&] { erodem::io::write_geotiff(dir.file("no/such/dir/x.tif"), g, v, "x"); }),
            ExitCode::cant_create);
  EXPECT_EQ(
      code_of([&] { erodem::io::write_geotiff(dir.file("x.tif"), g, std::vector<float>(5), "x"); }),
      ExitCode::internal);
  // The target is a directory: the rename fails, and the temporary file is removed.
  fs::create_directories(dir.path / "taken.tif" / "inner");
  EXPECT_EQ(code_of([&] { erodem::io::write_geotiff(dir.file("taken.tif"), g, v, "x"); }),
            ExitCode::cant_create);
  int entries = 0;
  for (const auto& e : fs::directory_iterator(dir.path)) {
    ++entries;
    std::printf("  left: %s\n", e.path().filename().string().c_str());
  }
  EXPECT_EQ(entries, 1);  // only taken.tif/
}

TEST(Raster, VolcanoNeedsCellSize) {
  erodem::Params::Dem dem;
  dem.path = kVolcano;
  std::string msg;
  EXPECT_EQ(code_of([&] { erodem::io::read_dem(dem); }, &msg), ExitCode::config);
  EXPECT_NE(msg.find("no georeferencing"), std::string::npos);
  EXPECT_NE(msg.find("dem.cell_size"), std::string::npos);

  dem.cell_size = 10.0;
  const auto t = erodem::io::read_dem(dem);
  const Range r = range_of(t);
  std::printf("  volcano: %d x %d, %.3f .. %.3f m, cell %.1f m, sha256 %s\n", t.grid.nx, t.grid.ny,
              r.lo, r.hi, t.grid.dx[0], t.source_sha256.c_str());
  EXPECT_EQ(t.grid.nx, 87);
  EXPECT_EQ(t.grid.ny, 61);
  EXPECT_EQ(r.lo, 94.0);
  EXPECT_EQ(r.hi, 195.0);
  EXPECT_TRUE(t.mask.empty());
  EXPECT_FALSE(t.grid.georef.has_transform);
  EXPECT_EQ(t.grid.dx[0], 10.0);
  EXPECT_EQ(t.grid.area[60], 100.0);
  EXPECT_EQ(t.source, kVolcano);
  EXPECT_EQ(t.source_sha256.size(), 64u);

  // A CRS for it, given by the user.
  dem.crs = "EPSG:32760";
  const auto tc = erodem::io::read_dem(dem);
  EXPECT_NE(tc.grid.georef.crs_wkt.find("UTM zone 60S"), std::string::npos);
  dem.crs = "EPSG:4326";
  EXPECT_EQ(code_of([&] { erodem::io::read_dem(dem); }), ExitCode::config);
  dem.crs = "not a crs";
  EXPECT_EQ(code_of([&] { erodem::io::read_dem(dem); }), ExitCode::config);

  // z_scale and a window.
  dem.crs.clear();
  dem.z_scale = 0.5;
  dem.window = std::array<int, 4>{10, 5, 20, 30};
  const auto tw = erodem::io::read_dem(dem);
  EXPECT_EQ(tw.grid.nx, 20);
  EXPECT_EQ(tw.grid.ny, 30);
  EXPECT_EQ(tw.bed[0], 0.5 * t.bed[5 * 87 + 10]);
}

TEST(Raster, BigTujungaProjectedWithWindow) {
  erodem::Params::Dem dem;
  dem.path = kTujunga;
  const auto t = erodem::io::read_dem(dem);
  const Range r = range_of(t);
  std::printf("  big tujunga: %d x %d, %.1f .. %.1f m, %zu valid of %zu, dx %.3f m, x0 %.6f\n",
              t.grid.nx, t.grid.ny, r.lo, r.hi, r.valid, t.bed.size(), t.grid.dx[0],
              t.grid.georef.transform[0]);
  EXPECT_EQ(t.grid.nx, 1197);
  EXPECT_EQ(t.grid.ny, 643);
  EXPECT_EQ(r.lo, 315.0);
  EXPECT_EQ(r.hi, 2295.0);
  EXPECT_TRUE(t.grid.georef.has_transform);
  EXPECT_FALSE(t.grid.georef.is_geographic);
  EXPECT_NE(t.grid.georef.crs_wkt.find("UTM zone 11N"), std::string::npos);
  EXPECT_DOUBLE_EQ(t.grid.dx[0], 30.0);
  EXPECT_DOUBLE_EQ(t.grid.dy[0], 30.0);
  EXPECT_NEAR(t.grid.georef.transform[0], 376313.655454263, 1e-6);
  EXPECT_NEAR(t.grid.georef.transform[3], 3807917.82762838, 1e-6);

  dem.window = std::array<int, 4>{100, 50, 200, 120};
  const auto w = erodem::io::read_dem(dem);
  EXPECT_EQ(w.grid.nx, 200);
  EXPECT_EQ(w.grid.ny, 120);
  EXPECT_DOUBLE_EQ(w.grid.georef.transform[0], t.grid.georef.transform[0] + 100 * 30.0);
  EXPECT_DOUBLE_EQ(w.grid.georef.transform[3], t.grid.georef.transform[3] - 50 * 30.0);
  for (int row = 0; row < 120; row += 17)
    for (int col = 0; col < 200; col += 13)
      ASSERT_EQ(w.bed[row * 200 + col], t.bed[(row + 50) * 1197 + col + 100]);
  // The windowed grid locates CRS points like the full one.
  const auto centre = w.grid.cell_center(7, 9);
  int c = -1, rr = -1;
  ASSERT_TRUE(t.grid.locate(centre[0], centre[1], c, rr));
  EXPECT_EQ(c, 107);
  EXPECT_EQ(rr, 59);

  std::string msg;
  dem.window = std::array<int, 4>{1100, 0, 200, 100};
  EXPECT_EQ(code_of([&] { erodem::io::read_dem(dem); }, &msg), ExitCode::data);
  EXPECT_NE(msg.find("[1100, 0, 200, 100]"), std::string::npos);
  EXPECT_NE(msg.find("1197 x 643"), std::string::npos);
  dem.window = std::array<int, 4>{-1, 0, 10, 10};
  EXPECT_EQ(code_of([&] { erodem::io::read_dem(dem); }), ExitCode::data);
  dem.window = std::array<int, 4>{0, 0, 0, 10};
  EXPECT_EQ(code_of([&] { erodem::io::read_dem(dem); }), ExitCode::data);

  // A georeferenced file refuses cell_size / crs overrides.
  dem.window.reset();
  dem.cell_size = 10.0;
  EXPECT_EQ(code_of([&] { erodem::io::read_dem(dem); }), ExitCode::config);
}

TEST(Raster, NodataIsMasked) {
  // Big Tujunga declares nodata 32767 but has no such cell; write a copy of a window with
  // some nodata cells to check the masking path, with the same nodata value.
  erodem::test::TempDir dir;
  erodem::Params::Dem dem;
  dem.path = kTujunga;
  dem.window = std::array<int, 4>{0, 0, 50, 40};
  const auto t = erodem::io::read_dem(dem);
  EXPECT_TRUE(t.mask.empty());  // every cell valid: the mask stays empty
  std::vector<float> v(t.bed.begin(), t.bed.end());
  for (int i = 0; i < 50; ++i) v[static_cast<std::size_t>(i) * 37 % v.size()] = 32767.0f;
  const std::string out = dir.file("holes.tif");
  erodem::io::write_geotiff(out, t.grid, v, "with holes", 32767.0);
  erodem::Params::Dem d2;
  d2.path = out;
  const auto h = erodem::io::read_dem(d2);
  ASSERT_EQ(h.mask.size(), v.size());
  std::size_t masked = 0;
  for (std::size_t i = 0; i < v.size(); ++i) {
    const bool hole = v[i] == 32767.0f;
    masked += hole;
    EXPECT_EQ(h.mask[i], hole ? 0 : 1);
    EXPECT_EQ(h.active(i), !hole);
    if (hole) {
      EXPECT_TRUE(std::isnan(h.bed[i]));
    }
  }
  const Range r = range_of(h);
  std::printf("  nodata 32767: %zu cells masked, valid range %.1f .. %.1f m\n", masked, r.lo, r.hi);
  EXPECT_GT(masked, 40u);
  EXPECT_LT(r.hi, 32767.0);
}

TEST(Raster, MissingAndBadFiles) {
  erodem::test::TempDir dir;
  erodem::Params::Dem dem;
  dem.path = dir.file("does_not_exist.tif");
  std::string msg;
  EXPECT_EQ(code_of([&] { erodem::io::read_dem(dem); }, &msg), ExitCode::no_input);
  EXPECT_NE(msg.find("does_not_exist.tif"), std::string::npos);

  dem.path = dir.file("garbage.tif");
  std::ofstream(dem.path) << "this is not a raster\n";
  EXPECT_EQ(code_of([&] { erodem::io::read_dem(dem); }, &msg), ExitCode::data);
  EXPECT_NE(msg.find("garbage.tif"), std::string::npos);

  dem.path.clear();
  EXPECT_EQ(code_of([&] { erodem::io::read_dem(dem); }), ExitCode::config);
}

TEST(Raster, PugetSoundPng) {
  erodem::Params::Dem dem;
  dem.path = kPuget;
  EXPECT_EQ(code_of([&] { erodem::io::read_dem(dem); }), ExitCode::config);
  dem.z_scale = 0.1;
  dem.cell_size = 160.0;
  const auto t = erodem::io::read_dem(dem);
  const Range r = range_of(t);
  std::printf("  puget sound: %d x %d, %.3f .. %.3f m, cell %.0f m\n", t.grid.nx, t.grid.ny, r.lo,
              r.hi, t.grid.dx[0]);
  EXPECT_EQ(t.grid.nx, 1025);
  EXPECT_EQ(t.grid.ny, 1025);
  EXPECT_NEAR(r.hi, 4379.8, 1e-6);
  EXPECT_EQ(r.lo, 0.0);
  EXPECT_EQ(t.grid.dx[0], 160.0);
  EXPECT_EQ(t.grid.area[0], 25600.0);
  EXPECT_TRUE(t.mask.empty());
}

// dem.nodata_value: the sea stored as 0 becomes nodata (so it can be held at sea level).
TEST(Raster, NodataValueMasksTheSea) {
  erodem::Params::Dem dem;
  dem.path = kPuget;
  dem.z_scale = 0.1;
  dem.cell_size = 160.0;
  dem.nodata_value = 0.0;
  const auto t = erodem::io::read_dem(dem);
  std::size_t masked = 0;
  double lowest = HUGE_VAL;
  for (std::size_t i = 0; i < t.bed.size(); ++i) {
    if (!t.active(i))
      ++masked;
    else
      lowest = std::min(lowest, t.bed[i]);
  }
  std::printf("  puget sound with nodata_value 0: %zu cells masked, lowest land %.3f m\n", masked,
              lowest);
  EXPECT_EQ(masked, 39421u);  // the cells stored as 0
  EXPECT_GT(lowest, 0.0);
}

// dem.resample: block averages over the valid cells only; an all-nodata block stays nodata;
// parameter rasters average over the same cells; cell size and transform scale.
TEST(Raster, CoarsenAveragesValidCells) {
  erodem::Terrain fine;
  fine.grid = erodem::Grid::uniform(4, 4, 10.0);
  fine.bed = {1, 2, 10, 10,  //
              3, 4, 10, 10,  //
              5, 5, 0,  0,   //
              5, 5, 0,  0};
  fine.mask.assign(16, 1);
  fine.mask[0] = 0;                                             // 1 m cell is nodata
  for (std::size_t k : {10u, 11u, 14u, 15u}) fine.mask[k] = 0;  // whole block nodata
  fine.manning_n.assign(16, 0.02);
  fine.manning_n[1] = 0.05;
  const auto c = erodem::io::coarsen(fine, 2);
  std::printf("  coarsened beds: %.4f %.4f %.4f %s\n", c.bed[0], c.bed[1], c.bed[2],
              c.active(3) ? "active" : "nodata");
  ASSERT_EQ(c.grid.nx, 2);
  ASSERT_EQ(c.grid.ny, 2);
  EXPECT_DOUBLE_EQ(c.bed[0], 3.0);  // (2 + 3 + 4) / 3: the nodata cell is left out
  EXPECT_DOUBLE_EQ(c.bed[1], 10.0);
  EXPECT_DOUBLE_EQ(c.bed[2], 5.0);
  EXPECT_FALSE(c.active(3));
  EXPECT_DOUBLE_EQ(c.manning_n[0], (0.05 + 0.02 + 0.02) / 3);
  EXPECT_DOUBLE_EQ(c.grid.dx[0], 20.0);
  EXPECT_DOUBLE_EQ(c.grid.area[0], 400.0);
  EXPECT_DOUBLE_EQ(c.grid.georef.transform[1], 20.0);
}
