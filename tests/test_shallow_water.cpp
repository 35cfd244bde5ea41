// erodem — the shallow-water scheme (flow.scheme = "shallow_water", model.md section 3.10)
// against closed forms: Stoker's and Ritter's dam breaks converging at their observed order,
// and lakes at rest on real DEMs, projected and geographic. Each test prints its figures
// beside their bounds; an idle solver scores 1 on every relative error (and no order), a
// scheme without the advection term (local inertial) stays at 0.27 of Stoker's change at every
// resolution, and one that is not well balanced moves a lake at rest.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "erodem/io/setup.hpp"
#include "scenarios.hpp"
#include "target_test.hpp"
#include "validation_record.hpp"

namespace erodem::test {
namespace vr = validation;
namespace {

class ShallowWater : public TargetTest {};

constexpr double kMargin = 20.0;  // m on each side of the region the wave reached

/// Frictionless, closed, fixed steps of dt: the dam-break set-up of test_analytical.cpp.
Params sw_params(double dt) {
  return quiet_params(FlowScheme::shallow_water, dt);
}

/// One rung of a dam-break ladder: the errors over [lo, hi] relative to an idle solver's.
struct Rung {
  double dx, depth, discharge, velocity, front;
};

/// The dam break `exact` (Stoker or Ritter: depth(x, t), velocity(x, t)) on a 1000 m channel
/// with the dam at 500 m, `h_up` onto `h_down`, at dx = 4, 2, 1 m (and 0.5 m for the full
/// ladder), steps of 0.04 dx s (the unsplit Courant number stays below 0.5: (|u| + c) dt / dx
/// + c dt / dy <= 0.46 for Stoker's 2 m onto 1 m), to t_end; `front_depth`: the threshold that
/// finds the front or shock on both profiles.
template <class Exact>
std::vector<Rung> ladder(const Target& target, const Exact& exact, double h_up, double h_down,
                         double t_end, double lo, double hi, double front_depth) {
  std::vector<double> sizes{2.0, 1.0, 0.5};
  if (vr::full_ladder()) sizes.push_back(0.25);
  std::vector<Rung> out;
  for (double dx : sizes) {
    const int n = static_cast<int>(std::lround(1000.0 / dx));
    const DamBreak db{n, dx, 500.0, h_up, h_down};
    auto sim = make_simulation(db.terrain(), sw_params(0.08 * dx), target);
    sim.step(std::lround(t_end / (0.08 * dx)));
    const Row row = db.row();
    const auto h = middle_row(sim, FieldId::water_depth);
    const auto q = middle_row(sim, FieldId::momentum_x);
    const auto u = middle_row(sim, FieldId::velocity_x);
    const auto h_x = row.sample([&](double x) { return exact.depth(x, t_end); });
    const auto u_x = row.sample([&](double x) { return exact.velocity(x, t_end); });
    std::vector<double> q_x(h_x.size());
    for (std::size_t i = 0; i < q_x.size(); ++i) q_x[i] = h_x[i] * u_x[i];
    const auto h_idle = db.initial_depth();
    const std::vector<double> zero(h_idle.size(), 0.0);
    out.push_back({dx, relative_l1(row, h, h_x, h_idle, lo, hi),
                   relative_l1(row, q, q_x, zero, lo, hi), relative_l1(row, u, u_x, zero, lo, hi),
                   last_above(row, h, front_depth) / last_above(row, h_x, front_depth)});
  }
  return out;
}

TEST_P(ShallowWater, StokerDamBreakConverges) {
  // 2 m onto 1 m, 40 s: the rarefaction's head at -177 m, the shock (h2 = 1.4556 m, u2 = 2.50
  // m/s) at +212 m. First-order Godunov converges at about 0.8 in L1 on a solution with a
  // shock; bounds from the issue: order >= 0.7 for depth and discharge between each pair of
  // rungs, and the finest depth error below 5 % of the change. The local-inertial scheme
  // scores 0.27 at every dx (no advection term: Analytical.LocalInertialDamBreakConverges),
  // an idle solver 1.
  const Stoker exact(2.0, 1.0);
  const double t_end = 40.0, lo = exact.head(t_end) - kMargin, hi = exact.shock * t_end + kMargin;
  const auto rungs = ladder(target(), exact, 2.0, 1.0, t_end, lo, hi, 0.5 * (exact.h1 + exact.h2));
  auto fig = [&](const char* q, double dx) {
    return figure("sw_stoker", "shallow_water", q, dx, "Stoker (1957)");
  };
  for (std::size_t k = 0; k < rungs.size(); ++k) {
    const Rung& r = rungs[k];
    std::printf(
        "[sw Stoker] %s dx = %.1f m: depth error %.4f, discharge error %.4f, velocity error "
        "%.4f (of an idle solver's), shock at %.4f of Stoker's\n",
        target().label().c_str(), r.dx, r.depth, r.discharge, r.velocity, r.front);
    vr::report(fig("depth error (relative L1)", r.dx), r.depth);
    vr::report(fig("discharge error (relative L1)", r.dx), r.discharge);
    vr::report(fig("velocity error (relative L1)", r.dx), r.velocity);
    vr::expect_between(fig("shock position / Stoker's", r.dx), r.front, 0.97, 1.03);
    if (k == 0) continue;
    const double p_h = observed_order(rungs[k - 1].depth, r.depth);
    const double p_q = observed_order(rungs[k - 1].discharge, r.discharge);
    std::printf(
        "[sw Stoker] %s dx %.1f -> %.1f m: observed order depth %.2f, discharge %.2f "
        "(bound >= 0.7)\n",
        target().label().c_str(), rungs[k - 1].dx, r.dx, p_h, p_q);
    vr::expect_above(fig("observed order, depth", r.dx), p_h, 0.7);
    vr::expect_above(fig("observed order, discharge", r.dx), p_q, 0.7);
  }
  vr::expect_below(fig("depth error at the finest dx (relative L1)", rungs.back().dx),
                   rungs.back().depth, 0.05);
}

TEST_P(ShallowWater, RitterDryDamBreakConverges) {
  // 2 m onto a dry bed, 30 s: the fan from -133 m to the front at 2 c0 t = +266 m. Orders >= 0.7
  // for depth and discharge (the velocity near a dry front is not bounded: it is 2 c0 at the
  // tip, where the depth vanishes); the front (h > 1 mm) within 10 % of Ritter's at the finest
  // dx. The local-inertial front lags by 64 % at every dx (RitterDryDamBreak).
  const Ritter exact{2.0};
  const double t_end = 30.0, lo = exact.head(t_end) - kMargin, hi = exact.front(t_end) + kMargin;
  const auto rungs = ladder(target(), exact, 2.0, 0.0, t_end, lo, hi, 1e-3);
  auto fig = [&](const char* q, double dx) {
    return figure("sw_ritter", "shallow_water", q, dx, "Ritter (1892)");
  };
  for (std::size_t k = 0; k < rungs.size(); ++k) {
    const Rung& r = rungs[k];
    std::printf(
        "[sw Ritter] %s dx = %.1f m: depth error %.4f, discharge error %.4f, velocity error "
        "%.4f (of an idle solver's), front (h > 1 mm) at %.4f of Ritter's\n",
        target().label().c_str(), r.dx, r.depth, r.discharge, r.velocity, r.front);
    vr::report(fig("depth error (relative L1)", r.dx), r.depth);
    vr::report(fig("discharge error (relative L1)", r.dx), r.discharge);
    vr::report(fig("velocity error (relative L1)", r.dx), r.velocity);
    vr::report(fig("front position / Ritter's", r.dx), r.front);
    if (k == 0) continue;
    const double p_h = observed_order(rungs[k - 1].depth, r.depth);
    const double p_q = observed_order(rungs[k - 1].discharge, r.discharge);
    std::printf(
        "[sw Ritter] %s dx %.1f -> %.1f m: observed order depth %.2f, discharge %.2f "
        "(bound >= 0.7)\n",
        target().label().c_str(), rungs[k - 1].dx, r.dx, p_h, p_q);
    vr::expect_above(fig("observed order, depth", r.dx), p_h, 0.7);
    vr::expect_above(fig("observed order, discharge", r.dx), p_q, 0.7);
  }
  vr::expect_between(fig("front position / Ritter's at the finest dx", rungs.back().dx),
                     rungs.back().front, 0.9, 1.02);
}

/// The largest |q| (m^2/s) and speed (m/s) over the grid.
std::array<double, 2> max_discharge_and_speed(const Simulation& sim) {
  const auto qx = sim.field(FieldId::momentum_x), qy = sim.field(FieldId::momentum_y);
  const auto u = sim.field(FieldId::velocity_x), v = sim.field(FieldId::velocity_y);
  double q = 0, s = 0;
  for (std::size_t i = 0; i < qx.size(); ++i) {
    if (std::isnan(qx[i])) continue;
    q = std::max(q, std::hypot(qx[i], qy[i]));
    s = std::max(s, std::hypot(u[i], v[i]));
  }
  return {q, s};
}

TEST_P(ShallowWater, LakeAtRestOnAGeographicDem) {
  // A lat/lon window of the Rhine DEM (30" cells: dx shrinks northwards with cos(latitude),
  // so the north and south faces of every cell differ in length by about 1e-4 of their own
  // length), filled to 80 m: a lake over the valley floors (up to 63 m deep) with a ragged shore,
  // dry hills above it, closed window edges. At rest the fluxes' pressure g h^2 / 2 differs between
  // the north and south faces by g h^2 / 2 (L_S - L_N); the side-pressure source balances it.
  // Without it a 60 m deep cell would gain |q| ~ g h^2 / 2 (L_S - L_N) dt / A ~ 1e-2 m^2/s in
  // the first step. Bound (the issue's): |q| <= 1e-10 m^2/s in float64 after 2000 steps of
  // 5 s. float32: each step rounds the pressure flux g h^2 / 2 = 1.95e4 m^3/s^2 of a 63 m
  // column to 6e-8 of itself, through 4 faces of 927 m into a cell of 5.4e5 m^2 over 5 s:
  // 4e-5 m^2/s a step at worst, a random walk of 2000 steps 45 times that: 2e-3 m^2/s.
  Params p = sw_params(5.0);
  p.dem.path = std::string(ERODEM_SHARED_DIR) + "/data/dem/rhine/rhine_elv0.tif";
  p.dem.window = std::array<int, 4>{260, 100, 60, 60};
  p.initial.water_level = 80.0;
  const Terrain terrain = io::load_terrain(p);
  long wet = 0, dry = 0;
  double deepest = 0;
  for (std::size_t i = 0; i < terrain.bed.size(); ++i) {
    if (!terrain.active(i)) continue;
    (terrain.bed[i] < 80.0 ? wet : dry)++;
    deepest = std::max(deepest, 80.0 - terrain.bed[i]);
  }
  const auto& g = terrain.grid;
  const double dx_n = g.dx[0], dx_s = g.dx[static_cast<std::size_t>(g.ny) - 1];
  std::printf(
      "[sw lake at rest, Rhine] %d x %d cells, dx %.2f m (north row) .. %.2f m (south "
      "row), dy %.2f m: %ld wet (deepest %.1f m), %ld dry\n",
      g.nx, g.ny, dx_n, dx_s, g.dy[0], wet, deepest, dry);
  ASSERT_NE(dx_n, dx_s) << "a geographic grid: per-row cell widths";
  ASSERT_GT(wet, 200);
  ASSERT_GT(dry, 200);
  auto sim = make_simulation(terrain, p, target());
  sim.step(2000);
  const auto m = max_discharge_and_speed(sim);
  const double bound_q = bound(1e-10, 2e-3);
  std::printf(
      "[sw lake at rest, Rhine] %s: after 2000 steps of 5 s max |q| %.3e m^2/s (bound "
      "%.0e), max speed %.3e m/s\n",
      target().label().c_str(), m[0], bound_q, m[1]);
  auto fig = [&](const char* q) {
    return figure("sw_lake_geographic", "shallow_water", q, g.dy[0], "at rest: q = 0");
  };
  vr::expect_below(fig("max |q| (m^2/s)"), m[0], bound_q);
  vr::report(fig("max speed (m/s)"), m[1]);
}

/// A wave leaving through an edge of kind `east`: a channel of 1000 m at dx = 2 m (3 rows, bed
/// 0, still water 1 m, sea level 1 m), a hump of 1 cm (Gaussian, 20 m) at x = 800 m that splits
/// into two waves of 5 mm at c0 = 3.13 m/s; the west edge a wall. After 150 s the westward wave
/// is centred at 330 m, and a reflection of the eastward one, which reached the east edge at
/// 64 s, would be centred at 730 m. Returns the largest surface departure east of 530 m over the
/// westward wave's, and the westward wave's velocity at its crest over the simple wave's
/// u = -c0 eta / h0.
struct EdgeWave {
  double reflection, velocity;
};
EdgeWave edge_wave(BoundaryKind east, const Target& target) {
  const int n = 500;
  const double dx = 2.0, h0 = 1.0, a = 0.01, x0 = 800.0, sigma = 20.0, t_end = 150.0;
  Terrain t = flat_terrain(n, 3, dx);
  t.water_depth.assign(t.grid.cells(), h0);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < n; ++c) {
      const double x = (c + 0.5) * dx;
      t.water_depth[static_cast<std::size_t>(r) * n + c] =
          h0 + a * std::exp(-(x - x0) * (x - x0) / (sigma * sigma));
    }
  // steps of 0.15 s: unsplit Courant number c0 dt (1 / dx + 1 / dy) = 0.47
  Params p = sw_params(0.15);
  p.boundary.east = east;
  p.boundary.sea_level = h0;
  auto sim = make_simulation(t, p, target);
  sim.step(std::lround(t_end / 0.15));
  const auto h = middle_row(sim, FieldId::water_depth);
  const auto u = middle_row(sim, FieldId::velocity_x);
  double west = 0, east_max = 0, u_crest = 0;
  for (int c = 0; c < n; ++c) {
    const double eta = std::abs(h[static_cast<std::size_t>(c)] - h0);
    if ((c + 0.5) * dx >= 530.0) {
      east_max = std::max(east_max, eta);
    } else if (eta > west) {
      west = eta;
      u_crest = u[static_cast<std::size_t>(c)] / (-std::sqrt(kG * h0) * eta / h0);
    }
  }
  return {east_max / west, u_crest};
}

TEST_P(ShallowWater, WavesLeaveThroughOpenAndFixedLevelEdges) {
  // A fixed level is still water at the level beyond the edge, and the face between it and the
  // edge cell is a Riemann problem (sw_face): the outgoing characteristic comes from the
  // domain, the incoming one from water at rest at the level, so a small wave leaves as into an
  // endless sea (linear theory: no reflection). An open edge copies the edge cell's depth and
  // outward velocity: a transmissive edge, also without reflection. Bounds: reflection below 5
  // % of the wave that stays (first-order diffusion spreads both alike); a wall reflects it
  // whole (printed, and above 0.5: the measure sees a reflection), and an edge that held the
  // level at the face would reflect it whole with the sign reversed; an idle solver leaves the
  // hump east of 530 m (reflection 1 / 0). The westward wave's crest velocity within 10 % of
  // the simple wave's -c0 eta / h0 (a scheme that moved the depth but not the momentum fails).
  const std::pair<BoundaryKind, const char*> kinds[] = {{BoundaryKind::fixed_level, "fixed_level"},
                                                        {BoundaryKind::open, "open"},
                                                        {BoundaryKind::closed, "closed"}};
  for (const auto& [kind, name] : kinds) {
    const EdgeWave w = edge_wave(kind, target());
    const bool wall = kind == BoundaryKind::closed;
    std::printf(
        "[sw edge wave] %s east edge %s: reflection %.4f of the wave that stays (bound %s), its "
        "crest velocity %.4f of the simple wave's (bound 0.9 .. 1.1)\n",
        target().label().c_str(), name, w.reflection, wall ? "> 0.5" : "< 0.05", w.velocity);
    auto fig = [&](const char* q) {
      return figure("sw_edge_wave", "shallow_water", q, 2.0,
                    "linear waves: no reflection at an open or sea edge");
    };
    if (wall) {
      EXPECT_GT(w.reflection, 0.5) << "a wall reflects the wave: the measure sees it";
      continue;
    }
    vr::expect_below(fig((std::string("reflection at a ") + name + " edge").c_str()), w.reflection,
                     0.05);
    vr::expect_between(fig((std::string("crest velocity / simple wave's, ") + name).c_str()),
                       w.velocity, 0.9, 1.1);
  }
}

/// Thacker's planar surface in a paraboloid (Thacker 1981; SWASHES 4.2.2): bed
/// z = -h0 (1 - r^2 / a^2) about the centre of an L x L square, a tilted plane of water that
/// turns round the basin at omega = sqrt(2 g h0) / a without changing shape: the water's centre
/// moves on a circle, its x coordinate eta/2 cos(omega t) (by symmetry of the wet disc, radius a).
/// Returns the measured period (s) from the zero crossings of sum (x - L/2) h, and the ratio of the
/// last to the first extremum of that sum (1: no decay).
struct ThackerRun {
  double period, exact, decay;
  int wet_across;
};
ThackerRun run_thacker(int n, double periods, const Target& target) {
  const double a = 1.0, h0 = 0.1, eta = 0.5, L = 4.0, g = kG;
  const double omega = std::sqrt(2 * g * h0) / a, T = 2 * M_PI / omega, dx = L / n;
  Terrain t = flat_terrain(n, n, dx);
  t.water_depth.assign(t.grid.cells(), 0.0);
  std::vector<double> qy(t.grid.cells(), 0.0);
  int wet_across = 0;
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) {
      const std::size_t i = static_cast<std::size_t>(r) * n + c;
      // x east, y north: row 0 is the north edge
      const double x = (c + 0.5) * dx - L / 2, y = L / 2 - (r + 0.5) * dx;
      const double z = -h0 * (1 - (x * x + y * y) / (a * a));
      t.bed[i] = z;
      const double h = eta * h0 / (a * a) * (2 * x - eta) - z;
      t.water_depth[i] = std::max(0.0, h);
      qy[i] = t.water_depth[i] * eta * omega;  // v = eta omega at t = 0, u = 0
      if (r == n / 2 && h > 0) ++wet_across;
    }
  Params p = sw_params(0.0);
  p.time.adaptive = true;
  p.time.cfl = 0.5;
  p.time.dt_max = 0.01;
  auto sim = make_simulation(t, p, target);
  sim.backend().set_field(FieldId::momentum_y, qy);
  std::vector<double> times, moments;
  while (sim.time() < periods * T) {
    sim.step();
    const auto h = sim.field(FieldId::water_depth);
    double m = 0;
    for (int r = 0; r < n; ++r)
      for (int c = 0; c < n; ++c)
        m += ((c + 0.5) * dx - L / 2) * h[static_cast<std::size_t>(r) * n + c];
    times.push_back(sim.time());
    moments.push_back(m);
  }
  // zero crossings of the moment, linearly interpolated; extrema between them
  std::vector<double> crossings, extrema;
  double extreme = 0;
  for (std::size_t k = 1; k < moments.size(); ++k) {
    if (std::abs(moments[k]) > std::abs(extreme)) extreme = moments[k];
    if ((moments[k - 1] < 0) != (moments[k] < 0)) {
      const double f = moments[k - 1] / (moments[k - 1] - moments[k]);
      crossings.push_back(times[k - 1] + f * (times[k] - times[k - 1]));
      extrema.push_back(extreme);
      extreme = 0;
    }
  }
  ThackerRun out{0, T, 0, wet_across};
  if (crossings.size() >= 3)
    out.period = 2 * (crossings.back() - crossings.front()) / (crossings.size() - 1);
  if (extrema.size() >= 3) out.decay = std::abs(extrema.back() / extrema[1]);
  return out;
}

TEST_P(ShallowWater, ThackerPlanarOscillation) {
  // Thacker's planar surface in a paraboloid (a = 1 m, h0 = 0.1 m, eta = 0.5 m, 4 m basin,
  // frictionless, adaptive steps at CFL 0.5), three periods (T = 4.486 s): the period from the
  // zero crossings of the water's first moment in x, and the decay of its amplitude. Issue 16:
  // within 1 % at a stated resolution, first order needing about 200 wet cells across. ctest
  // runs 100 cells across the 4 m (49 wet across the disc): bound 5 % (an idle solver's moment
  // never crosses zero). The report adds 200 and 400 cells across (100 and 200 wet): the error
  // falls at first order (+3.7, +1.9, +1.0 %), and at 200 wet cells the 1 % holds.
  std::vector<int> sizes{100};
  if (vr::full_ladder()) {
    sizes.push_back(200);
    sizes.push_back(400);
  }
  for (int n : sizes) {
    const ThackerRun r = run_thacker(n, 3.0, target());
    const double err = r.period / r.exact - 1;
    std::printf(
        "[sw Thacker] %s %d cells across (%d wet): period %.4f s, exact %.4f s (%+.2f %%, "
        "bound 5 %%); amplitude after 3 periods %.3f of the first\n",
        target().label().c_str(), n, r.wet_across, r.period, r.exact, 100 * err, r.decay);
    auto fig = [&](const char* q) {
      return figure("sw_thacker", "shallow_water", q, 4.0 / n, "Thacker (1981); SWASHES 4.2.2");
    };
    const double bound = r.wet_across >= 190 ? 0.01 : 0.05;
    vr::expect_between(fig("period / exact - 1"), err, -bound, bound);
    vr::report(fig("amplitude after 3 periods / first"), r.decay);
    EXPECT_GT(r.decay, 0.2) << "the oscillation survives three periods";
  }
}

ERODEM_INSTANTIATE_TARGETS(ShallowWater);

}  // namespace
}  // namespace erodem::test
