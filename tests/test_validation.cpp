// erodem — validation cases beyond the closed forms of test_analytical.cpp: the UK Environment
// Agency 2D benchmarks 1 and 2 (Néelz & Pender 2013) as far as their set-ups can be rebuilt
// from the published description, SWASHES' lake at rest with an immersed bump (Delestre et al.
// 2013), and the local-inertial scheme's sensitivity to a fixed time step. ctest runs the
// coarse rungs; the report (experiments/validation/run.py) the full ladders
// (validation_record.hpp). Each test prints the measured figure beside its bound.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <vector>

#include "reference_solutions.hpp"
#include "scenarios.hpp"
#include "target_test.hpp"
#include "validation_record.hpp"

namespace erodem::test {
namespace {

namespace vr = validation;

class Validation : public TargetTest {};

/// Linear interpolation through the (x, y) vertices, held constant outside them.
double piecewise(const std::vector<std::array<double, 2>>& v, double x) {
  if (x <= v.front()[0]) return v.front()[1];
  for (std::size_t k = 1; k < v.size(); ++k)
    if (x <= v[k][0])
      return v[k - 1][1] + (v[k][1] - v[k - 1][1]) * (x - v[k - 1][0]) / (v[k][0] - v[k - 1][0]);
  return v.back()[1];
}

/// The level sum (b + d) of a row-major field pair at cell i, or the bed where dry (m).
double level_at(const std::vector<double>& bed, const std::vector<double>& depth, std::size_t i) {
  return bed[i] + depth[i];
}

// ---- EA test 1: flooding a disconnected water body ------------------------------------
//
// Néelz & Pender (2013), Benchmarking the latest generation of 2D hydraulic modelling packages,
// Environment Agency report SC120002, test 1: a 700 m x 100 m domain whose bed varies along x
// only, a water-level hydrograph on the west edge that rises above a ridge and falls back, and
// a depression beyond the ridge that fills and is then cut off: the test is whether a model
// lets the water over the ridge and keeps what lies below the ridge's crest. The published
// profile and hydrograph were not available to this work (only the description), so both are
// rebuilt here (docs/validation.md says so): the bed below, a level of 9.7 m rising to 10.35 m
// over the first hour, held to 3 h, back to 9.7 m at 5 h, run to 20 h; n = 0.03. erodem has no
// time-varying level boundary, so the level is imposed on the first column of cells after each
// step (its depth set to level - bed; the volume that adds or removes is booked here as the
// boundary's). The reference is the mass balance, which is exact: once the boundary is below
// the crest, the depression keeps exactly the volume below its spill level (the crest, 10.25 m),
// so the level that the stored volume gives must come back to the crest from above.
struct EaTest1 {
  std::vector<std::array<double, 2>> profile{{0, 9.5},    {100, 9.5},  {300, 10.25}, {350, 10.25},
                                             {450, 9.75}, {550, 9.75}, {650, 10.5},  {700, 10.5}};
  std::vector<std::array<double, 2>> hydrograph{
      {0, 9.7}, {3600, 10.35}, {10800, 10.35}, {18000, 9.7}};
  double crest = 10.25, ridge_end = 350.0, duration = 20 * 3600.0;
  Terrain terrain(double dx) const {
    const int nx = static_cast<int>(700 / dx + 0.5), ny = static_cast<int>(100 / dx + 0.5);
    Terrain t = flat_terrain(nx, ny, dx);
    t.water_depth.assign(t.grid.cells(), 0.0);
    for (int r = 0; r < ny; ++r)
      for (int c = 0; c < nx; ++c) {
        const double x = (c + 0.5) * dx, z = piecewise(profile, x);
        const auto i = static_cast<std::size_t>(r) * nx + c;
        t.bed[i] = z;
        if (x < 300) t.water_depth[i] = std::max(0.0, hydrograph[0][1] - z);  // the connected pond
      }
    return t;
  }
};

TEST_P(Validation, EaTest1DisconnectedWaterBody) {
  const EaTest1 ea;
  std::vector<double> sizes{20.0};  // the report adds the EA's recommended 10 m grid
  if (vr::full_ladder()) sizes.push_back(10.0);
  const char* ref = "Neelz & Pender (2013) EA SC120002 test 1 (rebuilt); mass balance";
  for (FlowScheme scheme : {FlowScheme::local_inertial, FlowScheme::pipes}) {
    for (double dx : sizes) {
      Params p = quiet_params(scheme, 1.0);
      p.flow.manning_n.value = 0.03;
      p.flow.pipe_area = 0.5 * dx;  // a reference depth A / w of 0.5 m (StokerWetDamBreak)
      p.time.adaptive = true;
      p.time.dt_max = 5.0;
      p.numerics.threads = 1;  // 175 - 700 cells: one thread is faster than two
      auto sim = make_simulation(ea.terrain(dx), p, target());
      const Grid& g = sim.grid();
      const auto bed = sim.field(FieldId::bed);
      // gauges (m): the connected pond, the slope before the crest, the depression
      const std::array<double, 3> gauge_x{50.0, 250.0, 500.0};
      std::vector<std::vector<double>> series(5);
      double imposed = 0, next_sample = 0;
      const double v0 = sim.ledger().water;
      while (sim.time() < ea.duration - 1e-9) {
        sim.step();
        auto d = sim.field(FieldId::water_depth);
        const double level = piecewise(ea.hydrograph, sim.time());
        for (int r = 0; r < g.ny; ++r) {
          const auto i = static_cast<std::size_t>(r) * g.nx;
          const double want = std::max(0.0, level - bed[i]);
          imposed += (want - d[i]) * g.area[r];
          d[i] = want;
        }
        sim.backend().set_field(FieldId::water_depth, d);
        if (sim.time() < next_sample) continue;
        next_sample += 300.0;
        const auto row = static_cast<std::size_t>(g.ny / 2) * g.nx;
        series[0].push_back(sim.time() / 3600.0);
        series[1].push_back(level);
        for (std::size_t k = 0; k < 3; ++k) {
          const auto i = row + static_cast<std::size_t>(gauge_x[k] / dx);
          series[2 + k].push_back(level_at(bed, d, i));
        }
      }
      const auto d = sim.field(FieldId::water_depth);
      // the depression: the cells beyond the ridge; its stored volume and the level it gives
      std::vector<double> pit_bed, pit_depth;
      for (int r = 0; r < g.ny; ++r)
        for (int c = 0; c < g.nx; ++c)
          if ((c + 0.5) * dx > ea.ridge_end) {
            pit_bed.push_back(bed[static_cast<std::size_t>(r) * g.nx + c]);
            pit_depth.push_back(d[static_cast<std::size_t>(r) * g.nx + c]);
          }
      const double cell_area = g.area[0];
      double stored = 0;
      for (double h : pit_depth) stored += h * cell_area;
      auto volume_below = [&](double level) {
        double v = 0;
        for (double z : pit_bed) v += std::max(0.0, level - z) * cell_area;
        return v;
      };
      double lo = 9.0, hi = 11.0;  // the level whose volume is the stored one (bisection)
      for (int k = 0; k < 100; ++k)
        (volume_below(0.5 * (lo + hi)) < stored ? lo : hi) = 0.5 * (lo + hi);
      const double mb_level = 0.5 * (lo + hi);
      double water = 0;
      for (int r = 0; r < g.ny; ++r)
        for (int c = 0; c < g.nx; ++c)
          water += d[static_cast<std::size_t>(r) * g.nx + c] * g.area[r];
      // relative to the water the cells exchanged, the ledger's measure (model.md section 7)
      const double closure = std::abs(water - v0 - imposed) /
                             std::max(std::abs(imposed), sim.ledger().water_exchanged);
      const double peak_pit = *std::max_element(series[4].begin(), series[4].end());
      std::printf(
          "[EA test 1] %s %s dx = %.1f m: depression stores %.1f m^3 (%.1f m^3 below the crest); "
          "its level from the stored volume %.4f m, crest %.2f m: %+.4f m (bound -0.01 .. "
          "+0.02 m; an idle solver leaves it dry: -0.5 m); peak level there %.3f m (boundary "
          "peak 10.35 m); water closure with the level boundary's volume %.2e (bound %.0e)\n",
          target().label().c_str(), scheme_name(scheme), dx, stored, volume_below(ea.crest),
          mb_level, ea.crest, mb_level - ea.crest, peak_pit, closure, bound(1e-12, 1e-5));
      auto fig = [&](const char* quantity) {
        return figure("ea_test1", scheme_name(scheme), quantity, dx, ref);
      };
      vr::profile(fig(""), std::string(scheme_name(scheme)) + "_dx" + std::to_string(int(dx)),
                  {"t_h", "boundary_level", "level_x50", "level_x250", "level_x500"}, series);
      // After 15 h of recession the head left over the crest drains through a film whose
      // Manning conveyance vanishes with its depth: about 2.5 mm at 20 h for a 50 m crest
      // (A dh/dt = -w h^(13/6) / (n sqrt(L))), so the level from the stored volume sits a few
      // mm above the crest (local inertial +3.8 mm at 20 m). The pipes' fluxes carry inertia:
      // they overshoot the crest on the way out by about a mm (-0.9 mm). The band -1 cm ..
      // +2 cm admits both; a solver that lets nothing over the ridge (dry: -0.5 m) or nothing
      // back (+0.10 m, the boundary's peak) fails.
      vr::expect_between(fig("level from the stored volume - crest (m)"), mb_level - ea.crest,
                         -0.01, 0.02);
      vr::expect_below(fig("water closure with the level boundary (relative)"), closure,
                       bound(1e-12, 1e-5));
      vr::report(fig("peak level in the depression (m)"), peak_pit);
    }
  }
}

// ---- EA test 2: filling of floodplain depressions -------------------------------------
//
// Néelz & Pender (2013) test 2: a 2 km x 2 km floodplain of 4 x 4 depressions 0.5 m deep (an
// "egg box"), an inflow hydrograph at one corner, 48 h, n = 0.03; the test is the final
// levels and extents. The published DEM and hydrograph were not available (only the
// description), so both are rebuilt: z = -0.5 sin^2(pi x / 500) sin^2(pi y / 500) m (16
// depressions of 31,250 m^3 each, separated by ridges at 0 m), and 20 m^3/s into the north-west
// depression's centre, reached in 10 min, held to 50 min, off at 60 min (60,000 m^3: nearly two
// depressions). No closed form: the checks are the mass balance (exact), the fill-and-spill
// rule (the inflow's depression ends full to its spill level, no depression above its own,
// every wet depression flat) and the final levels, reported.
struct EaTest2 {
  double size = 2000.0, period = 500.0, depth = 0.5, duration = 48 * 3600.0;
  Series hydrograph{{0.0, 0.0}, {600.0, 20.0}, {3000.0, 20.0}, {3600.0, 0.0}};
  double inflow_volume() const { return 20.0 * 2400.0 + 2 * 0.5 * 600.0 * 20.0; }
  Terrain terrain(double dx) const {
    const int n = static_cast<int>(size / dx + 0.5);
    Terrain t = flat_terrain(n, n, dx);
    for (int r = 0; r < n; ++r)
      for (int c = 0; c < n; ++c) {
        const double x = (c + 0.5) * dx, y = size - (r + 0.5) * dx;  // north-up (Grid::uniform)
        t.bed[static_cast<std::size_t>(r) * n + c] = -depth *
                                                     std::pow(std::sin(M_PI * x / period), 2) *
                                                     std::pow(std::sin(M_PI * y / period), 2);
      }
    return t;
  }
  /// Which depression (0 .. 15, row-major from the north-west) cell (r, c) lies in.
  int depression(int r, int c, double dx) const {
    const int k = static_cast<int>(size / period + 0.5);
    return (static_cast<int>(r * dx / period)) * k + static_cast<int>(c * dx / period);
  }
};

/// The spill level of depression `k` on the grid: the lowest level at which water standing in
/// it reaches a cell of another depression through 4-neighbours (bisection on a flood fill).
double spill_level(const EaTest2& ea, const std::vector<double>& bed, int n, double dx, int k) {
  std::size_t bottom = 0;
  double zmin = HUGE_VAL;
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c)
      if (ea.depression(r, c, dx) == k && bed[static_cast<std::size_t>(r) * n + c] < zmin) {
        zmin = bed[static_cast<std::size_t>(r) * n + c];
        bottom = static_cast<std::size_t>(r) * n + c;
      }
  auto escapes = [&](double level) {
    std::vector<char> seen(bed.size(), 0);
    std::vector<std::size_t> stack{bottom};
    seen[bottom] = 1;
    while (!stack.empty()) {
      const auto i = stack.back();
      stack.pop_back();
      const int r = static_cast<int>(i) / n, c = static_cast<int>(i) % n;
      if (ea.depression(r, c, dx) != k) return true;
      const int nb[4][2] = {{r - 1, c}, {r + 1, c}, {r, c - 1}, {r, c + 1}};
      for (const auto& q : nb) {
        if (q[0] < 0 || q[0] >= n || q[1] < 0 || q[1] >= n) continue;
        const auto j = static_cast<std::size_t>(q[0]) * n + q[1];
        if (!seen[j] && bed[j] < level) {
          seen[j] = 1;
          stack.push_back(j);
        }
      }
    }
    return false;
  };
  double lo = zmin, hi = 0.01;
  for (int it = 0; it < 40; ++it) (escapes(0.5 * (lo + hi)) ? hi : lo) = 0.5 * (lo + hi);
  return 0.5 * (lo + hi);
}

TEST_P(Validation, EaTest2FillingFloodplainDepressions) {
  const EaTest2 ea;
  std::vector<double> sizes{50.0};  // the report adds the EA's recommended 20 m grid
  if (vr::full_ladder()) sizes.push_back(20.0);
  const char* ref =
      "Neelz & Pender (2013) EA SC120002 test 2 (rebuilt); mass balance, fill-and-spill";
  // The schemes at the default Courant number 0.7; the report adds local inertial at 0.5: at
  // 20 m cells (dt = 6.3 s, below dt_max) the default leaves the full depression sloshing
  // (+0.12 m over its spill level after 48 h, levels 0.32 m apart), at 0.5 it is at rest.
  struct Variant {
    FlowScheme scheme;
    double cfl;
    std::string name;
  };
  std::vector<Variant> variants{{FlowScheme::local_inertial, 0.7, "local_inertial"},
                                {FlowScheme::pipes, 0.7, "pipes"}};
  if (vr::full_ladder())
    variants.push_back({FlowScheme::local_inertial, 0.5, "local_inertial cfl 0.5"});
  for (const Variant& variant : variants) {
    const FlowScheme scheme = variant.scheme;
    const char* name = variant.name.c_str();
    std::string tag = variant.name;  // the profile's file name: no spaces
    std::replace(tag.begin(), tag.end(), ' ', '_');
    for (double dx : sizes) {
      Params p = quiet_params(scheme, 1.0);
      p.flow.manning_n.value = 0.03;
      p.flow.pipe_area = 0.25 * dx;  // a reference depth A / w of 0.25 m, half the depressions'
      p.time.adaptive = true;
      p.time.cfl = variant.cfl;
      p.time.dt_max = 10.0;
      p.numerics.threads = 1;  // up to 10^4 cells: one thread is about as fast as two
      p.inflow.push_back(InflowSpec{{{0.5 * ea.period, ea.size - 0.5 * ea.period}}, ea.hydrograph});
      auto sim = make_simulation(ea.terrain(dx), p, target());
      const int n = sim.grid().nx;
      while (sim.time() < ea.duration - 1e-9) sim.step();
      const auto bed = sim.field(FieldId::bed), d = sim.field(FieldId::water_depth);
      const double area = dx * dx;
      // per depression: stored volume, wet cells' level range, spill level
      std::vector<double> stored(16, 0.0), top(16, -HUGE_VAL), low(16, HUGE_VAL);
      for (int r = 0; r < n; ++r)
        for (int c = 0; c < n; ++c) {
          const auto i = static_cast<std::size_t>(r) * n + c;
          const int k = ea.depression(r, c, dx);
          stored[k] += d[i] * area;
          if (d[i] > 0.05) {  // thinner films at a puddle's edge drain for days (EA test 1)
            top[k] = std::max(top[k], bed[i] + d[i]);
            low[k] = std::min(low[k], bed[i] + d[i]);
          }
        }
      double worst_over = -HUGE_VAL, worst_tilt = 0, total = 0;
      std::vector<double> levels(16, NAN), spills(16), index(16);
      for (int k = 0; k < 16; ++k) {
        spills[k] = spill_level(ea, bed, n, dx, k);
        index[k] = k;
        total += stored[k];
        if (stored[k] < 1.0 || top[k] == -HUGE_VAL) continue;  // dry, or films only
        levels[k] = top[k];
        worst_over = std::max(worst_over, top[k] - spills[k]);
        worst_tilt = std::max(worst_tilt, top[k] - low[k]);
      }
      const double first = top[0] - spills[0];
      // against the volume the inflow booked (the hydrograph taken at step midpoints: its
      // kinks make that differ from the exact integral by O(dt^2), reported)
      const double booked = sim.ledger().inflow;
      // relative to the water the cells exchanged, the ledger's measure (model.md section 7):
      // float32 rounding grows with the steps (44,000 at 20 m and Courant 0.5: 1.2e-5 of the
      // inflow volume), the water exchanged with it
      const double closure =
          std::abs(total - booked) / std::max(booked, sim.ledger().water_exchanged);
      vr::report(figure("ea_test2", name, "booked inflow / hydrograph's integral - 1", dx, ref),
                 booked / ea.inflow_volume() - 1);
      int wet = 0;
      for (double v : stored) wet += v >= 1.0;
      std::printf(
          "[EA test 2] %s %s dx = %.0f m: %.1f of %.1f m^3 stored (closure %.2e, bound %.0e); "
          "%d depressions wet; the inflow's depression %.4f m above its spill level %.4f m "
          "(bound -0.01 .. +0.01 m; an idle solver piles 60,000 m^3 on one cell); highest level "
          "over a spill level %+.4f m (bound 0.01 m); widest level range over the cells deeper "
          "than 5 cm of a depression %.4f m (bound 0.01 m)\n",
          target().label().c_str(), name, dx, total, ea.inflow_volume(), closure,
          bound(1e-12, 1e-5), wet, first, spills[0], worst_over, worst_tilt);
      auto fig = [&](const char* quantity) { return figure("ea_test2", name, quantity, dx, ref); };
      vr::profile(fig(""), tag + "_dx" + std::to_string(int(dx)),
                  {"depression", "level", "spill_level", "stored_m3"},
                  {index, levels, spills, stored});
      // 60,000 m^3 fill the first depression (31,250 m^3) and spill; after 47 h at rest
      // the films over the ridges have drained to millimetres (Manning films, EA test 1), so
      // every level sits within 1 cm of flat and of its spill level at most. The mass balance
      // is the volume the inflow booked: rounding (float32 depths summed over 10^4 cells).
      vr::expect_below(fig("stored vs booked inflow (relative to the water exchanged)"), closure,
                       bound(1e-12, 1e-5));
      vr::expect_between(fig("inflow's depression: level - spill level (m)"), first, -0.01, 0.01);
      vr::expect_below(fig("highest level over its spill level (m)"), worst_over, 0.01);
      vr::expect_below(fig("widest level range in a depression, cells > 5 cm deep (m)"), worst_tilt,
                       0.01);
    }
  }
}

// ---- SWASHES 3.1.1: lake at rest with an immersed bump --------------------------------
//
// Delestre et al. (2013), SWASHES, section 3.1.1: a 25 m channel, bed z = 0.2 - 0.05 (x - 10)^2
// on 8 < x < 12 m (else 0), level 0.5 m, no flow: the exact solution is that state for ever
// (h + z = 0.5, u = 0). A well-balanced scheme keeps it to rounding. Both schemes compute the
// surface slope from the levels, so they should: bound 1e-4 m/s and 1e-5 m in float32 (a few
// ulps of 0.5 m divided by dt), 1e-9 and 1e-12 in float64; an unbalanced scheme moves water at
// once (the bed slope alone would drive 0.1 m/s within a second).
TEST_P(Validation, SwashesLakeAtRestImmersedBump) {
  std::vector<double> sizes{0.25};
  if (vr::full_ladder()) sizes.insert(sizes.end(), {0.1, 0.05});
  for (FlowScheme scheme : {FlowScheme::local_inertial, FlowScheme::pipes}) {
    for (double dx : sizes) {
      const int n = static_cast<int>(25.0 / dx + 0.5);
      Terrain t = flat_terrain(n, 3, dx);
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < n; ++c) {
          const double x = (c + 0.5) * dx;
          t.bed[static_cast<std::size_t>(r) * n + c] =
              x > 8 && x < 12 ? 0.2 - 0.05 * (x - 10) * (x - 10) : 0.0;
        }
      Params p = quiet_params(scheme, 0.1 * dx);  // dt sqrt(g h) / dx = 0.22
      p.numerics.threads = 1;
      p.initial.water_level = 0.5;
      auto sim = make_simulation(t, p, target());
      sim.step(static_cast<long>(20.0 / p.time.dt + 0.5));  // 20 s
      const auto h = middle_row(sim, FieldId::water_depth),
                 u = middle_row(sim, FieldId::velocity_x);
      const std::vector<double> z(t.bed.begin() + n, t.bed.begin() + 2 * n);
      std::vector<double> eta(n), x(n);
      double level_error = 0;
      for (int c = 0; c < n; ++c) {
        eta[c] = z[c] + h[c];
        x[c] = (c + 0.5) * dx;
        level_error = std::max(level_error, std::abs(eta[c] - 0.5));
      }
      const double speed = max_abs(u);
      std::printf(
          "[SWASHES lake at rest] %s %s dx = %.2f m: after 20 s max |h + z - 0.5| %.2e m (bound "
          "%.0e), max |u| %.2e m/s (bound %.0e)\n",
          target().label().c_str(), scheme_name(scheme), dx, level_error, bound(1e-12, 1e-5), speed,
          bound(1e-9, 1e-4));
      auto fig = [&](const char* quantity) {
        return figure("swashes_lake_at_rest", scheme_name(scheme), quantity, dx,
                      "SWASHES 3.1.1 (Delestre et al. 2013): h + z = 0.5 m, u = 0");
      };
      if (dx == sizes.back())
        vr::profile(fig(""), scheme_name(scheme), {"x", "level", "level_exact", "bed"},
                    {x, eta, std::vector<double>(n, 0.5), z});
      vr::expect_below(fig("max |h + z - 0.5| (m)"), level_error, bound(1e-12, 1e-5));
      vr::expect_below(fig("max |u| (m/s)"), speed, bound(1e-9, 1e-4));
    }
  }
}

// ---- local inertial: the error against a fixed time step at a fixed grid ---------------
//
// Two effects of dt at fixed dx (issue 14): the theta weighting (1 - theta)/2 (q_up + q_down -
// 2 q) adds a diffusion of about (1 - theta) dx^2 / (2 dt) to the discharge, which grows as dt
// shrinks; and a line inflow adds Q dt per step to its cells, so their depth depends on dt.
// Measured on the Stoker dam break (dx = 2 m, the StokerWetDamBreak set-up) and on the inflow
// cell of the Manning plane (dx = 10 m, ManningPlaneNormalDepth's set-up with fixed steps:
// the inflow cell sits above the normal depth by what one step's inflow and the outflow
// limiter leave there).
TEST_P(Validation, LocalInertialTimeStepSensitivity) {
  std::vector<double> steps{0.3, 0.1};  // s on 2 m cells (Courant 0.66 and 0.22)
  if (vr::full_ladder()) steps = {0.3, 0.2, 0.1, 0.05, 0.025};
  const DamBreak db{500, 2.0, 500.0, 2.0, 1.0};
  const Stoker exact(db.h_up, db.h_down);
  const double t_end = 40.0, lo = exact.head(t_end) - 20.0, hi = exact.shock * t_end + 20.0;
  const Row row = db.row();
  const auto h_exact = row.sample([&](double x) { return exact.depth(x, t_end); });
  std::vector<double> errors;
  for (double dt : steps) {
    Params p = quiet_params(FlowScheme::local_inertial, dt);
    p.numerics.threads = 1;  // 1500 cells
    const auto r = run_dam_break(db, p, t_end, target());
    errors.push_back(relative_l1(row, r.depth, h_exact, db.initial_depth(), lo, hi));
    std::printf("[dt sensitivity] %s Stoker dx = 2 m, dt = %.3f s: depth error %.4f\n",
                target().label().c_str(), dt, errors.back());
    // The dam-break bound of StokerWetDamBreak (0.35; an idle solver scores 1) at every step:
    // the added diffusion smears the shock and the fan but moves no water the wrong way.
    vr::expect_below(figure("li_dt_sensitivity", "local_inertial Stoker",
                            "depth error vs Stoker (relative L1; resolution: dt in s)", dt,
                            "Stoker (1957); dx = 2 m fixed"),
                     errors.back(), 0.35);
  }
  // Reported: at dx = 2 m the model error (0.27, no advection term) dominates; the smaller
  // steps' added diffusion shows in the fan and the shock's width, not in this ratio (0.985
  // from 0.3 s to 0.1 s).
  std::printf("[dt sensitivity] error at dt = %.3f s / at dt = %.3f s: %.3f\n", steps.back(),
              steps.front(), errors.back() / errors.front());
  vr::report(figure("li_dt_sensitivity", "local_inertial Stoker",
                    "error at the smallest dt / at the largest", 2.0, "Stoker (1957)"),
             errors.back() / errors.front());

  // The Manning plane with fixed steps: the inflow cell's depth against the normal depth, and
  // the middle half's worst deviation (ManningPlaneNormalDepth's bound, 0.02, at every step).
  const ManningPlane plane;
  const double normal = plane.normal_depth();
  std::vector<double> plane_steps{3.0, 1.0};  // s on 10 m cells (Courant 0.75, 0.25 at 0.64 m)
  if (vr::full_ladder()) plane_steps = {3.0, 2.0, 1.0, 0.5, 0.25};
  for (double dt : plane_steps) {
    Params p = plane.params(dt);
    p.numerics.threads = 1;  // 600 cells
    auto sim = make_simulation(plane.terrain(), p, target());
    sim.step(static_cast<long>(8000.0 / dt + 0.5));
    const auto d = middle_row(sim, FieldId::water_depth);
    double worst = 0;
    for (int c = plane.n / 4; c < 3 * plane.n / 4; ++c)
      worst = std::max(worst, std::abs(d[c] - normal) / normal);
    const double inflow_cell = d[0] / normal - 1;  // negative: below the normal depth
    std::printf(
        "[dt sensitivity] %s Manning plane dx = 10 m, dt = %.2f s: inflow cell %+.4f of the "
        "normal depth (reported), middle half worst %.4f (bound 0.02)\n",
        target().label().c_str(), dt, inflow_cell, worst);
    const char* ref = "Manning's normal depth; dx = 10 m fixed";
    vr::report(figure("li_dt_sensitivity", "local_inertial Manning plane",
                      "inflow cell: |depth / normal depth - 1| (resolution: dt in s)", dt, ref),
               std::abs(inflow_cell));
    vr::expect_below(
        figure("li_dt_sensitivity", "local_inertial Manning plane",
               "middle half: worst |depth / normal - 1| (resolution: dt in s)", dt, ref),
        worst, 0.02);
  }
}

}  // namespace

ERODEM_INSTANTIATE_TARGETS(Validation);

}  // namespace erodem::test
