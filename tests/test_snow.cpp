// erodem — the snow pack (kernels/common/snow.h, model.md section 2 step 8): degree-day melt
// against its closed forms, on every target. Each test prints the measured figure beside its
// bound; a solver that leaves the pack as it was, melts at another rate or temperature, or
// loses the melt fails.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "scenarios.hpp"
#include "target_test.hpp"
#include "validation_record.hpp"

namespace erodem::test {
namespace {

class Snow : public TargetTest {};

constexpr double kDay = 86400.0;

/// Every other process off, a pack of `initial` m everywhere, melting at `ddf` (m/s per K)
/// above 0 degrees C at `t_ref` degrees C at 0 m, lapse rate `lapse` (K/m).
Params snow_params(double initial, double ddf, double t_ref, double lapse, double dt) {
  Params p = quiet_params(FlowScheme::local_inertial, dt);
  p.snow.enabled = true;
  p.snow.initial = initial;
  p.snow.melt_factor = ddf;
  p.snow.melt_temperature = 0.0;
  p.snow.air_temperature = t_ref;
  p.snow.reference_elevation = 0.0;
  p.snow.lapse_rate = lapse;
  return p;
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

ERODEM_INSTANTIATE_TARGETS(Snow);

}  // namespace
}  // namespace erodem::test
