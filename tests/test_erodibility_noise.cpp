// Tests of the erodibility noise (erosion.hardness = "noise", issue 17): the field's range,
// seed and scale in metres (fbm_field, hardness_noise), that a uniform plane erodes unevenly
// under it, and that every backend is handed the same bits.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "erodem/backends.hpp"
#include "erodem/error.hpp"
#include "erodem/terrain_synth.hpp"
#include "scenarios.hpp"

namespace erodem::test {
namespace {

/// Erosion parameters with hardness "noise" of amplitude `a` and first wavelength `scale` m.
Params::Erosion noise_erosion(double a, double scale, int seed = 1) {
  Params::Erosion e;
  e.hardness_noise = true;
  e.noise_amplitude = a;
  e.noise_scale = scale;
  e.noise_seed = seed;
  return e;
}

/// Makes every cell of `t` active but a nodata disc of `radius` cells around (col, row).
void mask_disc(Terrain& t, double col, double row, double radius) {
  const int nx = t.grid.nx, ny = t.grid.ny;
  t.mask.assign(t.grid.cells(), 1);
  for (int r = 0; r < ny; ++r)
    for (int c = 0; c < nx; ++c)
      if (std::hypot(c - col, r - row) < radius) t.mask[static_cast<std::size_t>(r) * nx + c] = 0;
}

bool same_bits(const std::vector<double>& a, const std::vector<double>& b) {
  // (no memcmp of empty vectors: their data() may be null, which memcmp must not get)
  return a.size() == b.size() &&
         (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0);
}

TEST(ErodibilityNoise, FieldSpansOneMinusAmplitudeToOne) {
  // 96 x 64 cells of 10 m, a third of them nodata (a disc in the middle): over the active
  // cells R must lie in [1 - a, 1] and reach both ends exactly (the minimum of the fBm maps
  // to n = 0, R = 1 - a; the maximum to n = 1, R = 1); nodata cells hold 1.
  Terrain t = flat_terrain(96, 64, 10.0);
  mask_disc(t, 48.0, 32.0, 26.0);
  const double a = 0.3;
  const auto R = hardness_noise(t, noise_erosion(a, 200.0));
  ASSERT_EQ(R.size(), t.grid.cells());
  double lo = 2, hi = -1;
  std::size_t inactive = 0;
  for (std::size_t i = 0; i < R.size(); ++i) {
    if (!t.active(i)) {
      EXPECT_EQ(R[i], 1.0) << i;
      ++inactive;
      continue;
    }
    lo = std::min(lo, R[i]);
    hi = std::max(hi, R[i]);
  }
  std::printf("[hardness noise] a = %.2f: R over %zu active cells in [%.17g, %.17g]\n", a,
              R.size() - inactive, lo, hi);
  EXPECT_GT(inactive, 1000u);
  EXPECT_EQ(lo, 1.0 - a);
  EXPECT_EQ(hi, 1.0);
  // Amplitude 0: uniform 1, the same as the default hardness.
  for (double v : hardness_noise(t, noise_erosion(0.0, 200.0))) ASSERT_EQ(v, 1.0);
}

TEST(ErodibilityNoise, SeedGivesTheSameBitsAndAnotherSeedAnotherField) {
  const Terrain t = flat_terrain(80, 50, 10.0);
  const auto a = hardness_noise(t, noise_erosion(0.5, 300.0, 7));
  const auto b = hardness_noise(t, noise_erosion(0.5, 300.0, 7));
  const auto c = hardness_noise(t, noise_erosion(0.5, 300.0, 8));
  EXPECT_TRUE(same_bits(a, b));
  std::size_t differ = 0;
  for (std::size_t i = 0; i < a.size(); ++i) differ += a[i] != c[i];
  std::printf("[hardness noise] seeds 7 and 8: %zu of %zu cells differ\n", differ, a.size());
  // Independent fields agree only where both reach an end of the range (one cell each).
  EXPECT_GT(differ, a.size() - 4);
}

TEST(ErodibilityNoise, PatternIsInMetresNotCells) {
  // 1. Cells of 10 m with noise_scale 500 m, and cells of 20 m with 1000 m, on the same
  //    90 x 60 cells: each cell centre lies at the same fraction of a wavelength (the
  //    positions and 1 / scale differ by exact factors of 2), so the fields are bit-identical.
  const Terrain fine = flat_terrain(90, 60, 10.0);
  const auto r10 = hardness_noise(fine, noise_erosion(0.5, 500.0));
  const auto r20 = hardness_noise(flat_terrain(90, 60, 20.0), noise_erosion(0.5, 1000.0));
  EXPECT_TRUE(same_bits(r10, r20));
  // 2. The same 900 x 600 m at 10 m and at 30 m cells, one noise_scale (250 m): the centre of
  //    coarse cell (k, l) is the centre of fine cell (3k + 1, 3l + 1), both (30k + 15 m,
  //    30l + 15 m) exactly, and the unnormalised fBm must be the same there, bit for bit.
  const Grid coarse = Grid::uniform(30, 20, 30.0);
  const auto f = fbm_field(fine.grid, 250.0, 5, 3), g = fbm_field(coarse, 250.0, 5, 3);
  std::size_t equal = 0;
  for (int l = 0; l < 20; ++l)
    for (int k = 0; k < 30; ++k)
      equal += g[static_cast<std::size_t>(l) * 30 + k] ==
               f[static_cast<std::size_t>(3 * l + 1) * 90 + 3 * k + 1];
  EXPECT_EQ(equal, coarse.cells());
  // 3. And the scale matters: noise_scale 250 m is another field than 500 m.
  EXPECT_FALSE(same_bits(r10, hardness_noise(fine, noise_erosion(0.5, 250.0))));
}

TEST(ErodibilityNoise, OutOfRangeSettingsNameTheirKey) {
  const Terrain t = flat_terrain(8, 8, 10.0);
  auto message = [&](const Params::Erosion& e) {
    try {
      hardness_noise(t, e);
    } catch (const Error& err) {
      EXPECT_EQ(err.code(), ExitCode::config);
      return std::string(err.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message(noise_erosion(1.5, 500.0)).find("erosion.noise_amplitude"), std::string::npos);
  EXPECT_NE(message(noise_erosion(0.5, 0.0)).find("erosion.noise_scale"), std::string::npos);
  Params::Erosion e = noise_erosion(0.5, 500.0);
  e.noise_octaves = 17;
  EXPECT_NE(message(e).find("erosion.noise_octaves"), std::string::npos);
}

// ---- a uniform plane under rain ---------------------------------------------------------

/// A plane of 64 x 32 cells of 10 m falling eastwards at slope 0.02 to an open east edge
/// (closed elsewhere), 0.02 m of water to start and 100 mm/h of rain; local inertial,
/// n = 0.03, steps of 0.5 s. Erosion with K_s = 1e-3 1/s: the adaptation length u / (K_s R)
/// (~0.3 m/s / 1e-3 1/s = 300 m and more) is of the plane's length, so the suspended load
/// stays well under the capacity and the erosion rate K_s R (C - s) follows R: the
/// detachment-limited regime, in which hardness matters most.
Params plane_params(bool noise) {
  Params p = quiet_params(FlowScheme::local_inertial, 0.5);
  p.flow.manning_n.value = 0.03;
  p.boundary.east = BoundaryKind::open;
  p.rain.rate = 0.1 / 3600.0;
  p.erosion.enabled = true;
  p.erosion.dissolving_rate = 1e-3;
  p.erosion.hardness_noise = noise;
  p.erosion.noise_scale = 160.0;
  return p;
}

Terrain plane_terrain() {
  Terrain t = flat_terrain(64, 32, 10.0);
  for (int r = 0; r < 32; ++r)
    for (int c = 0; c < 64; ++c) t.bed[static_cast<std::size_t>(r) * 64 + c] = 0.02 * (64 - c) * 10;
  t.water_depth.assign(t.grid.cells(), 0.02);
  return t;
}

/// The mean over the columns c in [c0, nx) of the standard deviation across the rows (the
/// slope) of `f`, divided by the mean over those columns of |mean across the rows|.
double cross_slope_variation(const std::vector<double>& f, int nx, int ny, int c0) {
  double spread = 0, level = 0;
  for (int c = c0; c < nx; ++c) {
    double sum = 0, sum2 = 0;
    for (int r = 0; r < ny; ++r) sum += f[static_cast<std::size_t>(r) * nx + c];
    const double mean = sum / ny;
    for (int r = 0; r < ny; ++r) {
      const double d = f[static_cast<std::size_t>(r) * nx + c] - mean;
      sum2 += d * d;
    }
    spread += std::sqrt(sum2 / ny);
    level += std::abs(mean);
  }
  return spread / level;
}

TEST(ErodibilityNoise, UniformPlaneErodesUnevenly) {
  // 1,200 steps (600 s) on cpu_float64, once with hardness 1 and once with "noise" (a = 0.5,
  // 160 m). Measured away from the top 8 columns (the divide, where the water is thinnest):
  // - hardness 1: every row computes the same operations on the same numbers (no flow
  //   crosses a row, the walls are closed), so the erosion is uniform across the slope to
  //   rounding: bound 1e-12 relative.
  // - noise: in the detachment-limited regime (plane_params) the erosion of a cell is
  //   K_s R (C - s) dt summed over the steps, i.e. proportional to R to first order; its
  //   cross-slope variation must then be close to R's own (std / mean across the rows,
  //   measured on the same columns). Bound: at least half of R's (the suspended load and
  //   transport smooth it somewhat; a solver that ignored the field would give 0).
  const int nx = 64, ny = 32, c0 = 8;
  const Target cpu{"cpu", Precision::float64};
  auto uniform = make_simulation(plane_terrain(), plane_params(false), cpu);
  auto noisy = make_simulation(plane_terrain(), plane_params(true), cpu);
  uniform.step(1200);
  noisy.step(1200);
  const double v_uniform = cross_slope_variation(uniform.field(FieldId::erosion), nx, ny, c0);
  const double v_noise = cross_slope_variation(noisy.field(FieldId::erosion), nx, ny, c0);
  const double v_hardness = cross_slope_variation(noisy.field(FieldId::hardness), nx, ny, c0);
  const auto e = noisy.field(FieldId::erosion);
  double eroded = 0;
  for (double v : e) eroded += v * 100.0;
  std::printf(
      "[hardness noise] plane, 600 s: cross-slope std / mean of the erosion: hardness 1 %.3g "
      "(bound 1e-12), noise %.3f (bound > %.3f = half of R's %.3f); eroded %.4g m^3\n",
      v_uniform, v_noise, 0.5 * v_hardness, v_hardness, eroded);
  EXPECT_LT(v_uniform, 1e-12);
  EXPECT_GT(v_hardness, 0.05);
  EXPECT_GT(v_noise, 0.5 * v_hardness);
  EXPECT_GT(eroded, 0.0);
}

TEST(ErodibilityNoise, EveryBackendIsHandedTheSameField) {
  // The field is computed once on the host in double and handed to the backends like a
  // raster: cpu_float64 holds hardness_noise()'s values exactly, cpu_float32 and OpenCL
  // (float32) their float roundings, and those two agree bit for bit.
  const Terrain t = plane_terrain();
  const Params p = plane_params(true);
  const auto host = hardness_noise(t, p.erosion);
  const auto f64 = make_simulation(t, p, {"cpu", Precision::float64}).field(FieldId::hardness);
  const auto f32 = make_simulation(t, p, {"cpu", Precision::float32}).field(FieldId::hardness);
  EXPECT_TRUE(same_bits(f64, host));
  std::vector<double> rounded(host.size());
  for (std::size_t i = 0; i < host.size(); ++i) rounded[i] = static_cast<float>(host[i]);
  EXPECT_TRUE(same_bits(f32, rounded));
  if (!opencl_available()) GTEST_SKIP() << "no OpenCL device";
  const auto ocl = make_simulation(t, p, {"opencl", Precision::float32}).field(FieldId::hardness);
  EXPECT_TRUE(same_bits(ocl, f32));
  std::printf("[hardness noise] cpu_float64 = host, cpu_float32 = opencl = host in float: %s\n",
              same_bits(ocl, f32) ? "bit for bit" : "NO");
}

TEST(ErodibilityNoise, RowsAreThoseOfTheWholeFieldHoldingNoWholeField) {
  // An MPI band builds its hardness noise for its rows only (hardness_noise_rows), the range
  // of the whole grid's active cells found a block of 256 rows at a time. Reference: the
  // whole field scaled here, as hardness_noise did before (fbm_field, the range of the active
  // cells, R = 1 - a (1 - n)). 40 x 600 cells (three blocks), a nodata disc across the first
  // block boundary, so the range depends on rows of every block; rows taken inside a block,
  // across both boundaries, at the edges and none. A range taken from the asked rows only
  // (what a band would see alone) gives other bits: checked below.
  Terrain t = flat_terrain(40, 600, 10.0);
  mask_disc(t, 20.0, 256.0, 15.0);
  const Params::Erosion e = noise_erosion(0.4, 150.0, 3);
  std::vector<double> whole =
      fbm_field(t.grid, e.noise_scale, e.noise_octaves, static_cast<std::uint64_t>(e.noise_seed));
  double lo = INFINITY, hi = -INFINITY;
  for (std::size_t i = 0; i < whole.size(); ++i)
    if (t.active(i)) lo = std::min(lo, whole[i]), hi = std::max(hi, whole[i]);
  for (std::size_t i = 0; i < whole.size(); ++i) {
    const double n = t.active(i) ? (whole[i] - lo) / (hi - lo) : 1.0;
    whole[i] = 1.0 - e.noise_amplitude * (1.0 - std::min(1.0, std::max(0.0, n)));
  }
  ASSERT_TRUE(same_bits(hardness_noise(t, e), whole));
  int differ = 0;
  for (const auto& [r0, r1] : std::vector<std::pair<int, int>>{
           {0, 600}, {10, 100}, {200, 300}, {255, 257}, {250, 520}, {599, 600}, {0, 1}, {7, 7}}) {
    const std::vector<double> rows = hardness_noise_rows(t, e, r0, r1);
    const std::vector<double> expected(whole.begin() + r0 * 40, whole.begin() + r1 * 40);
    if (!same_bits(rows, expected)) ++differ;
    EXPECT_TRUE(same_bits(rows, expected)) << "rows [" << r0 << ", " << r1 << ")";
    const std::vector<double> fbm = fbm_rows(t.grid, e.noise_scale, e.noise_octaves,
                                             static_cast<std::uint64_t>(e.noise_seed), r0, r1);
    const std::vector<double> all =
        fbm_field(t.grid, e.noise_scale, e.noise_octaves, static_cast<std::uint64_t>(e.noise_seed));
    EXPECT_TRUE(same_bits(fbm, std::vector<double>(all.begin() + r0 * 40, all.begin() + r1 * 40)))
        << "fbm rows [" << r0 << ", " << r1 << ")";
  }
  std::printf("[hardness noise] rows of the whole field: %d of 8 ranges differ\n", differ);
  // the range of rows 10 .. 100 alone is narrower than the grid's: other values there
  double band_lo = INFINITY, band_hi = -INFINITY;
  const std::vector<double> all =
      fbm_field(t.grid, e.noise_scale, e.noise_octaves, static_cast<std::uint64_t>(e.noise_seed));
  for (std::size_t i = 400; i < 4000; ++i)
    band_lo = std::min(band_lo, all[i]), band_hi = std::max(band_hi, all[i]);
  std::printf(
      "[hardness noise] fBm range of the grid's active cells [%.6g, %.6g], of rows 10 .. 100 "
      "[%.6g, %.6g]\n",
      lo, hi, band_lo, band_hi);
  EXPECT_TRUE(band_lo > lo || band_hi < hi);
  EXPECT_THROW(hardness_noise_rows(t, e, -1, 5), Error);
  EXPECT_THROW(hardness_noise_rows(t, e, 5, 601), Error);
}

}  // namespace
}  // namespace erodem::test
