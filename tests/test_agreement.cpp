// erodem — agreement of the OpenCL backend with the CPU reference (MODEL.md "Precision and
// agreement between backends"): 1,000 steps of a full erosion run on a crop of a real DEM,
// in float32 on both, every field compared by relative L2 difference (bound 1e-5).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "erodem/backends.hpp"
#include "erodem/io/compare.hpp"
#include "erodem/io/raster.hpp"
#include "erodem/simulation.hpp"
#include "scenarios.hpp"
#ifdef ERODEM_HAVE_OPENCL
#include "opencl/opencl_backend.hpp"
#endif

namespace erodem::test {
namespace {

const std::string kTujunga = tujunga_path();

struct AgreementCase {
  std::string name;
  FlowScheme flow;
  TransportScheme transport;
  bool adaptive;
  double dt;      ///< s: the fixed step, or the upper bound of the adaptive one
  int order = 1;  ///< flow.order (shallow water)
  ErosionLaw law = ErosionLaw::mei;
  bool infiltration = false;  ///< Green-Ampt on a loam with a 0.2 m soil (its recovery too)
  /// a snow pack above 1200 m (a 200 m band, slopes below 30 degrees) under a warming series
  /// T_ref(t) at 1000 m: snowfall, rain on snow, melt, liquid water and sliding above 40
  /// degrees at once
  bool snow = false;
  /// terrain classes every 20 steps (snow above 1400 m, rock above 0.7 m/m, mud and water where
  /// the storm stays) whose tables give Manning n, erodibility, talus angles and K_sat
  bool classes = false;
};

Params agreement_params(const AgreementCase& c) {
  Params p = tujunga_storm(c.flow, c.transport, c.adaptive, c.dt, Precision::float32);
  p.flow.order = c.order;
  p.erosion.law = c.law;
  p.infiltration.enabled = c.infiltration;
  p.infiltration.ksat.value = 5e-3 / 3600.0;  // 5 mm/h: part of the storm soaks in
  p.infiltration.soil_depth = ScalarOrRaster{0.2, {}};
  p.snow.enabled = c.snow;
  p.snow.initial.value = 0.05;
  p.snow.snow_line = 1200.0;
  p.snow.transition = 200.0;
  p.snow.max_slope = 30.0;
  p.snow.reference_elevation = 1000.0;
  p.snow.air_temperature_series = {{0.0, 2.0}, {2000.0, 12.0}};
  p.snow.melt_factor = 50e-3 / 86400.0;
  p.snow.slide_angle = 40.0;
  p.snow.slide_rate = 1e-3;
  auto& tc = p.terrain_classes;
  tc.enabled = c.classes;
  tc.interval = 20;
  tc.snow_line = 1400.0;
  tc.mud_wetness = 2e-3;
  tc.water_wetness = 0.05;
  tc.rock.manning_n = 0.03;
  tc.rock.erodibility = 0.2;
  tc.rock.talus_angle = 45.0;
  tc.rock.ksat = 1e-7;
  tc.mud.talus_angle = 25.0;
  tc.mud.manning_n = 0.05;
  tc.water.manning_n = 0.03;
  tc.snow.erodibility = 0.0;
  if (!c.classes) tc = Params::TerrainClasses{};
  return p;
}

class Agreement : public ::testing::TestWithParam<AgreementCase> {};

TEST_P(Agreement, OpenClMatchesCpuFloat32After1000Steps) {
  if (!opencl_available()) GTEST_SKIP() << "no OpenCL device";
  const AgreementCase& c = GetParam();
  const Params params = agreement_params(c);
  const Terrain terrain = io::read_dem(params.dem);
  Simulation cpu(terrain, params, make_backend("cpu", terrain, params));
  Simulation ocl(terrain, params, make_backend("opencl", terrain, params));
  std::printf("[agreement] %s: %d x %d cells of %s, on '%s' and '%s'\n", c.name.c_str(),
              terrain.grid.nx, terrain.grid.ny, kTujunga.c_str(), cpu.backend().device().c_str(),
              ocl.backend().device().c_str());
  for (int k = 0; k < 10; ++k) {
    cpu.step(100);
    ocl.step(100);
  }
  EXPECT_EQ(cpu.steps_done(), 1000);
  EXPECT_EQ(ocl.steps_done(), 1000);
  std::printf(
      "[agreement] %s: time %.6g s (cpu) %.6g s (opencl); max depth %.4g m, max speed "
      "%.4g m/s, water %.6g m^3, rain %.6g m^3, out %.6g m^3\n",
      c.name.c_str(), cpu.time(), ocl.time(), cpu.last_stats().max_depth,
      cpu.last_stats().max_speed, cpu.ledger().water, cpu.ledger().rain, cpu.ledger().boundary_out);
  EXPECT_NEAR(ocl.time(), cpu.time(), 1e-5 * cpu.time());
  const double bound = 1e-5;
  for (FieldId id :
       {FieldId::bed, FieldId::water_depth, FieldId::sediment, FieldId::velocity_x,
        FieldId::velocity_y, FieldId::flux_left, FieldId::flux_right, FieldId::flux_top,
        FieldId::flux_bottom, FieldId::wetness, FieldId::erosion, FieldId::soil_thickness,
        FieldId::infiltrated, FieldId::snow, FieldId::snow_liquid, FieldId::terrain_class,
        FieldId::manning_n, FieldId::hardness}) {
    const auto a = ocl.field(id), b = cpu.field(id);
    ASSERT_EQ(a.size(), b.size());
    // ||a - b|| / ||b|| (0 when both vanish) as `erodem compare` computes it; every cell
    // counts (a NaN on either side fails the test).
    const io::FieldDifference diff = io::field_difference(a, b, terrain.grid.nx);
    EXPECT_EQ(diff.cells, a.size()) << field_info(id).name;
    const double rel = diff.rel_l2;
    std::printf("[agreement] %s %-12s relative L2 %.3e (bound %.0e)\n", c.name.c_str(),
                field_info(id).name, rel, bound);
    EXPECT_LT(rel, bound) << field_info(id).name;
  }
  // The ledgers agree too.
  const auto& L = cpu.ledger();
  const auto& M = ocl.ledger();
  std::printf(
      "[agreement] %s ledger: water %.9g / %.9g, material %.12g / %.12g, "
      "boundary out %.6g / %.6g, closure %.3e / %.3e\n",
      c.name.c_str(), L.water, M.water, L.material, M.material, L.boundary_out, M.boundary_out,
      L.relative_closure_error(), M.relative_closure_error());
  EXPECT_NEAR(M.water, L.water, 1e-5 * L.water);
  EXPECT_NEAR(M.infiltrated, L.infiltrated, 1e-5 * L.infiltrated);
  for (double Ledger::*v :
       {&Ledger::snowfall, &Ledger::rain_on_snow, &Ledger::snow_melted, &Ledger::snow_runoff})
    EXPECT_NEAR(M.*v, L.*v, 1e-5 * L.*v);
  if (c.snow) {
    std::printf(
        "[agreement] %s snow: snowfall %.9g / %.9g, rain on snow %.9g / %.9g, melted %.9g / "
        "%.9g, runoff %.9g / %.9g m^3\n",
        c.name.c_str(), L.snowfall, M.snowfall, L.rain_on_snow, M.rain_on_snow, L.snow_melted,
        M.snow_melted, L.snow_runoff, M.snow_runoff);
    EXPECT_GT(L.snowfall, 0.0);
    EXPECT_GT(L.rain_on_snow, 0.0);
    EXPECT_GT(L.snow_melted, 0.0);
  }
  EXPECT_NEAR(M.material, L.material, 1e-6 * std::abs(L.material));
  EXPECT_NEAR(M.boundary_out, L.boundary_out, 1e-5 * std::abs(L.boundary_out) + 1e-9);

  // The statistics: the same maxima at the same cells.
  const FieldStats& S = cpu.last_stats();
  const FieldStats& T = ocl.last_stats();
  std::printf(
      "[agreement] %s stats: max depth %.9g m at cell %lld / %.9g m at %lld; max speed %.9g m/s "
      "at %lld / %.9g m/s at %lld\n",
      c.name.c_str(), S.max_depth, static_cast<long long>(S.max_depth_cell), T.max_depth,
      static_cast<long long>(T.max_depth_cell), S.max_speed,
      static_cast<long long>(S.max_speed_cell), T.max_speed,
      static_cast<long long>(T.max_speed_cell));
  EXPECT_EQ(T.max_depth_cell, S.max_depth_cell);
  EXPECT_EQ(T.max_speed_cell, S.max_speed_cell);
  EXPECT_NEAR(T.max_depth, S.max_depth, 1e-6 * S.max_depth);
  EXPECT_NEAR(T.max_speed, S.max_speed, 1e-6 * S.max_speed);
  EXPECT_EQ(T.bad_cell, -1);
  EXPECT_EQ(S.bad_cell, -1);
  // A state that is not physical is found at its cell, the first of two, by both.
  const std::int64_t nx = terrain.grid.nx, ny = terrain.grid.ny;
  const std::int64_t first = (ny / 2) * nx + nx / 3, second = (ny / 2) * nx + nx / 3 + 11;
  auto depth = cpu.field(FieldId::water_depth);
  depth[static_cast<std::size_t>(second)] = -1.0;
  depth[static_cast<std::size_t>(first)] = NAN;
  for (Simulation* sim : {&cpu, &ocl}) {
    sim->backend().set_field(FieldId::water_depth, depth);
    const FieldStats bad = sim->backend().stats();
    std::printf(
        "[agreement] %s stats on %s: first state not physical at cell %lld (expected %lld)\n",
        c.name.c_str(), sim->backend().name().c_str(), static_cast<long long>(bad.bad_cell),
        static_cast<long long>(first));
    EXPECT_EQ(bad.bad_cell, first) << sim->backend().name();
  }
}

// The statistics' maxima and first bad cell follow the CPU reference's rules also on states
// that are not physical (negative depths), on grids one to three cells wide, where a row has
// one work-group or several.
TEST(AgreementStats, MaximaAndBadCellOnStatesThatAreNotPhysical) {
  if (!opencl_available()) GTEST_SKIP() << "no OpenCL device";
  struct Case {
    int nx, ny;
    std::vector<double> depth, velocity_x;
  };
  const std::vector<Case> cases = {
      {1, 2, {-0.5, 0.0}, {0.0, 0.0}},
      {1, 3, {-0.7, -0.3, -0.2}, {-1.0, 2.0, -2.0}},
      {3, 1, {-0.2, -0.1, -0.3}, {0.5, -0.5, 0.25}},
      {3, 3, {0.1, -0.2, 0.4, 0.4, -0.1, 0.2, 0.0, 0.4, -0.3}, {1, -3, 3, 2, -2, 1, 0, 3, -3}},
  };
  for (const Case& c : cases) {
    const Terrain terrain = flat_terrain(c.nx, c.ny, 10.0);
    const Params params = quiet_params(FlowScheme::local_inertial, 0.1);
    std::vector<FieldStats> got;
    for (const char* backend : {"cpu", "opencl"}) {
      auto b = make_backend(backend, terrain, params);
      b->set_field(FieldId::water_depth, c.depth);
      b->set_field(FieldId::velocity_x, c.velocity_x);
      got.push_back(b->stats());
    }
    std::printf(
        "[agreement stats] %d x %d: max depth cell %lld / %lld (%.2f / %.2f m), max speed cell "
        "%lld / %lld (%.2f / %.2f m/s), bad cell %lld / %lld (cpu / opencl)\n",
        c.nx, c.ny, static_cast<long long>(got[0].max_depth_cell),
        static_cast<long long>(got[1].max_depth_cell), got[0].max_depth, got[1].max_depth,
        static_cast<long long>(got[0].max_speed_cell),
        static_cast<long long>(got[1].max_speed_cell), got[0].max_speed, got[1].max_speed,
        static_cast<long long>(got[0].bad_cell), static_cast<long long>(got[1].bad_cell));
    EXPECT_EQ(got[1].max_depth_cell, got[0].max_depth_cell) << c.nx << " x " << c.ny;
    EXPECT_EQ(got[1].max_speed_cell, got[0].max_speed_cell) << c.nx << " x " << c.ny;
    EXPECT_EQ(got[1].bad_cell, got[0].bad_cell) << c.nx << " x " << c.ny;
    EXPECT_EQ(got[1].max_depth, got[0].max_depth) << c.nx << " x " << c.ny;
    EXPECT_EQ(got[1].max_speed, got[0].max_speed) << c.nx << " x " << c.ny;
  }
}

// The same on rows long enough for the OpenCL kernel's 8-cell blocks and several work-groups
// per row, filled from small sets of values so that rows hold ties: equal depths (and -0
// beside +0), negative and NaN depths, squared speeds equal in float but not in double
// (1 + 2^-23 against 1 and 2^-12), planted pairs that float squares would rank the wrong way
// round (normal and subnormal), speeds whose float square underflows or overflows. 20 states
// on each of three grid shapes. (Wrong kernels tried against it: one that ranked speeds by
// float squares failed 3 states, one without exact ranking of subnormal squares 4, one that
// took the last of equal maxima all 60.)
TEST(AgreementStats, MaximaOnLongRowsWithTiesAndNearTies) {
  if (!opencl_available()) GTEST_SKIP() << "no OpenCL device";
  const double eps = std::ldexp(1.0, -23), nan = std::nan("");
  const std::vector<double> depths = {-2.0, -1.0, -0.5, -0.0, 0.0, 0.4, 0.4, 1.5, 1.5, nan};
  // Velocity components by regime: near ties, squares that underflow in float, squares that
  // overflow in float, all of them.
  const std::vector<std::vector<double>> speeds = {
      {0.0, 1.0, 1.0 + eps, 1.0 - eps / 2, -1.0 - eps, std::ldexp(1.0, -12), 0.5},
      {0.0, 1e-20, -1e-20, 1e-25, 3e-25},
      {3.0, 1e19, 2e19, -2e19, 1.9e19},
      {0.0, 1.0, 1.0 + eps, std::ldexp(1.0, -12), -3.0, 1e-20, 1e-25, 2e19, 0.5}};
  std::uint32_t seed = 12345;
  // A value of `set` (a linear congruential generator: the same states everywhere); the
  // last one only `with_last`.
  auto pick = [&seed](const std::vector<double>& set, bool with_last) {
    seed = seed * 1664525u + 1013904223u;
    return set[(seed >> 8) % (with_last ? set.size() : set.size() - 1)];
  };
  int states = 0, agreed = 0;
  for (const auto& [nx, ny] : std::vector<std::pair<int, int>>{{45, 4}, {130, 3}, {700, 2}}) {
    const Terrain terrain = flat_terrain(nx, ny, 10.0);
    const Params params = quiet_params(FlowScheme::local_inertial, 0.1);
    auto cpu = make_backend("cpu", terrain, params);
    auto ocl = make_backend("opencl", terrain, params);
    const std::size_t n = static_cast<std::size_t>(nx) * ny;
    for (int s = 0; s < 20; ++s) {
      // Half of the states without NaN depths (a NaN makes that cell the first bad one, and
      // the other half checks the first bad cell).
      std::vector<double> d(n), u(n), v(n);
      for (std::size_t i = 0; i < n; ++i) {
        d[i] = pick(depths, s % 2 == 1);
        const auto& regime = speeds[static_cast<std::size_t>(s / 2) % speeds.size()];
        u[i] = pick(regime, true);
        v[i] = s % 3 == 2 ? 0.0 : pick(regime, true);
      }
      if (s % 4 == 1 || s % 4 == 3) {
        // Two planted cells whose float squared speeds rank them the other way round from
        // the exact ones: A = (ua, va) is faster, B = (ub, vb) has the larger float u u + v v
        // (near 1.125; and in the subnormal range, where float rounds to 2^-149: 5 against
        // 6 of them, exactly 5.73 against 5.58). Everything else slower.
        const bool tiny = s % 4 == 3;
        const double ua = tiny ? 7.855647288146363e-23 : 0.7500035762786865;
        const double va = tiny ? 4.314757393729191e-23 : 0.7500025033950806;
        const double ub = tiny ? 8.841709535720696e-23 : 0.7500033974647522;
        const double vb = tiny ? 0.0 : 0.7500026822090149;
        for (std::size_t i = 0; i < n; ++i) u[i] = v[i] = tiny ? 0.0 : 0.5;
        seed = seed * 1664525u + 1013904223u;
        const std::size_t a = (seed >> 8) % n, b = (a + 1 + (seed >> 20) % (n - 1)) % n;
        u[a] = ua, v[a] = va, u[b] = ub, v[b] = vb;
      }
      std::vector<FieldStats> got;
      for (auto* b : {cpu.get(), ocl.get()}) {
        b->set_field(FieldId::water_depth, d);
        b->set_field(FieldId::velocity_x, u);
        b->set_field(FieldId::velocity_y, v);
        got.push_back(b->stats());
      }
      ++states;
      const bool same =
          got[1].max_depth_cell == got[0].max_depth_cell &&
          got[1].max_speed_cell == got[0].max_speed_cell && got[1].bad_cell == got[0].bad_cell &&
          got[1].max_depth == got[0].max_depth && got[1].max_speed == got[0].max_speed;
      agreed += same;
      EXPECT_TRUE(same) << nx << " x " << ny << " state " << s << ": max depth cell "
                        << got[0].max_depth_cell << " / " << got[1].max_depth_cell
                        << ", max speed cell " << got[0].max_speed_cell << " / "
                        << got[1].max_speed_cell << ", bad cell " << got[0].bad_cell << " / "
                        << got[1].bad_cell << " (cpu / opencl)";
    }
  }
  std::printf(
      "[agreement stats] long rows: %d of %d states with the same maxima, their cells "
      "and the first bad cell (bound: all)\n",
      agreed, states);
}

// Rows whose padded width W has no divisor in [32, 1024]: on a CPU device (PoCL) each row is
// launched as work-groups from column 0 and one tail group of its last columns at an x offset
// (whole_row_launch, launch_rows), whose tally partials sit at the top of each slot
// (cell_group_index, reduce.cl) and whose statistics are the row's last group (field_stats).
// Two grids: a synthetic slope of 5637 x 6 cells (W = 5639: groups of 805, a tail of 4, three
// DEM cells and the east ghost) and a 1029 x 24 window of Big Tujunga (W = 1031: groups of 515,
// a tail of 1, the ghost only). 300 steps of the storm with every tally kernel on (erosion,
// transport, thermal, evaporation, infiltration, snow, terrain classes); the fields as in
// Agreement (relative L2 below 1e-5), every tally of the ledger within a relative 1e-5 (a tail
// whose partials landed on a main group's, or were not written, loses that group's share of a
// row: about 1/8 of the synthetic grid's tallies), and the statistics at the same cells: also on
// planted states whose largest depth and speed, and first bad cell, are in the tail.
TEST(AgreementRowTail, FieldsTalliesAndStatisticsOnRowsWithATail) {
  if (!opencl_available()) GTEST_SKIP() << "no OpenCL device";
  AgreementCase c{"row_tail",
                  FlowScheme::local_inertial,
                  TransportScheme::conservative,
                  true,
                  2.0,
                  1,
                  ErosionLaw::mei,
                  true,
                  true,
                  true};
  for (const bool synthetic : {true, false}) {
    Params params = agreement_params(c);
    Terrain terrain;
    if (synthetic) {
      // a slope from 1563 m down to the open east edge at 1000 m (the snow line, 1200 m, across
      // it), with ridges and a deterministic roughness steep enough for thermal collapse
      terrain = flat_terrain(5637, 6, 10.0);
      for (int r = 0; r < 6; ++r)
        for (int col = 0; col < 5637; ++col) {
          const std::uint32_t h = (static_cast<std::uint32_t>(col) * 2654435761u) ^
                                  (static_cast<std::uint32_t>(r) * 40503u);
          terrain.bed[static_cast<std::size_t>(r) * 5637 + col] =
              1000.0 + 0.1 * (5637 - col) + 8.0 * std::sin(0.7 * col) * std::cos(1.3 * r) +
              6.0 * static_cast<double>((h >> 8) % 1000) / 1000.0;
        }
    } else {
      params.dem.window = std::array<int, 4>{0, 300, 1029, 24};
      terrain = io::read_dem(params.dem);
    }
    Simulation cpu(terrain, params, make_backend("cpu", terrain, params));
    Simulation ocl(terrain, params, make_backend("opencl", terrain, params));
    const std::string grid = std::to_string(terrain.grid.nx) + " x " +
                             std::to_string(terrain.grid.ny) +
                             (synthetic ? " synthetic" : " Tujunga");
#ifdef ERODEM_HAVE_OPENCL
    // the launches this test is for: on a device with whole-row launches (CPU devices), the
    // row's groups and its tail; on one with the rounded launches (GPUs) the same comparisons
    // hold, but no tail is launched
    const auto* backend = dynamic_cast<const opencl::OpenClBackend*>(&ocl.backend());
    ASSERT_NE(backend, nullptr);
    const opencl::RowLaunch rows = backend->row_launch();
    std::printf("[row tail] %s: %s, groups of %zu, a tail of %zu (expected %d)\n", grid.c_str(),
                backend->whole_rows() ? "whole-row launches" : "rounded launches (no tail)",
                rows.group, rows.tail, synthetic ? 4 : 1);
    if (backend->whole_rows()) {
      EXPECT_EQ(rows.tail, synthetic ? 4u : 1u) << grid;
    }
#endif
    for (int k = 0; k < 3; ++k) {
      cpu.step(100);
      ocl.step(100);
    }
    std::printf("[row tail] %s on '%s': time %.6g / %.6g s (cpu / opencl)\n", grid.c_str(),
                ocl.backend().device().c_str(), cpu.time(), ocl.time());
    EXPECT_NEAR(ocl.time(), cpu.time(), 1e-5 * cpu.time()) << grid;
    const double bound = 1e-5;
    for (FieldId id : {FieldId::bed, FieldId::water_depth, FieldId::sediment, FieldId::velocity_x,
                       FieldId::velocity_y, FieldId::wetness, FieldId::infiltrated, FieldId::snow,
                       FieldId::snow_liquid}) {
      const io::FieldDifference diff =
          io::field_difference(ocl.field(id), cpu.field(id), terrain.grid.nx);
      std::printf("[row tail] %s %-12s relative L2 %.3e (bound %.0e)\n", grid.c_str(),
                  field_info(id).name, diff.rel_l2, bound);
      EXPECT_EQ(diff.cells, terrain.grid.cells()) << grid << " " << field_info(id).name;
      EXPECT_LT(diff.rel_l2, bound) << grid << " " << field_info(id).name;
    }
    // Every tally. The floor, 1e-9 of the rain: `clipped` is water added at the rounding level
    // of the depths (about 1e-8 of the rain here), where float32 rounds differently on the two.
    const Ledger& L = cpu.ledger();
    const Ledger& M = ocl.ledger();
    struct Tally {
      const char* name;
      double Ledger::*member;
    };
#define ERODEM_TALLY_ENTRY(name, zero_if_absent, doc) Tally{#name, &Ledger::name},
    const Tally tallies[] = {ERODEM_TALLIES(ERODEM_TALLY_ENTRY)};
#undef ERODEM_TALLY_ENTRY
    for (const Tally& t : tallies) {
      const double a = L.*t.member, b = M.*t.member;
      const double tol = 1e-5 * std::abs(a) + 1e-9 * L.rain;
      std::printf("[row tail] %s %-18s %.9g / %.9g m^3 (difference %.2e, bound %.2e)\n",
                  grid.c_str(), t.name, a, b, std::abs(b - a), tol);
      EXPECT_NEAR(b, a, tol) << grid << " " << t.name;
    }
    // the tallies of every kind of tally kernel moved something
    for (double Ledger::*m :
         {&Ledger::water_exchanged, &Ledger::eroded, &Ledger::deposited,
          &Ledger::sediment_exchanged, &Ledger::thermal_moved, &Ledger::evaporated,
          &Ledger::infiltrated, &Ledger::snowfall, &Ledger::rain_on_snow})
      EXPECT_GT(L.*m, 0.0) << grid;
    EXPECT_EQ(ocl.last_stats().max_depth_cell, cpu.last_stats().max_depth_cell) << grid;
    EXPECT_EQ(ocl.last_stats().max_speed_cell, cpu.last_stats().max_speed_cell) << grid;

    // Planted states: the largest depth and speed in the last DEM column of row 1 (the tail
    // where W = 5639; the last main group where W = 1031), then also equal in column 3 of row 1
    // (the first group: its cell is the first), and a NaN depth in the last column of row 2.
    const std::int64_t nx = terrain.grid.nx;
    const std::int64_t last = nx + nx - 1, early = nx + 3, bad = 2 * nx + nx - 1;
    for (int state = 0; state < 3; ++state) {
      auto depth = cpu.field(FieldId::water_depth);
      auto u = cpu.field(FieldId::velocity_x), v = cpu.field(FieldId::velocity_y);
      depth[static_cast<std::size_t>(last)] = 50.0;
      u[static_cast<std::size_t>(last)] = 40.0;
      v[static_cast<std::size_t>(last)] = 0.0;
      if (state >= 1) {
        depth[static_cast<std::size_t>(early)] = 50.0;
        u[static_cast<std::size_t>(early)] = -40.0;
        v[static_cast<std::size_t>(early)] = 0.0;
      }
      if (state == 2) depth[static_cast<std::size_t>(bad)] = NAN;
      const std::int64_t at = state == 0 ? last : early;
      for (Simulation* sim : {&cpu, &ocl}) {
        sim->backend().set_field(FieldId::water_depth, depth);
        sim->backend().set_field(FieldId::velocity_x, u);
        sim->backend().set_field(FieldId::velocity_y, v);
        const FieldStats st = sim->backend().stats();
        std::printf(
            "[row tail] %s state %d on %s: max depth %.3g m at %lld, max speed %.3g m/s at %lld "
            "(expected %lld), first bad cell %lld (expected %lld)\n",
            grid.c_str(), state, sim->backend().name().c_str(), st.max_depth,
            static_cast<long long>(st.max_depth_cell), st.max_speed,
            static_cast<long long>(st.max_speed_cell), static_cast<long long>(at),
            static_cast<long long>(st.bad_cell), static_cast<long long>(state == 2 ? bad : -1));
        EXPECT_EQ(st.max_depth_cell, at) << grid << " state " << state;
        EXPECT_EQ(st.max_speed_cell, at) << grid << " state " << state;
        EXPECT_EQ(st.max_depth, 50.0) << grid << " state " << state;
        EXPECT_EQ(st.bad_cell, state == 2 ? bad : -1) << grid << " state " << state;
      }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(
    Tujunga, Agreement,
    ::testing::Values(
        AgreementCase{"local_inertial_conservative", FlowScheme::local_inertial,
                      TransportScheme::conservative, true, 2.0},
        AgreementCase{"pipes_semi_lagrangian", FlowScheme::pipes, TransportScheme::semi_lagrangian,
                      false, 0.5},
        AgreementCase{"shallow_water_conservative", FlowScheme::shallow_water,
                      TransportScheme::conservative, true, 2.0},
        AgreementCase{"shallow_water_order2_conservative", FlowScheme::shallow_water,
                      TransportScheme::conservative, true, 2.0, 2},
        // the physical erosion law (its exp and expm1 are the libraries' on
        // each side, so not bit for bit)
        AgreementCase{"local_inertial_physical", FlowScheme::local_inertial,
                      TransportScheme::conservative, true, 2.0, 1, ErosionLaw::physical},
        // Green-Ampt infiltration (the libraries' log1p on each side: equal here, not promised)
        AgreementCase{"local_inertial_infiltration", FlowScheme::local_inertial,
                      TransportScheme::conservative, true, 2.0, 1, ErosionLaw::physical, true},
        // the snow pack: snowfall, rain on snow, melt, liquid water under a temperature series
        AgreementCase{"local_inertial_snow", FlowScheme::local_inertial,
                      TransportScheme::conservative, true, 2.0, 1, ErosionLaw::mei, false, true},
        // terrain classes and their tables, with infiltration, Mei's erosion and collapse
        AgreementCase{"local_inertial_classes", FlowScheme::local_inertial,
                      TransportScheme::conservative, true, 2.0, 1, ErosionLaw::mei, true, false,
                      true}),
    [](const ::testing::TestParamInfo<AgreementCase>& i) { return i.param.name; });

// On CPU devices (whole-row launches) the shallow water runs its interior rows by kernels that
// read velocities computed once per cell and need no clamping: the first order rows 1 .. H - 2
// by flow_shallow_water_interior, the second order rows 2 .. H - 3 by
// flow_shallow_water_muscl_interior (each of Heun's stages; with periodic east-west edges it
// selects the cells beyond the seam that the general kernel wraps to),
// the other rows by the general flow_shallow_water and flow_shallow_water_muscl. With rounded
// launches (ERODEM_OPENCL_WG, as on GPUs) the general kernels run every row. The two must give
// the same bits (shallow_water_cell_interior, shallow_water_muscl_cell_interior: near the first
// and last column they read across the row end where the general kernels see a wall; a face
// between two ghosts carries nothing, and a ghost's slopes are 0). A bumpy bed with a lake, an
// island and rain, 80 steps of 0.2 s, with walls, with fixed levels east and west (ghost columns
// that give water, and whose faces across the row ends the interior kernels compute), with
// periodic east-west edges (whose ghost columns are active cells, copies of the opposite
// columns, which the interior kernels read where the general ones wrap), with open edges east
// and west, and periodic again with Mei's erosion and thermal collapse (the bed changes, and its
// ghost columns must follow): the depth, both unit discharges, the four outflows, the bed and
// the sediment of every DEM cell, bound 0 differing values. Not vacuous: the water must have
// moved (a nonzero eastward unit discharge in most cells; an idle solver on both sides would
// agree too), the bed too where erosion is on (and only there), and swapping the east and west
// neighbours' eastward velocities in the interior kernel made 7743, 6956, 7931, 6973 and 10619
// of the 12321 values differ at the first order (walls, fixed levels, periodic, open, periodic
// with erosion), 7776, 7168, 7984, 7229 and 10676 at the second; without the selection at the
// seam (shallow_water_muscl_cell_interior) the periodic cases made 5949 and 8765 differ.
TEST(AgreementLaunch, ShallowWaterInteriorKernelsSameBitsAsGeneral) {
#ifndef ERODEM_HAVE_OPENCL
  GTEST_SKIP() << "built without OpenCL";
#else
  if (!opencl_available()) GTEST_SKIP() << "no OpenCL device";
  const char* wg = std::getenv("ERODEM_OPENCL_WG");
  const std::string wg_before = wg ? wg : "";
  for (const int order : {1, 2}) {
    // walls, fixed levels east and west, periodic, open east and west, periodic with erosion
    // and thermal collapse (the bed changes: its ghost columns must follow)
    for (const int edges : {0, 1, 2, 3, 4}) {
      Terrain t = bumpy_terrain(37, 10.0);
      t.water_depth.assign(t.grid.cells(), 0.0);
      for (std::size_t i = 0; i < t.bed.size(); ++i)
        t.water_depth[i] = t.bed[i] < 10.0 ? 10.0 - t.bed[i] : 0.0;
      Params p = quiet_params(FlowScheme::shallow_water, 0.2);
      p.flow.order = order;
      p.flow.manning_n.value = 0.03;
      p.rain.rate = 200e-3 / 3600;
      if (edges == 1) {
        // the ghost columns give water (a level of 9.5 m below the lake's 10 m: it drains out)
        p.boundary.east = p.boundary.west = BoundaryKind::fixed_level;
        p.boundary.sea_level = 9.5;
      }
      if (edges == 3) p.boundary.east = p.boundary.west = BoundaryKind::open;
      p.boundary.periodic_x = edges == 2 || edges == 4;
      if (edges == 4) {
        p.erosion.enabled = true;
        p.erosion.law = ErosionLaw::mei;  // no threshold: the lake's slow water erodes too
        p.thermal.enabled = true;
        p.thermal.talus_angle = 20.0;
      }
      const std::string label = std::string(order == 1 ? "first order, " : "second order, ") +
                                (edges == 0   ? "walls"
                                 : edges == 1 ? "fixed levels east and west"
                                 : edges == 2 ? "periodic east-west"
                                 : edges == 3 ? "open east and west"
                                              : "periodic east-west, erosion and thermal");
      unsetenv("ERODEM_OPENCL_WG");
      Simulation rows(t, p, make_backend("opencl", t, p));
      setenv("ERODEM_OPENCL_WG", "64", 1);
      Simulation rounded(t, p, make_backend("opencl", t, p));
      if (wg_before.empty())
        unsetenv("ERODEM_OPENCL_WG");
      else
        setenv("ERODEM_OPENCL_WG", wg_before.c_str(), 1);
      const auto* a = dynamic_cast<const opencl::OpenClBackend*>(&rows.backend());
      const auto* b = dynamic_cast<const opencl::OpenClBackend*>(&rounded.backend());
      ASSERT_NE(a, nullptr);
      ASSERT_NE(b, nullptr);
      if (!a->whole_rows()) GTEST_SKIP() << "not a CPU device: no whole-row launches";
      ASSERT_FALSE(b->whole_rows());
      const auto bed0 = rows.field(FieldId::bed);
      rows.step(80);
      rounded.step(80);
      std::size_t values = 0, differ = 0, moving = 0, bed_moved = 0;
      for (const FieldId f : {FieldId::water_depth, FieldId::momentum_x, FieldId::momentum_y,
                              FieldId::flux_left, FieldId::flux_right, FieldId::flux_top,
                              FieldId::flux_bottom, FieldId::bed, FieldId::sediment}) {
        const auto x = rows.field(f), y = rounded.field(f);
        ASSERT_EQ(x.size(), y.size());
        for (std::size_t i = 0; i < x.size(); ++i) {
          ++values;
          differ += std::memcmp(&x[i], &y[i], sizeof(double)) != 0;
          if (f == FieldId::momentum_x) moving += x[i] != 0.0;
          if (f == FieldId::bed) bed_moved += x[i] != bed0[i];
        }
      }
      const std::size_t cells = t.grid.cells();
      std::printf(
          "[launch] shallow water, %s, 37^2, 80 steps: %zu of %zu values differ between the "
          "interior kernel (whole rows) and the general one (rounded launches) (bound 0); cells "
          "with a nonzero eastward unit discharge %zu of %zu (bound: more than half); cells whose "
          "bed moved %zu (bound: more than half with erosion, else 0)\n",
          label.c_str(), differ, values, moving, cells, bed_moved);
      EXPECT_EQ(differ, 0u) << label;
      EXPECT_GT(moving, cells / 2) << label;
      if (edges == 4)
        EXPECT_GT(bed_moved, cells / 2) << label;
      else
        EXPECT_EQ(bed_moved, 0u) << label;
    }
  }
#endif
}

}  // namespace
}  // namespace erodem::test
