// erodem — the snow pack (kernels/common/snow.h, model.md section 2 step 8): degree-day melt
// against its closed forms, on every target. Each test prints the measured figure beside its
// bound; a solver that leaves the pack as it was, melts at another rate or temperature, or
// loses the melt fails.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "erodem/schema.hpp"
#include "scenarios.hpp"
#include "target_test.hpp"
#include "validation_record.hpp"

namespace erodem::test {
namespace {

class Snow : public TargetTest {};

constexpr double kDay = 86400.0;

/// Every other process off, a pack of `initial` m everywhere, melting at `ddf` (m/s per K)
/// above 0 degrees C at `t_ref` degrees C at 0 m, lapse rate `lapse` (K/m); the pack holds no
/// liquid water (retention 0: the melt reaches the depth in its step), no rain.
Params snow_params(double initial, double ddf, double t_ref, double lapse, double dt) {
  Params p = quiet_params(FlowScheme::local_inertial, dt);
  p.snow.enabled = true;
  p.snow.initial.value = initial;
  p.snow.melt_factor = ddf;
  p.snow.melt_temperature = 0.0;
  p.snow.air_temperature = t_ref;
  p.snow.reference_elevation = 0.0;
  p.snow.lapse_rate = lapse;
  p.snow.retention = 0.0;
  return p;
}

/// The snow pack's storage closure: (sum (snow + snow_liquid) area now - at the start) -
/// (snowfall + rain on snow - snow runoff), relative to what crossed the pack's boundary, and
/// the solid part's: (sum snow area now - at the start) - (snowfall - melted), relative to
/// snowfall + melted.
struct PackClosure {
  double whole = 0.0, solid = 0.0;
};
PackClosure pack_closure(const Simulation& sim, double snow0, double area) {
  double snow = 0.0, liquid = 0.0;
  for (double v : sim.field(FieldId::snow)) snow += v * area;
  for (double v : sim.field(FieldId::snow_liquid)) liquid += v * area;
  const auto& L = sim.ledger();
  const double crossed = L.snowfall + L.rain_on_snow + L.snow_runoff;
  PackClosure c;
  c.whole = std::abs(snow + liquid - snow0 - (L.snowfall + L.rain_on_snow - L.snow_runoff)) /
            std::max(crossed, 1e-300);
  c.solid = std::abs(snow - snow0 - (L.snowfall - L.snow_melted)) /
            std::max(L.snowfall + L.snow_melted, 1e-300);
  return c;
}

/// The largest |a_i - b_i|.
double max_abs_diff(const std::vector<double>& a, const std::vector<double>& b) {
  double m = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) m = std::max(m, std::abs(a[i] - b[i]));
  return m;
}

TEST_P(Snow, FlatPackMeltsAtTheDegreeDayRateAndVanishesOnTime) {
  // A flat closed tile of 8 x 8 cells of 1 km under S_0 = 0.1 m of snow at 4 degrees C, DDF
  // 5 mm/d/K: the pack melts at DDF (T - T_melt) = 20 mm/d and vanishes at t* = 5 d; all of it
  // becomes a uniform depth (flat bed: no flow; fixed steps of 600 s, Courant
  // 600 sqrt(g 0.1) / 1000 = 0.59). Checked at t* / 2 (snow and depth S_0 / 2 on every cell)
  // and at 1.5 t* (no snow left, depth S_0, the ledger's melt S_0 times the area).
  // Bounds: float64 1e-12 of S_0 (rounding); float32 2e-5 of S_0: 360 subtractions of the
  // step's melt from a pack near 0.1 m, each rounded to half an ulp of 0.1 (3.7e-9 m), add up
  // to 1.3e-6 m = 1.3e-5 of S_0. An idle pack is off by 0.5 of S_0.
  const double s0 = 0.1, ddf = 5e-3 / kDay, t_air = 4.0, dt = 600.0;
  const double rate = ddf * t_air, t_gone = s0 / rate;  // m/s, s
  ASSERT_NEAR(t_gone, 5 * kDay, 1e-6);
  auto sim =
      make_simulation(flat_terrain(8, 8, 1000.0), snow_params(s0, ddf, t_air, 0.0, dt), target());
  const double area = 64 * 1e6;
  const double bound = this->bound(1e-12, 2e-5) * s0;

  const long half = std::lround(0.5 * t_gone / dt);
  sim.step(half);
  const double t = half * dt;
  const std::vector<double> expect(64, s0 - rate * t), melted(64, rate * t);
  const double e_snow = max_abs_diff(sim.field(FieldId::snow), expect);
  const double e_depth = max_abs_diff(sim.field(FieldId::water_depth), melted);
  const double speed = sim.diagnostics().max_speed;

  sim.step(std::lround(t_gone / dt));  // to 1.5 t*
  const auto snow_end = sim.field(FieldId::snow);
  const double left = *std::max_element(snow_end.begin(), snow_end.end());
  const double e_depth_end =
      max_abs_diff(sim.field(FieldId::water_depth), std::vector<double>(64, s0));
  const auto& L = sim.ledger();
  const double e_ledger = std::abs(L.snow_melted / area - s0);
  const double closure = std::abs(L.relative_closure_error());
  std::printf(
      "[snow flat] %s: at t*/2 max |snow - (S0 - DDF T t)| %.2e m, max |depth - DDF T t| %.2e m "
      "(bound %.1e m), max speed %.1e m/s (bound 0); at 1.5 t* snow left %.1e m (bound 0), max "
      "|depth - S0| %.2e m, |melted / area - S0| %.2e m (bound %.1e m), water closure %.1e of "
      "what moved (bound %.0e)\n",
      target().label().c_str(), e_snow, e_depth, bound, speed, left, e_depth_end, e_ledger, bound,
      closure, this->bound(1e-12, 4e-5));
  auto fig = [&](const char* q) {
    return figure("snow_flat", "degree_day", q, 1000.0, "S(t) = S0 - DDF (T - T_melt) t");
  };
  validation::expect_below(fig("max |snow - exact| at t*/2 (m)"), e_snow, bound);
  validation::expect_below(fig("max |depth - exact| at t*/2 (m)"), e_depth, bound);
  validation::expect_below(fig("max |depth - S0| at 1.5 t* (m)"), e_depth_end, bound);
  validation::expect_below(fig("|melted / area - S0| (m)"), e_ledger, bound);
  EXPECT_EQ(speed, 0.0) << "a uniform depth on a flat bed does not flow";
  EXPECT_EQ(left, 0.0) << "the pack is gone after t* (never more melt than the pack)";
  // The water closure counts the melt as a source. float32: each step rounds every cell's
  // d + melt to half an ulp of a depth below 0.125 m (3.7e-9 m), 1080 steps: 4.0e-6 m, 4.0e-5 of
  // S_0 (what moved); a melt that misses the depth or the ledger is off by 1.
  validation::expect_below(fig("water closure / what moved"), closure, this->bound(1e-12, 4e-5));
}

TEST_P(Snow, SnowLineRisesToThePredictedElevation) {
  // A ramp rising eastwards, 64 columns of 50 m at z = 25 m per column (0 .. 1575 m), 3 rows,
  // under S_0 = 0.2 m, 10 degrees C at 0 m, lapse -6.5 K/km, DDF 4 mm/d/K; the snow process
  // alone (Backend::run) for 10 days in steps of 1 h. A cell has melted out where
  // DDF T(z) t >= S_0, i.e. T(z) >= 5 degrees C: below z* = (10 - 5) / 0.0065 = 769.2 m. Every
  // cell's pack is the closed form max(0, S_0 - DDF max(0, T(z)) t) (float64 1e-12 of S_0,
  // float32 2e-5 of S_0 as above: 240 steps); the snow line, the lowest cell with snow, is the
  // first column above z*. Without the lapse rate every cell melts out (T = 10 degrees C
  // everywhere: 0.4 m in 10 days); with its sign wrong the line falls to the bottom.
  const int nx = 64;
  const double dx = 50.0, rise = 25.0, s0 = 0.2, ddf = 4e-3 / kDay, t0 = 10.0, lapse = -0.0065;
  const double dt = 3600.0, t = 10 * kDay;
  Terrain terrain = flat_terrain(nx, 3, dx);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < nx; ++c) terrain.bed[static_cast<std::size_t>(r) * nx + c] = rise * c;
  auto sim = make_simulation(terrain, snow_params(s0, ddf, t0, lapse, dt), target());
  const StepTally tally = run_processes(sim, {Process::snow}, dt, std::lround(t / dt));

  const auto snow = sim.field(FieldId::snow);
  std::vector<double> exact(snow.size());
  double melted_exact = 0.0;
  for (std::size_t i = 0; i < snow.size(); ++i) {
    const double z = terrain.bed[i], temperature = t0 + lapse * z;
    exact[i] = std::max(0.0, s0 - ddf * std::max(0.0, temperature) * t);
    melted_exact += (s0 - exact[i]) * dx * dx;
  }
  const double e_cells = max_abs_diff(snow, exact), bound = this->bound(1e-12, 2e-5) * s0;
  const double z_star = (t0 - s0 / (ddf * t)) / -lapse;
  int first_snow = nx;  // the lowest column with snow on the middle row
  for (int c = 0; c < nx && first_snow == nx; ++c)
    if (snow[static_cast<std::size_t>(nx) + c] > 0) first_snow = c;
  const double line = rise * first_snow;
  const double e_melted = std::abs(tally.snow_melted - melted_exact) / melted_exact;
  std::printf(
      "[snow line] %s: snow line after 10 d at %.0f m (the first column above z* = %.1f m: "
      "%.0f m); max |snow - exact| %.2e m (bound %.1e m); melted %.6e m^3, exact %.6e m^3 "
      "(relative %.1e, bound %.0e)\n",
      target().label().c_str(), line, z_star, std::ceil(z_star / rise) * rise, e_cells, bound,
      tally.snow_melted, melted_exact, e_melted, this->bound(1e-12, 2e-5));
  auto fig = [&](const char* q) {
    return figure("snow_line", "degree_day", q, dx, "z* = (T_ref - S0 / (DDF t)) / -lapse");
  };
  EXPECT_EQ(line, std::ceil(z_star / rise) * rise) << "the snow line is the first cell above z*";
  validation::expect_below(fig("max |snow - exact| (m)"), e_cells, bound);
  validation::expect_below(fig("|melted / exact - 1|"), e_melted, this->bound(1e-12, 2e-5));
}

TEST_P(Snow, InitialPackLiesAboveTheSnowLineOnly) {
  // snow.snow_line = 400 m on the ramp of 25 m per column: the pack starts on the columns at
  // or above 400 m (16 .. 63) and nowhere else; the ledger starts with no melt.
  const int nx = 64;
  Terrain terrain = flat_terrain(nx, 3, 50.0);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < nx; ++c) terrain.bed[static_cast<std::size_t>(r) * nx + c] = 25.0 * c;
  Params p = snow_params(0.3, 4e-3 / kDay, -5.0, -0.0065, 60.0);
  p.snow.snow_line = 400.0;
  auto sim = make_simulation(terrain, p, target());
  const auto snow = sim.field(FieldId::snow);
  int wrong = 0;
  for (int c = 0; c < nx; ++c)
    for (int r = 0; r < 3; ++r) {
      const double expect = 25.0 * c >= 400.0 ? static_cast<double>(static_cast<float>(0.3)) : 0.0;
      const double v = snow[static_cast<std::size_t>(r) * nx + c];
      if (target().f64() ? v != (expect ? 0.3 : 0.0) : v != expect) ++wrong;
    }
  std::printf("[snow initial] %s: %d of %d cells differ from the snow-line rule (bound 0)\n",
              target().label().c_str(), wrong, 3 * nx);
  EXPECT_EQ(wrong, 0);
  EXPECT_EQ(sim.ledger().snow_melted, 0.0);
}

TEST_P(Snow, RainOnSnowAddsExactlyItsHeatTerm) {
  // The flat tile of 8 x 8 cells of 1 km under S_0 = 0.1 m at 5 degrees C (above the snowfall
  // threshold of 1 degree C), DDF 5 mm/d/K, rain r = 10 mm/h for 12 h in steps of 600 s,
  // retention 0 (all liquid water reaches the depth in its step). The pack melts at
  // DDF T + r c_w T / L_f: the rain's heat adds r t c_w T / L_f = 7.52 mm to the 12.5 mm of the
  // degree days. Checked: every cell's pack against S_0 - (DDF T + r c_w T / L_f) t, the
  // ledger's melt minus the degree days against the heat term, the depth against rain + melt
  // (uniform: no flow) and the water closure. Bounds: float64 1e-12 (rounding), float32 as the
  // flat pack's (72 steps: 2e-5 of S_0 for the pack and depth; 1e-5 relative for the heat term,
  // a sum of 72 per-step melts each rounded to 6e-8). Without the heat term the melt is short
  // by 7.52 mm (1.0 of the term), and rain kept off the pack leaves the depth 0.12 m too low.
  const double s0 = 0.1, ddf = 5e-3 / kDay, t_air = 5.0, dt = 600.0, r = 10e-3 / 3600.0;
  const long steps = 72;
  const double t = steps * dt;
  Params p = snow_params(s0, ddf, t_air, 0.0, dt);
  p.rain.rate = r;
  auto sim = make_simulation(flat_terrain(8, 8, 1000.0), p, target());
  sim.step(steps);
  const double area = 64 * 1e6, heat = r * t * 4186.0 * t_air / 334000.0;
  const double melt = ddf * t_air * t + heat;
  const double e_snow = max_abs_diff(sim.field(FieldId::snow), std::vector<double>(64, s0 - melt));
  const double e_depth =
      max_abs_diff(sim.field(FieldId::water_depth), std::vector<double>(64, r * t + melt));
  const auto& L = sim.ledger();
  const double heat_measured = L.snow_melted / area - ddf * t_air * t;
  const double e_heat = std::abs(heat_measured / heat - 1.0);
  const double e_rain = std::abs(L.rain_on_snow / (r * t * area) - 1.0);
  const double closure = std::abs(L.relative_closure_error());
  const double bound = this->bound(1e-12, 2e-5) * s0;
  std::printf(
      "[snow rain-on-snow] %s: heat term %.6e m, exact r t c_w T / L_f %.6e m (relative %.1e, "
      "bound %.0e); max |snow - exact| %.2e m, max |depth - (r t + melt)| %.2e m (bound %.1e "
      "m); rain on snow / (r t area) - 1 %.1e (bound %.0e); water closure %.1e (bound %.0e)\n",
      target().label().c_str(), heat_measured, heat, e_heat, this->bound(1e-10, 1e-5), e_snow,
      e_depth, bound, e_rain, this->bound(1e-12, 1e-6), closure, this->bound(1e-12, 4e-5));
  auto fig = [&](const char* q) {
    return figure("snow_rain_on_snow", "degree_day", q, 1000.0,
                  "M = DDF (T - T_melt) dt + P c_w T / L_f");
  };
  validation::expect_below(fig("|heat term / exact - 1|"), e_heat, this->bound(1e-10, 1e-5));
  validation::expect_below(fig("max |snow - exact| (m)"), e_snow, bound);
  validation::expect_below(fig("max |depth - exact| (m)"), e_depth, bound);
  validation::expect_below(fig("|rain on snow / (r t area) - 1|"), e_rain,
                           this->bound(1e-12, 1e-6));
  validation::expect_below(fig("water closure / what moved"), closure, this->bound(1e-12, 4e-5));
}

TEST_P(Snow, SnowfallBelowTheThresholdGoesToThePackAndTheLedgerCloses) {
  // 1. The flat tile at -3 degrees C (below the snowfall threshold of 1 degree C) under
  // S_0 = 0.05 m, rain r = 5 mm/h for 12 h in steps of 600 s: all of it falls as snow. Every
  // cell's pack is S_0 + r t, no water stays on the depth (the snow sweep takes back exactly
  // what the sources poured: the same expression), the ledger's snowfall is r t area, and both
  // budgets close: the water (the pack outside it) and the pack's,
  // sum snow area (t) - sum snow area (0) = snowfall - melted. Bounds: float64 1e-12, float32
  // 2e-5 of S_0 for the pack (72 additions rounded to half an ulp of 0.1) and of what crossed.
  // A sweep that leaves the rain on the depth fails every figure.
  const double dt = 600.0, r = 5e-3 / 3600.0, s0 = 0.05;
  const long steps = 72;
  const double t = steps * dt, area = 64 * 1e6;
  Params p = snow_params(s0, 4e-3 / kDay, -3.0, 0.0, dt);
  p.snow.retention = 0.1;
  p.rain.rate = r;
  auto flat = make_simulation(flat_terrain(8, 8, 1000.0), p, target());
  double snow0 = 0.0;
  for (double v : flat.field(FieldId::snow)) snow0 += v * 1e6;
  flat.step(steps);
  const double e_snow =
      max_abs_diff(flat.field(FieldId::snow), std::vector<double>(64, s0 + r * t));
  const auto depth = flat.field(FieldId::water_depth);
  const double d_max = *std::max_element(depth.begin(), depth.end());
  const auto& L = flat.ledger();
  const double e_fall = std::abs(L.snowfall / (r * t * area) - 1.0);
  const double closure = std::abs(L.relative_closure_error());
  const PackClosure pack = pack_closure(flat, snow0, 1e6);
  const double bound = this->bound(1e-12, 2e-5);
  std::printf(
      "[snow snowfall flat] %s: max |snow - (S0 + r t)| %.2e m (bound %.1e m), max depth %.1e m "
      "(bound %.1e m), snowfall / (r t area) - 1 %.1e (bound %.0e), water closure %.1e, pack "
      "closure %.1e, solid %.1e (bound %.0e)\n",
      target().label().c_str(), e_snow, bound * s0, d_max, this->bound(1e-15, 1e-7) * r * t, e_fall,
      this->bound(1e-12, 1e-6), closure, pack.whole, pack.solid, bound);
  auto fig = [&](const char* q, double dx) {
    return figure("snow_snowfall", "degree_day", q, dx, "S(t) = S0 + r t below the threshold");
  };
  validation::expect_below(fig("max |snow - (S0 + r t)| (m)", 1000.0), e_snow, bound * s0);
  validation::expect_below(fig("max depth (m)", 1000.0), d_max, this->bound(1e-15, 1e-7) * r * t);
  validation::expect_below(fig("|snowfall / (r t area) - 1|", 1000.0), e_fall,
                           this->bound(1e-12, 1e-6));
  validation::expect_below(fig("flat: water closure / what moved", 1000.0), closure, bound);
  validation::expect_below(fig("flat: pack closure / what crossed", 1000.0), pack.whole, bound);
  validation::expect_below(fig("flat: solid pack closure", 1000.0), pack.solid, bound);

  // 2. Everything at once on the ramp of 25 m per 50 m column (0 .. 1575 m): 6 degrees C at
  // 0 m, -6.5 K/km (rain below 769 m, snow above), S_0 = 0.1 m, retention 0.1, rain 5 mm/h for
  // 6 h, DDF 4 mm/d/K, Manning 0.05 with adaptive steps: rain on snow, melt, runoff that flows
  // down the ramp between closed walls. The snowfall is r t times the area where T < 1 (the
  // sources' rain stays on a cell through its step: the flow's outflows come from the depth
  // before it); the water and pack budgets close to rounding (float32: a few 1e-7 of what
  // moved per step in the water (local inertial), 1e-4 bound).
  const int nx = 64;
  const double dx = 50.0, rise = 25.0;
  Terrain ramp = flat_terrain(nx, 3, dx);
  for (int row = 0; row < 3; ++row)
    for (int c = 0; c < nx; ++c) ramp.bed[static_cast<std::size_t>(row) * nx + c] = rise * c;
  Params q = snow_params(0.1, 4e-3 / kDay, 6.0, -0.0065, 60.0);
  q.snow.retention = 0.1;
  q.rain.rate = r;
  q.flow.manning_n.value = 0.05;
  q.time.adaptive = true;
  q.time.dt_max = 60.0;
  q.time.duration = 6 * 3600.0;
  auto sim = make_simulation(ramp, q, target());
  const auto s_start = sim.field(FieldId::snow);
  double ramp_snow0 = 0.0;
  for (double v : s_start) ramp_snow0 += v * dx * dx;
  sim.run();
  double cold = 0.0;  // the area where it snows (m^2)
  for (double z : ramp.bed)
    if (6.0 - 0.0065 * z < 1.0) cold += dx * dx;
  const auto& M = sim.ledger();
  const double e_ramp_fall = std::abs(M.snowfall / (r * q.time.duration * cold) - 1.0);
  const double ramp_closure = std::abs(M.relative_closure_error());
  const PackClosure ramp_pack = pack_closure(sim, ramp_snow0, dx * dx);
  const double ramp_bound = this->bound(1e-12, 1e-4);
  std::printf(
      "[snow snowfall ramp] %s: snowfall / (r t cold area) - 1 %.1e (bound %.0e); rain on snow "
      "%.4e m^3, melted %.4e m^3, runoff %.4e m^3 (each > 0); water closure %.1e, pack closure "
      "%.1e, solid %.1e (bound %.0e)\n",
      target().label().c_str(), e_ramp_fall, this->bound(1e-12, 1e-6), M.rain_on_snow,
      M.snow_melted, M.snow_runoff, ramp_closure, ramp_pack.whole, ramp_pack.solid, ramp_bound);
  validation::expect_below(fig("ramp: |snowfall / (r t cold area) - 1|", dx), e_ramp_fall,
                           this->bound(1e-12, 1e-6));
  validation::expect_below(fig("ramp: water closure / what moved", dx), ramp_closure, ramp_bound);
  validation::expect_below(fig("ramp: pack closure / what crossed", dx), ramp_pack.whole,
                           ramp_bound);
  validation::expect_below(fig("ramp: solid pack closure", dx), ramp_pack.solid, ramp_bound);
  EXPECT_GT(M.rain_on_snow, 0.0);
  EXPECT_GT(M.snow_melted, 0.0);
  EXPECT_GT(M.snow_runoff, 0.0);
}

TEST_P(Snow, RetentionHoldsTheMeltUpToItsFractionOfThePack) {
  // The flat pack of the first test (S_0 = 0.1 m, 4 degrees C, DDF 5 mm/d/K: melt rate
  // m = 20 mm/d, t* = 5 d) holding liquid water up to theta = 0.1 of the pack. The melt stays in
  // the pack until m t = theta (S_0 - m t), at t_w = theta S_0 / (m (1 + theta)) = 0.4545 d;
  // then the liquid water is theta S(t) and the depth m t - theta S(t); when the pack is gone
  // all S_0 is on the depth. Checked at 0.2 d (no water on the depth, liquid m t), 1 d (depth
  // 12 mm, liquid 8 mm), 6 d (no pack, no liquid, depth S_0); and at every step the liquid is
  // at most theta times the pack. Bounds: float64 1e-12, float32 2e-5 of S_0 (as the flat
  // pack). Without retention the depth at 0.2 d is 4 mm, at 1 d 20 mm.
  const double s0 = 0.1, ddf = 5e-3 / kDay, t_air = 4.0, dt = 600.0, theta = 0.1;
  const double rate = ddf * t_air;
  Params p = snow_params(s0, ddf, t_air, 0.0, dt);
  p.snow.retention = theta;
  auto sim = make_simulation(flat_terrain(8, 8, 1000.0), p, target());
  const double bound = this->bound(1e-12, 2e-5) * s0;
  double over = 0.0;  // the largest liquid - theta snow (m)
  auto run_to = [&](long step) {
    while (sim.steps_done() < step) {
      sim.step();
      const auto s = sim.field(FieldId::snow), l = sim.field(FieldId::snow_liquid);
      for (std::size_t i = 0; i < s.size(); ++i) over = std::max(over, l[i] - theta * s[i]);
    }
  };
  const double t_w = theta * s0 / (rate * (1 + theta));
  run_to(30);  // 0.208 d < t_w
  const double t1 = 30 * dt;
  ASSERT_LT(t1, t_w);
  const double e_l1 =
      max_abs_diff(sim.field(FieldId::snow_liquid), std::vector<double>(64, rate * t1));
  const auto d1 = sim.field(FieldId::water_depth);
  const double d1_max = *std::max_element(d1.begin(), d1.end());
  run_to(144);  // 1 d
  const double t2 = 144 * dt, s2 = s0 - rate * t2;
  const double e_l2 =
      max_abs_diff(sim.field(FieldId::snow_liquid), std::vector<double>(64, theta * s2));
  const double e_d2 = max_abs_diff(sim.field(FieldId::water_depth),
                                   std::vector<double>(64, rate * t2 - theta * s2));
  run_to(864);  // 6 d
  const auto l3 = sim.field(FieldId::snow_liquid);
  const double l3_max = *std::max_element(l3.begin(), l3.end());
  const double e_d3 = max_abs_diff(sim.field(FieldId::water_depth), std::vector<double>(64, s0));
  std::printf(
      "[snow retention] %s: t_w = %.4f d; at 0.21 d max depth %.1e m (bound 0), max |liquid - m "
      "t| %.2e m; at 1 d max |liquid - theta S| %.2e m, max |depth - (m t - theta S)| %.2e m; at "
      "6 d liquid %.1e m (bound 0), max |depth - S0| %.2e m (bound %.1e m); max liquid - theta "
      "S over all steps %.1e m (bound %.1e m)\n",
      target().label().c_str(), t_w / kDay, d1_max, e_l1, e_l2, e_d2, l3_max, e_d3, bound, over,
      bound);
  auto fig = [&](const char* q) {
    return figure("snow_retention", "degree_day", q, 1000.0, "L = min(m t, theta S), d = m t - L");
  };
  EXPECT_EQ(d1_max, 0.0) << "no water leaves the pack before t_w";
  validation::expect_below(fig("max |liquid - m t| before t_w (m)"), e_l1, bound);
  validation::expect_below(fig("max |liquid - theta S| at 1 d (m)"), e_l2, bound);
  validation::expect_below(fig("max |depth - (m t - theta S)| at 1 d (m)"), e_d2, bound);
  validation::expect_below(fig("max |depth - S0| at 6 d (m)"), e_d3, bound);
  validation::expect_below(fig("max (liquid - theta S) over the steps (m)"), over, bound);
  EXPECT_EQ(l3_max, 0.0) << "no liquid water without a pack";
}

TEST_P(Snow, TemperatureSeriesMeltFollowsItsDegreeDays) {
  // T_ref(t) from the config key snow.air_temperature as a series [[0, -5], [5 d, 15]]
  // (degrees C), held at 15 after 5 d; the flat pack S_0 = 0.2 m on 8 x 8 cells of 10 km, DDF
  // 4 mm/d/K, T_melt 0, retention 0, steps of 1 h (Courant 0.47 at the 0.17 m of melt). The melt is
  // DDF times the integral of max(0, T): T crosses 0 at t_0 = 1.25 d (a step boundary), so the
  // step-midpoint values integrate the linear series exactly: 2 (t - t_0)^2 K d to 5 d, then 15 K d
  // per day: 24.5 mm at 3 d, 172.5 mm at 6 d. Bounds as the flat pack (float64 1e-12, float32 2e-5
  // of S_0). The constant T_ref of the number (0 degrees C) melts nothing; the series read at the
  // step's start melts about 0.6 mm less by 3 d (150 times the float32 bound).
  const double s0 = 0.2, ddf = 4e-3 / kDay, dt = 3600.0;
  Params p = snow_params(s0, ddf, 0.0, 0.0, dt);
  apply_setting(p, "snow.air_temperature", "[[0, -5], [432000, 15]]");
  ASSERT_EQ(p.snow.air_temperature_series.size(), 2u);
  auto sim = make_simulation(flat_terrain(8, 8, 10000.0), p, target());
  const double bound = this->bound(1e-12, 2e-5) * s0;
  auto melt_at = [&](double days) {  // DDF times the degree days of the series (m)
    const double t0 = 1.25, hot = std::min(days, 5.0) - t0;
    return ddf * kDay * (2.0 * hot * hot + 15.0 * std::max(days - 5.0, 0.0));
  };
  sim.step(72);  // 3 d
  const double e3 =
      max_abs_diff(sim.field(FieldId::snow), std::vector<double>(64, s0 - melt_at(3.0)));
  sim.step(72);  // 6 d
  const double e6 =
      max_abs_diff(sim.field(FieldId::snow), std::vector<double>(64, s0 - melt_at(6.0)));
  const double e_depth =
      max_abs_diff(sim.field(FieldId::water_depth), std::vector<double>(64, melt_at(6.0)));
  // a number clears the series: the constant again
  Params c = p;
  apply_setting(c, "snow.air_temperature", "3");
  std::printf(
      "[snow series] %s: melt by 3 d %.4f m, by 6 d %.4f m (closed form); max |snow - exact| at "
      "3 d %.2e m, at 6 d %.2e m, max |depth - melt| at 6 d %.2e m (bound %.1e m)\n",
      target().label().c_str(), melt_at(3.0), melt_at(6.0), e3, e6, e_depth, bound);
  auto fig = [&](const char* q) {
    return figure("snow_series", "degree_day", q, 10000.0,
                  "S(t) = S0 - DDF integral of max(0, T_ref(t)) dt");
  };
  validation::expect_below(fig("max |snow - exact| at 3 d (m)"), e3, bound);
  validation::expect_below(fig("max |snow - exact| at 6 d (m)"), e6, bound);
  validation::expect_below(fig("max |depth - melt| at 6 d (m)"), e_depth, bound);
  EXPECT_TRUE(c.snow.air_temperature_series.empty());
  EXPECT_EQ(c.snow.air_temperature, 3.0);
}

TEST_P(Snow, InitialPackFollowsTheTransitionBandAndTheSlopeLimit) {
  // A ramp of 64 columns of 50 m, 3 rows: 25 m per column (26.6 degrees) up to column 40, then
  // 60 m per column (50.2 degrees). snow.snow_line 400 m with snow.transition 200 m: the pack
  // ramps from 0 at 300 m to S_0 = 0.3 m at 500 m; snow.max_slope 35 degrees: none where the
  // central-difference slope (one-sided at the west and east edges) is 35 degrees or more
  // (columns 40 .. 63: the kink's column 40 has (1060 - 975) / 100 = 0.85, 40.4 degrees).
  // Every cell against the rule computed here (bound: float64 1e-15, float32 1e-7 of S_0); the
  // sharp snow line of the old rule differs on the 7 columns of the band, no slope limit on 24.
  const int nx = 64;
  const double dx = 50.0, s0 = 0.3;
  Terrain terrain = flat_terrain(nx, 3, dx);
  std::vector<double> z(nx);
  for (int c = 0; c < nx; ++c) z[c] = c <= 40 ? 25.0 * c : 1000.0 + 60.0 * (c - 40);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < nx; ++c) terrain.bed[static_cast<std::size_t>(r) * nx + c] = z[c];
  Params p = snow_params(s0, 4e-3 / kDay, -5.0, -0.0065, 60.0);
  p.snow.snow_line = 400.0;
  p.snow.transition = 200.0;
  p.snow.max_slope = 35.0;
  auto sim = make_simulation(terrain, p, target());
  const auto snow = sim.field(FieldId::snow);
  double worst = 0.0;
  int in_band = 0, too_steep = 0;
  const double pi = 3.14159265358979323846;
  for (int c = 0; c < nx; ++c) {
    const int a = std::max(c - 1, 0), b = std::min(c + 1, nx - 1);
    const double slope = std::atan(std::abs(z[b] - z[a]) / ((b - a) * dx)) * 180.0 / pi;
    const double share = std::clamp((z[c] - 300.0) / 200.0, 0.0, 1.0);
    const double expect = slope < 35.0 ? s0 * share : 0.0;
    in_band += share > 0 && share < 1;
    too_steep += !(slope < 35.0);
    for (int r = 0; r < 3; ++r)
      worst = std::max(worst, std::abs(snow[static_cast<std::size_t>(r) * nx + c] - expect));
  }
  const double bound = this->bound(1e-15, 1e-7) * s0;
  std::printf(
      "[snow initial rule] %s: %d columns in the band, %d too steep; max |snow - rule| %.1e m "
      "(bound %.1e m)\n",
      target().label().c_str(), in_band, too_steep, worst, bound);
  EXPECT_EQ(in_band, 7);
  EXPECT_EQ(too_steep, 24);
  validation::expect_below(figure("snow_initial_rule", "degree_day", "max |snow - rule| (m)", dx,
                                  "linear band, central-difference slope limit"),
                           worst, bound);
}

TEST_P(Snow, PackSlidesDownSlopesSteeperThanTheSlideAngle) {
  // 8 columns of 10 m, 3 rows: a 60 degree slope falling eastwards over columns 0 .. 5
  // (17.32 m per column), flat from column 5 on; S_0 = 0.1 m everywhere at -10 degrees C (no
  // melt), snow.slide_angle 45 degrees; the snow process alone. With slide_rate dt = 1 each
  // steep cell gives its whole pack to its only lower neighbour (east; the rows are level)
  // every step: after 5 steps the pack of columns 0 .. 5 lies on column 5 (6 S_0), columns
  // 0 .. 4 are bare and 6, 7 keep S_0. With slide_rate dt = 1/4, one step: column 0 keeps
  // 0.75 S_0, 1 .. 4 give and take S_0 / 4, column 5 gets 1.25 S_0. With the slide angle at
  // 65 degrees (steeper than the ramp) nothing moves. Every cell against these to float64
  // 1e-14, float32 1e-6 of S_0 (the share's division by the excess drop, 7.3 m, rounds), and
  // the pack's volume is kept (same bounds, relative). An idle or one-sided sweep fails
  // column 5 by 5 S_0 or the volume by S_0 per step.
  const int nx = 8;
  const double dx = 10.0, s0 = 0.1, drop = dx * std::tan(60.0 * 3.14159265358979323846 / 180.0);
  Terrain terrain = flat_terrain(nx, 3, dx);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < nx; ++c)
      terrain.bed[static_cast<std::size_t>(r) * nx + c] = c < 5 ? drop * (5 - c) : 0.0;
  const double bound = this->bound(1e-14, 1e-6) * s0;
  struct Case {
    double angle, rate_dt;
    long steps;
    std::vector<double> expect;  // per column, in units of S_0
  };
  const Case cases[] = {{45.0, 1.0, 5, {0, 0, 0, 0, 0, 6, 1, 1}},
                        {45.0, 0.25, 1, {0.75, 1, 1, 1, 1, 1.25, 1, 1}},
                        {65.0, 1.0, 5, {1, 1, 1, 1, 1, 1, 1, 1}}};
  for (const Case& k : cases) {
    const double dt = 3600.0;
    Params p = snow_params(s0, 4e-3 / kDay, -10.0, 0.0, dt);
    p.snow.slide_angle = k.angle;
    p.snow.slide_rate = k.rate_dt / dt;
    auto sim = make_simulation(terrain, p, target());
    const auto start = sim.field(FieldId::snow);
    run_processes(sim, {Process::snow}, dt, k.steps);
    const auto snow = sim.field(FieldId::snow);
    double worst = 0.0, before = 0.0, after = 0.0;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < nx; ++c) {
        const auto i = static_cast<std::size_t>(r) * nx + c;
        worst = std::max(worst, std::abs(snow[i] - k.expect[static_cast<std::size_t>(c)] * s0));
        before += start[i];
        after += snow[i];
      }
    const double kept = std::abs(after / before - 1.0);
    std::printf(
        "[snow slide] %s: angle %.0f deg, rate dt %.2f, %ld steps: max |snow - expected| %.1e m "
        "(bound %.1e m), |volume after / before - 1| %.1e (bound %.0e)\n",
        target().label().c_str(), k.angle, k.rate_dt, k.steps, worst, bound, kept,
        this->bound(1e-14, 1e-6));
    auto fig = [&](const char* q) {
      return figure("snow_slide", "degree_day", q, dx, "pack moved down slopes above the angle");
    };
    validation::expect_below(fig("max |snow - expected| (m)"), worst, bound);
    validation::expect_below(fig("|volume after / before - 1|"), kept, this->bound(1e-14, 1e-6));
  }
}

ERODEM_INSTANTIATE_TARGETS(Snow);

}  // namespace
}  // namespace erodem::test
