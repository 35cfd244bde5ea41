// erodem — analytical solutions: dam breaks (Stoker, Ritter), uniform Manning flow, rain
// run-off at equilibrium, thermal relaxation to the talus angle. Each test prints the measured
// figure beside its bound.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>

#include "reference_solutions.hpp"
#include "scenarios.hpp"
#include "target_test.hpp"
#include "validation_record.hpp"

namespace erodem::test {
namespace {

namespace vr = validation;

class Analytical : public TargetTest {};

// ---- dam breaks ------------------------------------------------------------------------
//
// Errors are taken over the region the wave reached, from the rarefaction's head x = -c0 t to
// the downstream front, plus a margin of 20 m on each side; elsewhere every solver (an idle one
// too) is exact, and a whole-channel norm would dilute the error (the old whole-channel Stoker
// norm gave an idle solver 0.10 against a bound of 0.10). Each error is relative_l1: the L1
// distance from the exact profile divided by that of the initial state, so a solver that does
// nothing scores exactly 1 (depth) and 1 (velocity, the exact one is not 0 there). Fronts are
// found by one depth threshold on the numerical and on the exact profile sampled at the same
// cell centres.

constexpr double kDamMargin = 20.0;  // m on each side of the reached region

/// Depth and velocity errors of a dam-break result against an exact solution over [lo, hi].
struct DamBreakErrors {
  double depth, velocity, idle_depth, idle_velocity;
};

template <class Exact>
DamBreakErrors dam_break_errors(const DamBreak& db, const DamBreakResult& r, const Exact& exact,
                                double lo, double hi) {
  const Row row = db.row();
  const auto h = row.sample([&](double x) { return exact.depth(x, r.time); });
  const auto u = row.sample([&](double x) { return exact.velocity(x, r.time); });
  const auto h_idle = db.initial_depth();
  const std::vector<double> u_idle(h_idle.size(), 0.0);
  return {relative_l1(row, r.depth, h, h_idle, lo, hi),
          relative_l1(row, r.velocity, u, u_idle, lo, hi),
          relative_l1(row, h_idle, h, h_idle, lo, hi), relative_l1(row, u_idle, u, u_idle, lo, hi)};
}

/// Parameters of the dam-break runs: no friction, fixed steps of dt, the default theta (0.8,
/// de Almeida et al. 2012). With theta = 1 (Bates et al. 2010) the local-inertial scheme has
/// no dissipation at all: behind a shock it leaves grid-scale oscillations (+-0.3 m at 2 m
/// and at 0.5 m cells) that do not shrink when dx does (LocalInertialDamBreakConverges
/// prints that ladder too).
Params dam_break_params(FlowScheme scheme, double dt, double theta = default_params().flow.theta) {
  Params p = quiet_params(scheme, dt);
  p.flow.theta = theta;
  return p;
}

TEST_P(Analytical, StokerWetDamBreak) {
  // 2 m onto 1 m, 1000 m channel of 2 m cells, 40 s with dt = 0.2 s (dt sqrt(g h0) / dx =
  // 0.44). The rarefaction's head is then at -177 m, the shock at +212 m.
  const DamBreak db{500, 2.0, 500.0, 2.0, 1.0};
  const Stoker exact(db.h_up, db.h_down);
  const double t_end = 40.0, lo = exact.head(t_end) - kDamMargin,
               hi = exact.shock * t_end + kDamMargin;
  const Row row = db.row();
  const double h_mid = 0.5 * (exact.h1 + exact.h2);  // the shock is where h crosses this
  const double shock_exact =
      last_above(row, row.sample([&](double x) { return exact.depth(x, t_end); }), h_mid);
  for (FlowScheme scheme : {FlowScheme::local_inertial, FlowScheme::pipes}) {
    Params p = dam_break_params(scheme, 0.2);
    // The pipe model with a constant pipe area A is linear shallow water about the reference
    // depth A / w (w = dy the face width): it moves A g dh / l per unit of surface drop, as a
    // channel of depth A / w would, so its waves run at c^2 = g A dx / (l dy) whatever the
    // depth. A = 1.5 m x 2 m makes that reference the mean depth 1.5 m (c = 3.84 m/s against
    // Stoker's head at 4.43 m/s and shock at 5.30 m/s); it cannot form a shock or a fan of the
    // right speeds, so its errors are reported, not bounded.
    p.flow.pipe_area = 0.5 * (db.h_up + db.h_down) * db.dx;
    const auto r = run_dam_break(db, p, t_end, target());
    const auto e = dam_break_errors(db, r, exact, lo, hi);
    const double shock = last_above(row, r.depth, h_mid);
    const bool inertial = scheme == FlowScheme::local_inertial;
    std::printf(
        "[Stoker] %s %s: over [%.0f, %.0f] m at t = %.1f s: depth error %.4f, velocity error "
        "%.4f (bounds %s; idle solver %.4f, %.4f); shock at %.1f m, Stoker %.1f m (h2 = %.4f "
        "m, u2 = %.4f m/s); water drift %.1e\n",
        target().label().c_str(), scheme_name(scheme), lo, hi, r.time, e.depth, e.velocity,
        inertial ? "0.35, 0.25" : "1, 1: it moved", e.idle_depth, e.idle_velocity, shock,
        shock_exact, exact.h2, exact.u2, r.water_drift);
    const char* ref = "Stoker (1957); SWASHES 4.1.1 (Delestre et al. 2013)";
    auto fig = [&](const char* quantity) {
      return figure("stoker", scheme_name(scheme), quantity, db.dx, ref);
    };
    vr::profile(fig(""), scheme_name(scheme), {"x", "depth", "depth_exact", "u", "u_exact"},
                {row.sample([](double x) { return x; }), r.depth,
                 row.sample([&](double x) { return exact.depth(x, r.time); }), r.velocity,
                 row.sample([&](double x) { return exact.velocity(x, r.time); })});
    if (inertial) {
      // Model error: without the advection term the scheme converges to another solution
      // (LocalInertialDamBreakConverges), 0.27 / 0.19 from Stoker's at every dx from 4 m to
      // 0.5 m, its shock 13 % slow. The bounds hold that model error with a margin that an
      // idle solver (1, 1; its "shock" stays at the dam) or a scheme moving water the wrong
      // way fails by far.
      vr::expect_below(fig("depth error (relative L1)"), e.depth, 0.35);
      vr::expect_below(fig("velocity error (relative L1)"), e.velocity, 0.25);
      vr::expect_between(fig("shock position / Stoker's"), shock / shock_exact, 0.8, 1.05);
    } else {
      // "it moved towards Stoker's profile": an idle solver scores 1
      vr::expect_below(fig("depth error (relative L1)"), e.depth, 1.0);
      vr::expect_below(fig("velocity error (relative L1)"), e.velocity, 1.0);
      vr::report(fig("shock position / Stoker's"), shock / shock_exact);
    }
  }
}

TEST_P(Analytical, LocalInertialDamBreakConverges) {
  // The local-inertial scheme drops the advection term d(hu^2)/dx, so it converges to the
  // solution of its own equations, not to Stoker's (its Stoker error stays at 0.27 from dx =
  // 4 m to 0.5 m). This checks that it converges, and at what order, against its own finest
  // solution: the Stoker set-up on 600 m with dx = 4, 2, 1 m against 0.5 m, dt / dx fixed at
  // 0.1 s/m (dt sqrt(g h0) / dx = 0.44 on every grid), finer solutions restricted to the
  // coarse cells by averaging. The distances from the 0.5 m solution overstate the order (at
  // dx = 1 m that solution's own error is half the distance: a true order 1/2 would read 0.9
  // and 1.3), so the bound is on the distances between successive grids, whose ratio is 2^p
  // for an error C dx^p. A first-order scheme reaches 1 only asymptotically; with the
  // rarefaction's corners and the shock smeared over a few cells it measured 0.55 and 0.62
  // here (0.72 between 1 m and 0.5 m against 0.25 m), hence the bound 0.5. An idle or
  // non-convergent solver fails it: unchanged states give 0 / 0, and theta = 1, whose
  // oscillations do not shrink, 0.30 and 0.13 (printed on cpu_float64, not asserted).
  const Stoker exact(2.0, 1.0);
  const double t_end = 40.0, length = 600.0;
  const double lo = exact.head(t_end) - kDamMargin, hi = exact.shock * t_end + kDamMargin;
  // The report's full ladder adds dx = 0.25 m: one more successive order, reported.
  std::vector<double> sizes{4.0, 2.0, 1.0, 0.5};
  if (vr::full_ladder()) sizes.push_back(0.25);
  const char* self_ref = "self-convergence (finest grid); Stoker (1957) for the model error";
  for (double theta : {default_params().flow.theta, 1.0}) {
    const bool asserted = theta < 1.0;
    if (!asserted && (target().backend != "cpu" || !target().f64())) continue;  // once is enough
    std::vector<DamBreak> grids;
    std::vector<DamBreakResult> runs;
    for (double dx : sizes) {
      grids.push_back(DamBreak{static_cast<int>(length / dx + 0.5), dx, 0.5 * length, 2.0, 1.0});
      runs.push_back(run_dam_break(grids.back(),
                                   dam_break_params(FlowScheme::local_inertial, 0.1 * dx, theta),
                                   t_end, target()));
    }
    // L1 distance (m^2, or m^2/s for the velocity) of level k from level j restricted to k
    auto distance = [&](std::size_t k, std::size_t j, bool velocity) {
      const int factor = static_cast<int>(sizes[k] / sizes[j] + 0.5);
      const auto& a = velocity ? runs[k].velocity : runs[k].depth;
      const auto& b = velocity ? runs[j].velocity : runs[j].depth;
      return l1_in(grids[k].row(), a, restrict_mean(b, factor), lo, hi) * sizes[k];
    };
    const std::string scheme = std::string("local_inertial theta ") + (asserted ? "0.8" : "1.0");
    for (bool velocity : {false, true}) {
      double ref[3], succ[3];
      for (std::size_t k = 0; k < 3; ++k) {
        ref[k] = distance(k, 3, velocity);
        succ[k] = distance(k, k + 1, velocity);
      }
      const double p1 = observed_order(succ[0], succ[1]), p2 = observed_order(succ[1], succ[2]);
      std::printf(
          "[local inertial convergence] %s theta %.1f %s: L1 from the 0.5 m solution at dx = "
          "4, 2, 1 m: %.4g, %.4g, %.4g (orders %.3f, %.3f); between successive grids %.4g, "
          "%.4g, %.4g: orders %.3f, %.3f (bound %s)\n",
          target().label().c_str(), theta, velocity ? "velocity" : "depth", ref[0], ref[1], ref[2],
          observed_order(ref[0], ref[1]), observed_order(ref[1], ref[2]), succ[0], succ[1], succ[2],
          p1, p2, asserted ? "> 0.5" : "none: reported");
      const char* what = velocity ? "velocity: L1 to the next finer grid (m^2/s)"
                                  : "depth: L1 to the next finer grid (m^2)";
      const char* order = velocity ? "velocity: observed order" : "depth: observed order";
      for (std::size_t k = 0; k + 1 < sizes.size(); ++k) {
        const double d = k < 3 ? succ[k] : distance(k, k + 1, velocity);
        const double prev = k == 0 ? 0.0 : (k - 1 < 3 ? succ[k - 1] : distance(k - 1, k, velocity));
        const auto p = k == 0 ? std::nullopt : std::optional<double>(observed_order(prev, d));
        vr::report(figure("li_convergence", scheme, what, sizes[k], self_ref), d, p);
        // The asserted orders: from the distances 4-2 / 2-1 m and 2-1 / 1-0.5 m (see above).
        if (k == 0) continue;
        const auto f = figure("li_convergence", scheme, order, sizes[k], self_ref);
        if (asserted && k < 3)
          vr::expect_above(f, *p, 0.5);
        else
          vr::report(f, *p);
      }
      if (asserted) {
        EXPECT_LT(ref[2], ref[1]);
        EXPECT_LT(ref[1], ref[0]);
      }
    }
    if (!asserted) continue;
    for (std::size_t k = 0; k < sizes.size(); ++k) {
      const auto e = dam_break_errors(grids[k], runs[k], exact, lo, hi);
      std::printf(
          "[local inertial vs Stoker] %s dx = %.1f m: depth error %.4f, velocity error %.4f "
          "(model error: no advection term; reported)\n",
          target().label().c_str(), sizes[k], e.depth, e.velocity);
      const char* model = "Stoker (1957): model error, the scheme has no advection term";
      vr::report(
          figure("li_convergence", scheme, "depth error vs Stoker (relative L1)", sizes[k], model),
          e.depth);
    }
  }
}

TEST_P(Analytical, RitterDryDamBreak) {
  // 1 m onto a dry bed, 1000 m channel of 2 m cells, 30 s with dt = 0.2 s. The fan runs from
  // -94 m to Ritter's front at 2 c0 t = +188 m; the front is where h crosses 1 mm, on the
  // exact profile at +179 m.
  const DamBreak db{500, 2.0, 400.0, 1.0, 0.0};
  const Ritter exact{db.h_up};
  const double t_end = 30.0, h_th = 1e-3, lo = exact.head(t_end) - kDamMargin,
               hi = exact.front(t_end) + kDamMargin;
  const Row row = db.row();
  const double front_exact =
      last_above(row, row.sample([&](double x) { return exact.depth(x, t_end); }), h_th);
  for (FlowScheme scheme : {FlowScheme::local_inertial, FlowScheme::pipes}) {
    Params p = dam_break_params(scheme, 0.2);
    p.flow.pipe_area = 0.5 * db.h_up * db.dx;  // reference depth h0 / 2 (StokerWetDamBreak)
    const auto r = run_dam_break(db, p, t_end, target());
    const auto e = dam_break_errors(db, r, exact, lo, hi);
    const double front = last_above(row, r.depth, h_th);
    std::printf(
        "[Ritter] %s %s: over [%.0f, %.0f] m: depth error %.4f, velocity error %.4f (bounds "
        "0.8, 0.9; idle solver %.4f, %.4f); front (h > %.0e m) at %.1f m, Ritter %.1f m (%+.0f "
        "%%, bound -70 .. +5 %%); water drift %.1e\n",
        target().label().c_str(), scheme_name(scheme), lo, hi, e.depth, e.velocity, e.idle_depth,
        e.idle_velocity, h_th, front, front_exact, 100 * (front / front_exact - 1), r.water_drift);
    // Neither scheme has the advection term that dominates the supercritical flow near a dry
    // front: the fronts lag Ritter's by 64 % (local inertial) and 58 % (pipes) here, and no
    // less on finer grids (local inertial 74, 65, 62, 59 m and pipes 82, 75, 73, 70 m at
    // dx = 4, 2, 1, 0.5 m: model error, not resolution); the region errors sit at 0.5 - 0.8
    // of an idle solver's.
    // The bounds are sanity bounds: a front that did not move (idle: 0 m) or overtook
    // Ritter's, or profiles no closer than an idle solver's, fail.
    auto fig = [&](const char* quantity) {
      return figure("ritter", scheme_name(scheme), quantity, db.dx,
                    "Ritter (1892); SWASHES 4.1.2 (Delestre et al. 2013)");
    };
    vr::profile(fig(""), scheme_name(scheme), {"x", "depth", "depth_exact", "u", "u_exact"},
                {row.sample([](double x) { return x; }), r.depth,
                 row.sample([&](double x) { return exact.depth(x, r.time); }), r.velocity,
                 row.sample([&](double x) { return exact.velocity(x, r.time); })});
    vr::expect_below(fig("depth error (relative L1)"), e.depth, 0.8);
    vr::expect_below(fig("velocity error (relative L1)"), e.velocity, 0.9);
    vr::expect_between(fig("front position / Ritter's"), front / front_exact, 0.3, 1.05);
  }
}

TEST_P(Analytical, ManningPlaneNormalDepth) {
  // A 2 km channel of slope S fed with q per unit width at the top, free outflow at the foot.
  const ManningPlane plane;
  const int n = plane.n;
  const double dx = plane.dx, normal = plane.normal_depth();
  Params p = plane.params(1.0);
  p.time.adaptive = true;
  p.time.cfl = 0.7;
  p.time.dt_max = 5.0;
  auto sim = make_simulation(plane.terrain(), p, target());
  while (sim.time() < 8000.0) sim.step();
  const auto d = middle_row(sim, FieldId::water_depth);
  double worst = 0, mean = 0;
  for (int c = n / 4; c < 3 * n / 4; ++c) {
    worst = std::max(worst, std::abs(d[c] - normal) / normal);
    mean += d[c] / (n / 2);
  }
  std::printf(
      "[Manning plane] %s: normal depth %.4f m, simulated mean %.4f m, worst relative "
      "deviation %.4f (bound 0.02) after %ld steps\n",
      target().label().c_str(), normal, mean, worst, sim.steps_done());
  const auto fig =
      figure("manning_plane", "local_inertial", "worst relative deviation from the normal depth",
             dx, "Manning's normal depth (q n / sqrt S)^(3/5)");
  const Row row{n, dx, 0.0};
  vr::profile(fig, "depth", {"x", "depth", "normal_depth"},
              {row.sample([](double x) { return x; }), d, std::vector<double>(n, normal)});
  vr::expect_below(fig, worst, 0.02);
  // The bed shear stress (the output field shear_stress, rho g n^2 |u|^2 / h^(1/3)): in uniform
  // flow the bed carries the weight's downslope component, rho g h S. Bound 5 % on the middle
  // half's mean: tau goes as q^2 / h^(7/3), so the depth's 2 % becomes 4.7 %; an idle solver
  // (no velocity) scores 0.
  const auto tau = middle_row(sim, FieldId::shear_stress);
  double tau_mean = 0;
  for (int c = n / 4; c < 3 * n / 4; ++c) tau_mean += tau[c] / (n / 2);
  const double tau_exact = p.flow.water_density * p.flow.gravity * normal * plane.slope;
  std::printf(
      "[Manning plane] %s: bed shear stress %.4f Pa, rho g h S %.4f Pa (ratio %.4f, "
      "bound 0.95 .. 1.05)\n",
      target().label().c_str(), tau_mean, tau_exact, tau_mean / tau_exact);
  vr::expect_between(
      figure("manning_plane", "local_inertial", "bed shear stress / rho g h S (middle half)", dx,
             "uniform flow: tau = rho g h S"),
      tau_mean / tau_exact, 0.95, 1.05);
}

TEST_P(Analytical, RainOnTiltedPlaneReachesEquilibrium) {
  const int n = 40;
  const double dx = 10.0, slope = 0.01, rain = 50.0 / 1000.0 / 3600.0;  // 50 mm/h
  Terrain t = flat_terrain(n, n, dx);
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c)
      t.bed[static_cast<std::size_t>(r) * n + c] = slope * (n - r - 0.5) * dx;  // down to south
  for (FlowScheme scheme :
       {FlowScheme::local_inertial, FlowScheme::pipes, FlowScheme::shallow_water}) {
    Params p = quiet_params(scheme, 1.0);
    p.flow.manning_n.value = 0.03;
    p.rain.rate = rain;
    p.time.adaptive = true;
    p.time.dt_max = 2.0;
    p.boundary.south = BoundaryKind::open;
    auto sim = make_simulation(t, p, target());
    // The outflow averaged over 3600-6000 s. Local inertial is steady from about 3000 s. The
    // frictionless pipes never settle: their stored water swings between about 25 and 80 m^3
    // with a period of about 1200 s, so a 600 s window measured the swing (ratios 0.96 and
    // 1.03 in alternate windows), not the balance; over two periods the change of storage is
    // at most about 60 m^3 of the 5,300 m^3 that fall, 1.1 %.
    while (sim.time() < 3600.0) sim.step();
    const double out0 = sim.ledger().boundary_out, t0 = sim.time();
    while (sim.time() < 6000.0) sim.step();
    const double outflow = (sim.ledger().boundary_out - out0) / (sim.time() - t0);
    const double expected = rain * n * n * dx * dx;
    const double ratio = outflow / expected;
    std::printf(
        "[rain on plane] %s %s: outflow %.5f m^3/s, rain x area %.5f m^3/s, ratio %.4f "
        "(bound |1 - ratio| < 0.02); closure %.2e\n",
        target().label().c_str(), scheme_name(scheme), outflow, expected, ratio,
        sim.ledger().relative_closure_error());
    vr::expect_below(figure("rain_plane", scheme_name(scheme), "|1 - outflow / (rain x area)|", dx,
                            "steady state: outflow = rain x area (mass balance)"),
                     std::abs(1 - ratio), 0.02);
  }
}

TEST_P(Analytical, ThermalRelaxesToTalusAngle) {
  const int n = 40;
  const double dx = 1.0, talus = 35.0;
  Terrain t = flat_terrain(n, n, dx);
  for (int r = 15; r < 25; ++r)
    for (int c = 15; c < 25; ++c) t.bed[static_cast<std::size_t>(r) * n + c] = 20.0;
  Params p = quiet_params(FlowScheme::pipes, 0.1);
  p.thermal.enabled = true;
  p.thermal.talus_angle = talus;
  p.thermal.rate = 5.0;  // K_t dt = 0.5
  auto sim = make_simulation(t, p, target());
  sim.step(6000);
  const auto b = sim.field(FieldId::bed);
  double worst = 0;
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) {
      const auto i = static_cast<std::size_t>(r) * n + c;
      if (c + 1 < n) worst = std::max(worst, std::abs(b[i] - b[i + 1]) / dx);
      if (r + 1 < n) worst = std::max(worst, std::abs(b[i] - b[i + n]) / dx);
    }
  // The steepest slope left between two neighbours, as an angle: relaxation stops exactly
  // when no drop exceeds dx tan(talus), and the last transfers approach that from above, so
  // the angle must sit at the talus angle from both sides. The upper side catches a scheme
  // that stops early (an idle one keeps the block's 87.1 deg walls); the lower side a scheme
  // that slumps too far or uses another angle (a block relaxed with a talus of 30 deg reads
  // 30.0 deg here: 5 deg outside the band, since its steepest drop is dx tan(30 deg) and the
  // block, 20 m high on 10 m, keeps some drop at the talus).
  const double angle = std::atan(worst) * 180.0 / M_PI;
  const auto& L = sim.ledger();
  const double drift = std::abs(L.material - L.material_initial) / L.material_initial;
  const double peak = *std::max_element(b.begin(), b.end());
  std::printf(
      "[thermal] %s: steepest slope %.4f deg, talus %.1f deg (bound +-1 deg; idle solver %.1f "
      "deg); peak %.2f m; material drift %.2e (bound %.0e)\n",
      target().label().c_str(), angle, talus, std::atan(20.0 / dx) * 180.0 / M_PI, peak, drift,
      target().f64() ? 1e-12 : 1e-5);
  auto fig = [&](const char* quantity) {
    return figure("thermal", "thermal", quantity, dx, "the talus angle (relaxation's fixed point)");
  };
  const Row row{n, dx, 0.0};
  vr::profile(fig(""), "bed", {"x", "bed", "bed_initial"},
              {row.sample([](double x) { return x; }),
               std::vector<double>(b.begin() + 20 * n, b.begin() + 21 * n),
               std::vector<double>(t.bed.begin() + 20 * n, t.bed.begin() + 21 * n)});
  vr::expect_between(fig("steepest slope (deg)"), angle, talus - 1.0, talus + 1.0);
  vr::expect_below(fig("peak (m)"), peak, 19.0);
  vr::expect_below(fig("material drift (relative)"), drift, target().f64() ? 1e-12 : 1e-5);
}

TEST_P(Analytical, ThermalRelaxesToTheWetTalusAngleOnWetGround) {
  // Two 20 m blocks of 10 x 10 cells of 1 m (as ThermalRelaxesToTalusAngle's), one on dry ground
  // (west half, wetness 0) and one on wet ground (east half, wetness 0.5 m, held by a
  // wetness time of 1e12 s), thermal.talus_angle 35 deg and thermal.wet_talus_angle 25 deg
  // above a wetness of 1 cm. Each half relaxes to its own angle: the steepest slope left in
  // the dry half is 35 deg and in the wet half 25 deg, each within 1 deg (the fixed point of the
  // relaxation, as in the dry test). Without the wet angle both read 35 deg; with it applied
  // everywhere both read 25.
  const int n = 80, half = 40;
  const double dx = 1.0, dry = 35.0, wet = 25.0;
  Terrain t = flat_terrain(n, n / 2, dx);
  for (int r = 15; r < 25; ++r)
    for (int c = 15; c < 25; ++c) {
      t.bed[static_cast<std::size_t>(r) * n + c] = 20.0;
      t.bed[static_cast<std::size_t>(r) * n + c + half] = 20.0;
    }
  Params p = quiet_params(FlowScheme::pipes, 0.1);
  p.thermal.enabled = true;
  p.thermal.talus_angle = dry;
  p.thermal.wet_talus_angle = wet;
  p.thermal.wet_threshold = 0.01;
  p.thermal.rate = 5.0;  // K_t dt = 0.5
  p.numerics.wetness_time = 1e12;
  auto sim = make_simulation(t, p, target());
  std::vector<double> w(t.bed.size(), 0.0);
  for (int r = 0; r < n / 2; ++r)
    for (int c = half; c < n; ++c) w[static_cast<std::size_t>(r) * n + c] = 0.5;
  sim.backend().set_field(FieldId::wetness, w);
  sim.step(8000);
  const auto b = sim.field(FieldId::bed);
  double steepest[2] = {0, 0};
  for (int r = 0; r < n / 2; ++r)
    for (int c = 0; c < n; ++c) {
      const auto i = static_cast<std::size_t>(r) * n + c;
      const int side = c >= half;
      if (c + 1 < n && (c + 1 >= half) == side)
        steepest[side] = std::max(steepest[side], std::abs(b[i] - b[i + 1]) / dx);
      if (r + 1 < n / 2) steepest[side] = std::max(steepest[side], std::abs(b[i] - b[i + n]) / dx);
    }
  const double a_dry = std::atan(steepest[0]) * 180.0 / M_PI;
  const double a_wet = std::atan(steepest[1]) * 180.0 / M_PI;
  std::printf(
      "[thermal wet] %s: steepest slope on dry ground %.4f deg (talus %.0f), on wet "
      "ground %.4f deg (wet talus %.0f); bounds +-1 deg\n",
      target().label().c_str(), a_dry, dry, a_wet, wet);
  auto fig = [&](const char* quantity) {
    return figure("thermal", "thermal", quantity, dx, "the talus angle of wet and dry ground");
  };
  vr::expect_between(fig("steepest slope on dry ground (deg)"), a_dry, dry - 1.0, dry + 1.0);
  vr::expect_between(fig("steepest slope on wet ground (deg)"), a_wet, wet - 1.0, wet + 1.0);
}

TEST_P(Analytical, SedimentAdaptsToCapacityAlongUniformFlow) {
  const SedimentAdaptation set;
  const double cap = set.capacity(), duration = 2 * set.length / set.speed;
  std::vector<double> sizes{1.0, 0.5, 0.25};
  if (vr::full_ladder()) sizes.push_back(0.125);  // the report's rung: the same bounds hold
  auto error = [&](const Row& row, const std::vector<double>& s) {
    const auto exact = row.sample(
        [&](double x) { return adapted_sediment(cap, set.dissolving_rate, set.speed, x); });
    return l1_in(row, s, exact, 0, set.length) / (row.n * cap);
  };
  const Row coarse{static_cast<int>(set.length / sizes[0] + 0.5), sizes[0], 0.0};
  const double idle = error(coarse, std::vector<double>(coarse.n, 0.0));
  const double untransported = error(coarse, std::vector<double>(coarse.n, cap));
  // Uniform flow of 1 m/s, 1 m deep, held fixed (SedimentAdaptation: erosion and transport
  // run alone on a state set with set_field, since Simulation::step always runs flow and
  // water); C = 1 mm, K_s = 0.05 /s, so the adaptation length u / K_s is 20 m and the 100 m
  // channel is 5 of them; 200 s (twice the transit time) reaches the steady state. Hardness 1,
  // K_s dt <= 0.02 (no clamp), s < C everywhere (erosion only), bed change <= 1 cm on a flat
  // bed (its tilt stays below min_tilt, so C stays K_c min_tilt u). The resolution
  // a = K_s dx / u is 0.05, 0.025, 0.0125 at u dt / dx = 0.4: at a = 0.5 the first cell would
  // already sit near C and the test could not fail. Error: mean |s - s_exact| / C over the
  // channel (s_exact at the cell centres). Upwind transport after a split erosion step
  // relaxes by r = (1 - a nu) / (1 + a (1 - nu)) per cell (nu = u dt / dx), a decay rate
  // wrong by a (1 - 2 nu) / 2 relative, and its first cell is off by a (nu - 1/2): first order,
  // with an error about a / 50 here (so not nu = 1/2, where the leading terms cancel). The
  // bounds: order > 0.8 on both halvings, and the error < a / 10 at each a. An idle solver
  // scores 0.80 and erosion without transport 0.20 (s = C everywhere), at every a (order 0).
  for (TransportScheme scheme : {TransportScheme::conservative, TransportScheme::semi_lagrangian}) {
    std::vector<double> e(sizes.size());
    double closure = 0;
    for (std::size_t k = 0; k < sizes.size(); ++k) {
      const auto r = set.run(scheme, sizes[k], duration, target());
      e[k] = error(r.row, r.sediment);
      closure = std::max(closure, r.material_closure);
      if (k + 1 < sizes.size()) continue;
      const auto exact = r.row.sample(
          [&](double x) { return adapted_sediment(cap, set.dissolving_rate, set.speed, x); });
      vr::profile(figure("sediment_adaptation", scheme_name(scheme), "", sizes[k], ""),
                  scheme_name(scheme), {"x", "sediment", "sediment_exact"},
                  {r.row.sample([](double x) { return x; }), r.sediment, exact});
    }
    const bool conservative = scheme == TransportScheme::conservative;
    for (std::size_t k = 0; k < sizes.size(); ++k) {
      const auto f = figure("sediment_adaptation", scheme_name(scheme),
                            "mean |s - s_exact| / C (resolution: dx in m; K_s dx / u = dx / 20)",
                            sizes[k], "u ds/dx = K_s (C - s): s = C (1 - exp(-K_s x / u))");
      const auto p = k == 0 ? std::nullopt : std::optional<double>(observed_order(e[k - 1], e[k]));
      if (conservative)  // order > 0.8 and error < a / 10: see above
        vr::expect_below(f, e[k], 0.1 * set.resolution(sizes[k]), p);
      else
        vr::report(f, e[k], p);
      if (k > 0 && conservative)
        vr::expect_above(figure("sediment_adaptation", scheme_name(scheme), "observed order",
                                sizes[k], "first order (upwind)"),
                         *p, 0.8);
    }
    std::printf(
        "[sediment adaptation] %s %s: mean |s - C(1 - exp(-K_s x/u))| / C at K_s dx/u = %.4g, "
        "%.4g, %.4g: %.4g, %.4g, %.4g (orders %.3f, %.3f); idle solver %.4f, erosion without "
        "transport %.4f; material closure %.1e\n",
        target().label().c_str(), scheme_name(scheme), set.resolution(sizes[0]),
        set.resolution(sizes[1]), set.resolution(sizes[2]), e[0], e[1], e[2],
        observed_order(e[0], e[1]), observed_order(e[1], e[2]), idle, untransported, closure);
    if (scheme == TransportScheme::semi_lagrangian) {
      // Not asserted: the departure point is clamped to the grid, so the first cell reads its
      // own sediment, not the clear water entering through the wall. The inflow boundary is
      // zero-gradient, every cell settles at C, and the scheme scores exactly as erosion
      // without transport (0.1986 at every a): it cannot represent a clear inflow.
      continue;
    }
    vr::expect_below(figure("sediment_adaptation", scheme_name(scheme),
                            "material closure (relative)", sizes.back(), "conservation"),
                     closure, target().f64() ? 1e-12 : 1e-4);
  }
}

TEST_P(Analytical, EvaporationFollowsTheExplicitDecay) {
  // A lake at rest, 1 m deep, on 10 x 10 cells of 100 m; K_e = 0.01 /s with dt = 10 s, so
  // K_e dt = 0.1 and 20 steps leave d0 0.9^20 = 0.1216 m. The step is large on purpose: the
  // exact ODE's d0 exp(-K_e t) = 0.1353 m is 11 % off, so a scheme integrating anything but
  // the explicit rule fails, as does an idle one (d0: +723 %). Bounds: rounding, 1e-12 in
  // float64 and 1e-5 in float32 (20 float steps of 2^-24 each), on every cell's depth and on
  // the evaporated volume the ledger books against the volume the lake lost.
  const double d0 = 1.0, rate = 0.01, dt = 10.0;
  const long n = 20;
  Params p = quiet_params(FlowScheme::local_inertial, dt);
  p.evaporation.rate = rate;
  p.initial.water_depth.value = d0;
  auto sim = make_simulation(flat_terrain(10, 10, 100.0), p, target());
  sim.step(n);
  const double expected = evaporated_depth(d0, rate, dt, n);
  const auto d = sim.field(FieldId::water_depth);
  double worst = 0;
  for (double v : d) worst = std::max(worst, std::abs(v - expected) / expected);
  const auto& L = sim.ledger();
  const double lost = L.water_initial - L.water;
  const double booked = std::abs(L.evaporated - lost) / lost;
  std::printf(
      "[evaporation] %s: depth after %ld steps %.6f m, d0 (1 - K_e dt)^n = %.6f m, worst relative "
      "error %.2e (idle solver %.2f, d0 exp(-K_e t) %.4f); evaporated %.4f m^3 booked vs lost "
      "%.2e\n",
      target().label().c_str(), n, d[0], expected, worst, (d0 - expected) / expected,
      std::abs(d0 * std::exp(-rate * dt * n) - expected) / expected, L.evaporated, booked);
  const double limit = target().f64() ? 1e-12 : 1e-5;
  auto fig = [&](const char* quantity) {
    return figure("evaporation", "explicit decay", quantity, 100.0,
                  "d0 (1 - K_e dt)^n, the explicit rule");
  };
  vr::expect_below(fig("worst relative depth error"), worst, limit);
  vr::expect_below(fig("evaporated (booked) vs lost volume"), booked, limit);
  EXPECT_LT(max_abs(sim.field(FieldId::velocity_x)), limit) << "the lake stays at rest";

  // K_e dt = 1.5 is clamped to 1: one step evaporates everything, and books all of it.
  p.evaporation.rate = 0.15;
  auto dry = make_simulation(flat_terrain(10, 10, 100.0), p, target());
  dry.step();
  const auto d1 = dry.field(FieldId::water_depth);
  const auto& L1 = dry.ledger();
  std::printf(
      "[evaporation] %s: K_e dt = 1.5: max depth after one step %.3e m; evaporated %.6g "
      "of %.6g m^3\n",
      target().label().c_str(), max_abs(d1), L1.evaporated, L1.water_initial);
  EXPECT_EQ(max_abs(d1), 0.0);
  EXPECT_NEAR(L1.evaporated, L1.water_initial, limit * L1.water_initial);
}

}  // namespace

ERODEM_INSTANTIATE_TARGETS(Analytical);

}  // namespace erodem::test
