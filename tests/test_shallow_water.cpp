// erodem — the shallow-water scheme (flow.scheme = "shallow_water", model.md section 3.10)
// against closed forms: Stoker's and Ritter's dam breaks converging at their observed order,
// a radial dam break in 2D against a fine 1-D radially symmetric solution computed in the test,
// Thacker's oscillation, and lakes at rest on real DEMs, projected and geographic. Each test
// prints its figures beside their bounds; an idle solver scores 1 on every relative error (and
// no order), a scheme without the advection term (local inertial) stays at 0.27 of Stoker's
// change at every resolution, one that drops the tangential momentum flux passes the 1-D dam
// breaks but not the radial one, and one that is not well balanced moves a lake at rest.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include "common/shallow_water.h"
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
Params sw_params(double dt, int order = 1) {
  Params p = quiet_params(FlowScheme::shallow_water, dt);
  p.flow.order = order;
  return p;
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
                         double t_end, double lo, double hi, double front_depth, int order = 1) {
  std::vector<double> sizes{2.0, 1.0, 0.5};
  if (vr::full_ladder()) sizes.push_back(0.25);
  std::vector<Rung> out;
  for (double dx : sizes) {
    const int n = static_cast<int>(std::lround(1000.0 / dx));
    const DamBreak db{n, dx, 500.0, h_up, h_down};
    auto sim = make_simulation(db.terrain(), sw_params(0.08 * dx, order), target);
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

TEST_P(ShallowWater, SecondOrderDamBreaks) {
  // Stoker's and Ritter's dam breaks (the ladders above) with flow.order = 2 (MUSCL-minmod and
  // Heun) against the first order on the same rungs. A shock or a dry front limits any scheme
  // to first order in L1, so the gain is in the constant: bounds, at every dx, a depth error
  // below half the first order's (measured 0.34, 0.30, 0.25 for Stoker, 0.33, 0.26, 0.22 for
  // Ritter), orders >= 0.7 in depth and discharge, Stoker's shock within 3 %, and Ritter's 1 mm
  // front at >= 0.93 of Ritter's at the finest dx (measured 0.951; first order 0.903). A
  // second order that reconstructed nothing would score the first order's errors (ratio 1).
  const Stoker stoker(2.0, 1.0);
  const Ritter ritter{2.0};
  const double ts = 40.0, tr = 30.0;
  struct Case {
    const char* name;
    std::vector<Rung> first, second;
  };
  const double s_lo = stoker.head(ts) - kMargin, s_hi = stoker.shock * ts + kMargin;
  const double r_lo = ritter.head(tr) - kMargin, r_hi = ritter.front(tr) + kMargin;
  const double s_front = 0.5 * (stoker.h1 + stoker.h2);
  Case cases[] = {{"Stoker", ladder(target(), stoker, 2.0, 1.0, ts, s_lo, s_hi, s_front, 1),
                   ladder(target(), stoker, 2.0, 1.0, ts, s_lo, s_hi, s_front, 2)},
                  {"Ritter", ladder(target(), ritter, 2.0, 0.0, tr, r_lo, r_hi, 1e-3, 1),
                   ladder(target(), ritter, 2.0, 0.0, tr, r_lo, r_hi, 1e-3, 2)}};
  for (const Case& c : cases) {
    const bool is_stoker = std::string(c.name) == "Stoker";
    auto fig = [&](const char* q, double dx) {
      return figure(is_stoker ? "sw_stoker" : "sw_ritter", "shallow_water", q, dx,
                    is_stoker ? "Stoker (1957)" : "Ritter (1892)");
    };
    for (std::size_t k = 0; k < c.second.size(); ++k) {
      const Rung &r = c.second[k], &f = c.first[k];
      const double ratio = r.depth / f.depth;
      std::printf(
          "[sw second order] %s %s dx = %.1f m: depth error %.4f (first order %.4f, ratio %.2f, "
          "bound < 0.5), discharge %.4f, velocity %.4f, front %.4f\n",
          target().label().c_str(), c.name, r.dx, r.depth, f.depth, ratio, r.discharge, r.velocity,
          r.front);
      vr::report(fig("second order: depth error (relative L1)", r.dx), r.depth);
      vr::report(fig("second order: discharge error (relative L1)", r.dx), r.discharge);
      vr::expect_below(fig("second order: depth error / first order's", r.dx), ratio, 0.5);
      if (is_stoker)
        vr::expect_between(fig("second order: shock position / Stoker's", r.dx), r.front, 0.97,
                           1.03);
      if (k == 0) continue;
      const double p_h = observed_order(c.second[k - 1].depth, r.depth);
      const double p_q = observed_order(c.second[k - 1].discharge, r.discharge);
      std::printf(
          "[sw second order] %s %s dx %.1f -> %.1f m: observed order depth %.2f, "
          "discharge %.2f (bound >= 0.7)\n",
          target().label().c_str(), c.name, c.second[k - 1].dx, r.dx, p_h, p_q);
      vr::expect_above(fig("second order: observed order, depth", r.dx), p_h, 0.7);
      vr::expect_above(fig("second order: observed order, discharge", r.dx), p_q, 0.7);
    }
    if (!is_stoker)
      vr::expect_between(
          fig("second order: front position / Ritter's at the finest dx", c.second.back().dx),
          c.second.back().front, 0.93, 1.02);
  }
}

/// The radial dam break (RadialDamBreakConverges): a square basin 64 m across between walls,
/// flat and frictionless, 2 m deep within 10 m of its centre and 1 m beyond, run for 4 s. The
/// shock is then at 25.8 m (6 m from the walls); the rarefaction, reflected from the centre, has
/// left a 0.40 m hollow there with an inward-facing secondary shock at its rim (r = 3.9 m).
constexpr double kRadialHalf = 32.0, kRadialR0 = 10.0, kRadialEnd = 4.0;

/// The reference: RadialDamBreak (reference_solutions.hpp) on [0, 36] m in 3600 cells of 1 cm,
/// second order. Its distance from the same solver's run in 7200 cells, in the test's norm at
/// the report's finest rung, is 3.8e-4 of an idle solver's in depth and 5.1e-4 in discharge
/// and velocity (1800 cells: 1.1e-3, 1.6e-3), a hundredth of the 2D error there (0.037); it
/// reproduces Stoker's solution without its radial terms (planar, 2000 cells: 2.1e-3 of an
/// idle solver's). Nothing reaches its wall at 36 m by 4 s (with the wall at 48 m the profile
/// is the same to the digits above), and beyond 36 m it holds the last cell's 1 m at rest, as
/// the basin does there.
RadialDamBreak radial_reference() {
  RadialDamBreak exact(2.0, 1.0, kRadialR0, 36.0, 3600);
  exact.run_to(kRadialEnd);
  return exact;
}

/// The outermost radius (m) at which a profile ordered by radius `r` falls through
/// `threshold`, linear between the two cells on either side (0 if it never does): the shock,
/// found the same way on the 2D rays and on the reference's cells.
double outer_crossing(const std::vector<double>& r, const std::vector<double>& v,
                      double threshold) {
  for (std::size_t k = v.size() - 1; k > 0; --k)
    if (v[k - 1] > threshold && v[k] <= threshold)
      return r[k - 1] + (v[k - 1] - threshold) / (v[k - 1] - v[k]) * (r[k] - r[k - 1]);
  return 0;
}

/// `v` (a profile ordered by radius `r`) at radius x, linear between its points.
double interpolate(const std::vector<double>& r, const std::vector<double>& v, double x) {
  if (x <= r.front()) return v.front();
  if (x >= r.back()) return v.back();
  const auto k = static_cast<std::size_t>(std::upper_bound(r.begin(), r.end(), x) - r.begin());
  const double f = (x - r[k - 1]) / (r[k] - r[k - 1]);
  return (1 - f) * v[k - 1] + f * v[k];
}

/// A ray of cells from the basin's centre: their centre radii (m), depth (m), radial discharge
/// (m^2/s) and velocity (m/s), and the reference's depth, discharge and velocity there.
struct Ray {
  std::vector<double> r, h, q, u, h_exact, q_exact, u_exact;
};

/// One rung of the radial dam break: the errors over all cells relative to an idle solver's,
/// the shock radius on the east half-axis and on the south-east diagonal over the reference's,
/// the distance between those two rays' profiles, the largest departure from the grid's mirror
/// symmetries, and the largest tangential discharge over the largest radial one.
struct RadialRung {
  double dx, depth, discharge, velocity, shock_axis, shock_diagonal, rays_depth, rays_discharge,
      mirror, tangential;
  Ray axis, diagonal;
};

RadialRung run_radial(double dx, const RadialDamBreak& exact, const Target& target) {
  const int n = static_cast<int>(std::lround(2 * kRadialHalf / dx));
  const auto at = [n](int r, int c) { return static_cast<std::size_t>(r) * n + c; };
  // x east, y north from the centre: row 0 is the north edge
  const auto x_of = [&](int c) { return (c + 0.5) * dx - kRadialHalf; };
  const auto y_of = [&](int r) { return kRadialHalf - (r + 0.5) * dx; };
  // each cell holds the cylinder's share of it (8 x 8 points a cell): the idle solver's state
  Terrain t = flat_terrain(n, n, dx);
  t.water_depth.assign(t.grid.cells(), 0.0);
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) {
      double h = 0;
      for (int j = 0; j < 8; ++j)
        for (int i = 0; i < 8; ++i)
          h += std::hypot(x_of(c) + ((i + 0.5) / 8 - 0.5) * dx,
                          y_of(r) + ((j + 0.5) / 8 - 0.5) * dx) < kRadialR0
                   ? 2.0
                   : 1.0;
      t.water_depth[at(r, c)] = h / 64;
    }
  const std::vector<double> h0 = t.water_depth;
  // steps of 0.05 dx s: the unsplit Courant number (|u| + |v| + 2c) dt / dx stays below 0.47
  // (the reference's largest sqrt(2) |u| + 2c is 9.4 m/s, early on, just behind the shock)
  const double dt = 0.05 * dx;
  auto sim = make_simulation(std::move(t), sw_params(dt), target);
  sim.step(std::lround(kRadialEnd / dt));
  const auto h = sim.field(FieldId::water_depth);
  const auto qx = sim.field(FieldId::momentum_x), qy = sim.field(FieldId::momentum_y);
  const auto u = sim.field(FieldId::velocity_x), v = sim.field(FieldId::velocity_y);
  const std::size_t cells = h.size();
  std::vector<double> q_r(cells), u_r(cells), h_e(cells), q_e(cells), u_e(cells);
  double e_h = 0, i_h = 0, e_q = 0, i_q = 0, e_u = 0, i_u = 0, q_t = 0, q_max = 0;
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) {
      const std::size_t k = at(r, c);
      const double x = x_of(c), y = y_of(r), rad = std::hypot(x, y);
      h_e[k] = exact.depth(rad);
      q_e[k] = exact.discharge(rad);
      u_e[k] = exact.velocity(rad);
      q_r[k] = (x * qx[k] + y * qy[k]) / rad;
      u_r[k] = (x * u[k] + y * v[k]) / rad;
      e_h += std::abs(h[k] - h_e[k]);
      i_h += std::abs(h0[k] - h_e[k]);
      e_q += std::abs(q_r[k] - q_e[k]);
      i_q += std::abs(q_e[k]);
      e_u += std::abs(u_r[k] - u_e[k]);
      i_u += std::abs(u_e[k]);
      q_t = std::max(q_t, std::abs(x * qy[k] - y * qx[k]) / rad);
      q_max = std::max(q_max, std::abs(q_e[k]));
    }
  // each cell against its mirror images across the two centre lines and the diagonal
  double mirror = 0;
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c)
      for (std::size_t m : {at(r, n - 1 - c), at(n - 1 - r, c), at(c, r)}) {
        mirror = std::max(mirror, std::abs(h[at(r, c)] - h[m]));
        mirror = std::max(mirror, std::abs(q_r[at(r, c)] - q_r[m]));
      }
  RadialRung out{dx, e_h / i_h, e_q / i_q, e_u / i_u, 0, 0, 0, 0, mirror, q_t / q_max, {}, {}};
  // the east half-axis (the row just south of the centre) and the south-east diagonal
  for (int k = 0; k < n / 2; ++k)
    for (auto [ray, r, c] : {std::tuple{&out.axis, n / 2, n / 2 + k},
                             std::tuple{&out.diagonal, n / 2 + k, n / 2 + k}}) {
      const std::size_t i = at(r, c);
      ray->r.push_back(std::hypot(x_of(c), y_of(r)));
      ray->h.push_back(h[i]);
      ray->q.push_back(q_r[i]);
      ray->u.push_back(u_r[i]);
      ray->h_exact.push_back(h_e[i]);
      ray->q_exact.push_back(q_e[i]);
      ray->u_exact.push_back(u_e[i]);
    }
  // The shock: where the depth falls through the middle of the jump, from 1 m ahead of it to
  // the reference's depth behind it (its largest beyond r0: the depth rises from 1.03 m at r0
  // to 1.29 m behind the shock).
  std::vector<double> r_exact(exact.depths().size());
  for (std::size_t i = 0; i < r_exact.size(); ++i) r_exact[i] = (i + 0.5) * exact.cell();
  double behind = 0;
  for (std::size_t i = 0; i < r_exact.size(); ++i)
    if (r_exact[i] > kRadialR0) behind = std::max(behind, exact.depths()[i]);
  const double mid = 0.5 * (1.0 + behind);
  const double shock = outer_crossing(r_exact, exact.depths(), mid);
  out.shock_axis = outer_crossing(out.axis.r, out.axis.h, mid) / shock;
  out.shock_diagonal = outer_crossing(out.diagonal.r, out.diagonal.h, mid) / shock;
  // The diagonal's profile against the axis's at the diagonal's radii (within the axis's
  // reach), relative to an idle solver's distance from the reference over the same cells.
  double d_h = 0, d_q = 0, idle_h = 0, idle_q = 0;
  for (std::size_t k = 0; k < out.diagonal.r.size(); ++k) {
    const double rad = out.diagonal.r[k];
    if (rad > out.axis.r.back()) break;
    d_h += std::abs(out.diagonal.h[k] - interpolate(out.axis.r, out.axis.h, rad));
    d_q += std::abs(out.diagonal.q[k] - interpolate(out.axis.r, out.axis.q, rad));
    idle_h += std::abs((rad < kRadialR0 ? 2.0 : 1.0) - out.diagonal.h_exact[k]);
    idle_q += std::abs(out.diagonal.q_exact[k]);
  }
  out.rays_depth = d_h / idle_h;
  out.rays_discharge = d_q / idle_q;
  return out;
}

TEST_P(ShallowWater, RadialDamBreakConverges) {
  // The radial dam break (above: 2 m within 10 m onto 1 m, a 64 m closed basin, 4 s) at dx =
  // 1, 0.5, 0.25 m (the report adds 0.125 m), against a fine 1-D radially symmetric solution
  // computed here (radial_reference). Errors over all cells relative to an idle solver's (which
  // scores 1): depth, and the radial discharge (x q_x + y q_y) / r and velocity against the
  // reference's h u and u at each cell's centre radius.
  //  - Observed orders >= 0.6 in depth, discharge and velocity between each pair of rungs.
  //    First-order Godunov reaches about 0.8 on a solution with shocks (Stoker: 0.77, 0.81);
  //    here a second, inward-facing shock and the hollow at the centre are smeared over a few
  //    cells too, and with 10 cells across r0 at 1 m the orders start lower: measured 0.70,
  //    0.76 (0.82 to 0.125 m) in depth, discharge 0.69, 0.76 (0.83), velocity 0.66, 0.72 (0.79).
  //  - The shock (where the depth falls through the middle of its jump, linear between cells)
  //    on the east half-axis and on the diagonal within 3 % of the reference's at every rung
  //    (the band of the Stoker test): measured 0.980 .. 1.004, the diagonal behind at 1 m.
  //  - The diagonal's profile against the axis's (the grid's anisotropy; relative L1 over the
  //    diagonal cells, normalised by an idle solver's distance from the reference there): below
  //    0.03 in depth and 0.1 in discharge at every rung (measured 0.015 and 0.071 at 1 m), and
  //    shrinking with dx at an order >= 0.3 (measured 0.43, 0.53 in depth, 0.78, 0.66 in
  //    discharge: the grid's anisotropy, first order too, still pre-asymptotic).
  //  - The grid's mirror symmetries (across both centre lines and the diagonal) kept to
  //    rounding in depth and radial discharge: 1e-12 in float64, 1e-5 in float32 (about 40 ulps
  //    of 2 m; measured 2e-15, 8e-7, 1.2e-6 at 0.125 m), checked on every rung, recorded once.
  //  - The depth error at the finest rung below 0.1 of an idle solver's (0.065 at 0.25 m, 0.037
  //    at 0.125 m).
  // An idle solver scores 1 on every error (orders 0) and its shock stays at r0 (0.39); it
  // passes only the symmetry bounds (the mirror and the rays'). The local-inertial scheme (no
  // advection term) diverges from the reference (depth errors 0.20, 0.21, 0.24, orders < 0) with
  // its shock 4-7 % slow. A shallow-water scheme that drops the tangential momentum flux passes the
  // Stoker ladder unchanged (in a channel the tangential velocity is 0) but fails here: orders 0.52
  // / 0.22 (depth) and 0.22 / 0.10 (discharge), the diagonal's shock 4.6-6.1 % behind, the rays
  // 0.07 (depth) and 0.46-0.57 (discharge) apart and not closing; upwinding the tangential velocity
  // from the wrong side blows up (the CFL check stops it at 1.7 s).
  const RadialDamBreak exact = radial_reference();
  std::vector<double> sizes{1.0, 0.5, 0.25};
  if (vr::full_ladder()) sizes.push_back(0.125);
  std::vector<RadialRung> rungs;
  for (double dx : sizes) rungs.push_back(run_radial(dx, exact, target()));
  auto fig = [&](const char* q, double dx) {
    return figure("sw_radial", "shallow_water", q, dx,
                  "a fine 1-D radially symmetric solution (computed in the test)");
  };
  double mirror = 0;
  for (std::size_t k = 0; k < rungs.size(); ++k) {
    const RadialRung& r = rungs[k];
    mirror = std::max(mirror, r.mirror);
    std::printf(
        "[sw radial] %s dx = %.3f m: depth error %.4f, radial discharge error %.4f, radial "
        "velocity error %.4f (of an idle solver's); shock at %.4f (axis), %.4f (diagonal) of "
        "the reference's (bounds 0.97 .. 1.03); diagonal against axis: depth %.4f (bound 0.03), "
        "discharge %.4f (bound 0.1); mirror asymmetry %.1e; largest tangential discharge %.4f "
        "of the largest radial\n",
        target().label().c_str(), r.dx, r.depth, r.discharge, r.velocity, r.shock_axis,
        r.shock_diagonal, r.rays_depth, r.rays_discharge, r.mirror, r.tangential);
    vr::report(fig("depth error (relative L1)", r.dx), r.depth);
    vr::report(fig("radial discharge error (relative L1)", r.dx), r.discharge);
    vr::report(fig("radial velocity error (relative L1)", r.dx), r.velocity);
    vr::expect_between(fig("shock radius / reference's, axis", r.dx), r.shock_axis, 0.97, 1.03);
    vr::expect_between(fig("shock radius / reference's, diagonal", r.dx), r.shock_diagonal, 0.97,
                       1.03);
    vr::expect_below(fig("diagonal against axis, depth (relative L1)", r.dx), r.rays_depth, 0.03);
    vr::expect_below(fig("diagonal against axis, radial discharge (relative L1)", r.dx),
                     r.rays_discharge, 0.1);
    vr::report(fig("largest tangential / largest radial discharge", r.dx), r.tangential);
    if (k == 0) continue;
    const RadialRung& c = rungs[k - 1];
    const double p_h = observed_order(c.depth, r.depth);
    const double p_q = observed_order(c.discharge, r.discharge);
    const double p_u = observed_order(c.velocity, r.velocity);
    const double p_rh = observed_order(c.rays_depth, r.rays_depth);
    const double p_rq = observed_order(c.rays_discharge, r.rays_discharge);
    std::printf(
        "[sw radial] %s dx %.3f -> %.3f m: observed order depth %.2f, discharge %.2f, velocity "
        "%.2f (bound >= 0.6); diagonal against axis: depth %.2f, discharge %.2f (bound >= "
        "0.3)\n",
        target().label().c_str(), c.dx, r.dx, p_h, p_q, p_u, p_rh, p_rq);
    vr::expect_above(fig("observed order, depth", r.dx), p_h, 0.6);
    vr::expect_above(fig("observed order, radial discharge", r.dx), p_q, 0.6);
    vr::expect_above(fig("observed order, radial velocity", r.dx), p_u, 0.6);
    vr::expect_above(fig("observed order, diagonal against axis (depth)", r.dx), p_rh, 0.3);
    vr::expect_above(fig("observed order, diagonal against axis (discharge)", r.dx), p_rq, 0.3);
  }
  const RadialRung& finest = rungs.back();
  const double bound_mirror = bound(1e-12, 1e-5);
  std::printf(
      "[sw radial] %s: mirror asymmetry over every rung %.1e (m, m^2/s; bound %.0e); depth "
      "error at the finest dx %.4f (bound 0.1)\n",
      target().label().c_str(), mirror, bound_mirror, finest.depth);
  vr::expect_below(fig("mirror asymmetry, largest over the rungs (m, m^2/s)", finest.dx), mirror,
                   bound_mirror);
  vr::expect_below(fig("depth error at the finest dx (relative L1)", finest.dx), finest.depth, 0.1);
  for (const auto& [name, ray] :
       {std::pair{"axis", &finest.axis}, std::pair{"diagonal", &finest.diagonal}})
    vr::profile(fig("", finest.dx), name, {"r", "depth", "depth_exact", "u", "u_exact"},
                {ray->r, ray->h, ray->h_exact, ray->u, ray->u_exact});
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
  // both orders: the second order's reconstructed faces keep the level too (its slopes of the
  // surface are 0, and it reconstructs the bed as surface minus depth), the same bounds
  for (int order : {1, 2}) {
    p.flow.order = order;
    auto sim = make_simulation(terrain, p, target());
    sim.step(2000);
    const auto m = max_discharge_and_speed(sim);
    const double bound_q = bound(1e-10, 2e-3);
    std::printf(
        "[sw lake at rest, Rhine] %s order %d: after 2000 steps of 5 s max |q| %.3e m^2/s "
        "(bound %.0e), max speed %.3e m/s\n",
        target().label().c_str(), order, m[0], bound_q, m[1]);
    auto fig = [&](const char* q) {
      return figure("sw_lake_geographic", "shallow_water", q, g.dy[0], "at rest: q = 0");
    };
    vr::expect_below(fig(order == 1 ? "max |q| (m^2/s)" : "second order: max |q| (m^2/s)"), m[0],
                     bound_q);
    vr::report(fig(order == 1 ? "max speed (m/s)" : "second order: max speed (m/s)"), m[1]);
  }
}

/// A smooth supercritical steady flow built as MacDonald et al. (1997) and SWASHES build theirs
/// (choose the depth, derive the bed that makes it steady): a 1000 m channel, q = 2 m^2/s,
/// Manning n = 0.033, the depth h(x) = hc (0.75 - 0.15 exp(-36 (x/1000 - 1/2)^2)), hc =
/// (q^2/g)^(1/3) the critical depth (Froude number 1.54 at the ends, 2.15 at the middle), and
/// z' = -(1 - q^2 / (g h^3)) h' - n^2 q^2 / h^(10/3), integrated from z(1000) = 0 (Simpson, 64
/// panels per cell) at the cell centres: a bed of slope 0.016 to 0.055. (SWASHES' own
/// supercritical case, hc (1 - exp(...) / 5), tends to the critical depth at both ends, where
/// the slow wave stalls: there the scheme's end state depended on the start, from the exact
/// state or from q = 1.6 m^2/s, and the order measured 1.9 or 0.4.) Supercritical flow takes
/// both of its conditions upstream: the first three cells are held at the exact state (h, q)
/// every step (Dirichlet data; three, so the first free cell's faces are reconstructed from
/// exact data); the east edge is open (transmissive). The run starts from the exact depth with
/// q = 1.6 m^2/s (an idle solver's discharge error: 0.2) and runs 1000 s (the water crosses the
/// channel in about 300 s).
struct MacDonald {
  static constexpr double L = 1000.0, q = 2.0, n = 0.033;
  static double critical() { return std::cbrt(q * q / kG); }
  static double depth(double x) {
    const double xi = x / L - 0.5;
    return critical() * (0.75 - 0.15 * std::exp(-36.0 * xi * xi));
  }
  /// dz/dx at x
  static double slope(double x) {
    const double xi = x / L - 0.5, h = depth(x);
    const double dh = critical() * 0.15 * std::exp(-36.0 * xi * xi) * 72.0 * xi / L;
    return -(1.0 - q * q / (kG * h * h * h)) * dh - n * n * q * q / std::pow(h, 10.0 / 3.0);
  }
};

/// The relative L1 errors of depth (over the exact depth's sum) and unit discharge (over q)
/// after the run, over 100 m <= x <= 900 m and over all free cells, and the largest relative
/// change of the depth over the run's last 10 % (0 at a steady state).
struct MacDonaldRun {
  double depth, discharge, depth_all, discharge_all, unsteady;
};
MacDonaldRun run_macdonald(int cells, int order, const Target& target) {
  using M = MacDonald;
  const double dx = M::L / cells, t_end = 1000.0;
  const int held = 3;
  Terrain t = flat_terrain(cells, 3, dx);
  std::vector<double> z(static_cast<std::size_t>(cells)), h(z.size());
  double acc = 0;  // z(x) = -int_x^L z'(s) ds, from the outlet
  for (int c = cells - 1; c >= 0; --c) {
    const double a = (c + 0.5) * dx, b = c == cells - 1 ? M::L : (c + 1.5) * dx;
    const int panels = 64;
    const double step = (b - a) / panels;
    double sum = M::slope(a) + M::slope(b);
    for (int k = 1; k < panels; ++k) sum += (k % 2 ? 4 : 2) * M::slope(a + k * step);
    acc -= sum * step / 3;
    z[static_cast<std::size_t>(c)] = acc;
    h[static_cast<std::size_t>(c)] = M::depth(a);
  }
  t.water_depth.assign(t.grid.cells(), 0.0);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < cells; ++c) {
      t.bed[static_cast<std::size_t>(r) * cells + c] = z[c];
      t.water_depth[static_cast<std::size_t>(r) * cells + c] = h[c];
    }
  // steps of 0.05 dx s: (|u| + c) dt / dx + c dt / dy <= 0.46 with u <= 4.5 m/s, c <= 2.3 m/s
  const double dt = 0.05 * dx;
  Params p = sw_params(dt, order);
  p.flow.manning_n.value = M::n;
  p.boundary.east = BoundaryKind::open;
  auto sim = make_simulation(t, p, target);
  sim.backend().set_field(FieldId::momentum_x, std::vector<double>(t.grid.cells(), 0.8 * M::q));
  const long steps = std::lround(t_end / dt), tail = steps / 10;
  std::vector<double> before;
  for (long s = 0; s < steps; ++s) {
    sim.step();
    auto hf = sim.field(FieldId::water_depth);
    auto qf = sim.field(FieldId::momentum_x);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < held; ++c) {
        const std::size_t i = static_cast<std::size_t>(r) * cells + c;
        hf[i] = h[static_cast<std::size_t>(c)];
        qf[i] = M::q;
      }
    sim.backend().set_field(FieldId::water_depth, hf);
    sim.backend().set_field(FieldId::momentum_x, qf);
    if (s == steps - tail) before = middle_row(sim, FieldId::water_depth);
  }
  const auto hn = middle_row(sim, FieldId::water_depth);
  const auto qn = middle_row(sim, FieldId::momentum_x);
  MacDonaldRun out{};
  double eh = 0, eq = 0, sh = 0, eh_all = 0, eq_all = 0, sh_all = 0;
  int n_mid = 0, n_all = 0;
  for (int c = held; c < cells; ++c) {
    const std::size_t i = static_cast<std::size_t>(c);
    const double dh = std::abs(hn[i] - h[i]), dq = std::abs(qn[i] - M::q), x = (c + 0.5) * dx;
    eh_all += dh;
    eq_all += dq;
    sh_all += h[i];
    ++n_all;
    if (x >= 100.0 && x <= 900.0) {
      eh += dh;
      eq += dq;
      sh += h[i];
      ++n_mid;
    }
    out.unsteady = std::max(out.unsteady, std::abs(hn[i] - before[i]) / h[i]);
  }
  out.depth = eh / sh;
  out.discharge = eq / (n_mid * M::q);
  out.depth_all = eh_all / sh_all;
  out.discharge_all = eq_all / (n_all * M::q);
  return out;
}

TEST_P(ShallowWater, MacDonaldSupercriticalSecondOrder) {
  // The second order's order on a smooth steady flow (issue 16): between each pair of rungs of
  // 50, 100, 200 cells (the report adds 400) the depth and discharge errors over 100 .. 900 m
  // fall at order >= 1.7 (measured 2.01, 2.01, 2.00 in depth; 2.2, 2.2, 2.06 in discharge; at
  // 400 cells float32's discharge error meets its rounding floor, below), and at 200 cells the
  // second order's depth error is below a fifth of the first order's. The first order is
  // printed, not bounded: where the bed drops by a good part of the depth per cell (0.3 m on
  // 0.55 m at 10 m cells) the first-order hydrostatic reconstruction keeps only part of the bed
  // force (depth errors 0.10, 0.066 at 100, 200 cells), and at 20 m cells the step treatment
  // (film over a step, model.md 3.10) takes over. An idle solver keeps q = 1.6 (discharge error
  // 0.2). The second order's end state carries a small oscillation, the minmod limiter switching
  // on the steep bed (the largest change of the depth over the last 100 s: 2.4e-3, 5.7e-4, 6e-5
  // of itself at 50, 100, 200 cells, falling faster than the error); bound 1e-2.
  std::vector<int> sizes{50, 100, 200};
  if (vr::full_ladder()) sizes.push_back(400);
  auto fig = [&](const std::string& q, double dx) {
    return figure("sw_macdonald", "shallow_water", q.c_str(), dx,
                  "MacDonald et al. (1997) construction, SWASHES");
  };
  std::vector<MacDonaldRun> first, second;
  for (int n : sizes) {
    const double dx = MacDonald::L / n;
    for (int order : {1, 2}) {
      const MacDonaldRun r = run_macdonald(n, order, target());
      std::printf(
          "[sw MacDonald] %s order %d, %d cells (dx %.2f m): depth error %.3e, discharge error "
          "%.3e over 100 .. 900 m (whole channel %.3e, %.3e); end-state change %.1e%s\n",
          target().label().c_str(), order, n, dx, r.depth, r.discharge, r.depth_all,
          r.discharge_all, r.unsteady, order == 2 ? " (bound 1e-2)" : "");
      const std::string o = order == 1 ? "first order: " : "second order: ";
      vr::report(fig(o + "depth error (relative L1, 100-900 m)", dx), r.depth);
      vr::report(fig(o + "discharge error (relative L1, 100-900 m)", dx), r.discharge);
      (order == 1 ? first : second).push_back(r);
      if (order == 1) continue;
      vr::expect_below(fig(o + "end-state change (relative)", dx), r.unsteady, 1e-2);
      if (second.size() < 2) continue;
      const double p_h = observed_order(second[second.size() - 2].depth, r.depth);
      const double p_q = observed_order(second[second.size() - 2].discharge, r.discharge);
      std::printf(
          "[sw MacDonald] %s second order, %d -> %d cells: observed order depth %.2f, discharge "
          "%.2f (bound >= 1.7)\n",
          target().label().c_str(), n / 2, n, p_h, p_q);
      vr::expect_above(fig(o + "observed order, depth", dx), p_h, 1.7);
      // float32: at 400 cells (the report's rung) the discharge error, 5e-6 of q in float64,
      // meets its rounding floor (the momentum fluxes of about 7 m^3/s^2 rounded to 6e-8 of
      // themselves every step: 7.4e-6 measured), so its order there is reported, not bounded
      if (!target().f64() && n >= 400)
        vr::report(fig(o + "observed order, discharge (float32 at its rounding floor)", dx), p_q);
      else
        vr::expect_above(fig(o + "observed order, discharge", dx), p_q, 1.7);
    }
  }
  const double ratio = second[2].depth / first[2].depth;
  std::printf(
      "[sw MacDonald] %s 200 cells: second-order depth error / first-order %.4f (bound < 0.2)\n",
      target().label().c_str(), ratio);
  vr::expect_below(fig("depth error, second / first order", 5.0), ratio, 0.2);
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

/// The textbook minmod (the one of a and b of smaller magnitude where they share a sign, else
/// 0), written as sw_minmod was until 2026-11-30: the reference for the form that PoCL
/// vectorises (one comparison of a with b instead of two absolute values).
template <class T>
T textbook_minmod(T a, T b) {
  const T m = std::fabs(a) < std::fabs(b) ? a : b;
  return a * b > T(0) ? m : T(0);
}

template <class T>
bool same_bits(T x, T y) {
  return std::memcmp(&x, &y, sizeof(T)) == 0;
}

/// sw_minmod and sw_limited_slope against the textbook forms, bit for bit: every pair and
/// triple of 26 special values (signed zeros, the smallest subnormal and normal numbers, equal
/// and neighbouring magnitudes, the largest number, infinities, NaN), then 4 million random
/// pairs and triples (random bit patterns, and values near one another, where ties and the
/// skipped equal-neighbour case arise), in float and in double. Bound 0 values differing: both
/// kernels and the CPU reference rely on the same bits (digests). With the comparison's sense
/// reversed ((a < 0) == (a < b)) 1.22 and 1.21 million of the 4.0 million differ (float, double).
template <class T>
void expect_minmod_is_textbook(const char* type) {
  const T inf = std::numeric_limits<T>::infinity(), tiny = std::numeric_limits<T>::denorm_min();
  const T lo = std::numeric_limits<T>::min(), big = std::numeric_limits<T>::max();
  const T one_up = std::nextafter(T(1), T(2));
  std::vector<T> special{T(0),   T(1),     tiny,   lo,
                         one_up, T(0.5),   T(3),   big,
                         inf,    T(1e-20), T(2.5), T(2.5) + std::numeric_limits<T>::epsilon()};
  const std::size_t n_pos = special.size();
  for (std::size_t i = 0; i < n_pos; ++i) special.push_back(-special[i]);
  special.push_back(std::numeric_limits<T>::quiet_NaN());
  special.push_back(-std::numeric_limits<T>::quiet_NaN());
  std::size_t checked = 0, differ = 0;
  auto check_pair = [&](T a, T b) {
    ++checked;
    differ += !same_bits(cell::sw_minmod<T>(a, b), textbook_minmod(a, b));
  };
  auto check_triple = [&](int on, T m, T c, T p) {
    ++checked;
    const T want = on ? textbook_minmod(c - m, p - c) : T(0);
    differ += !same_bits(cell::sw_limited_slope<T>(on, m, c, p), want);
  };
  for (T a : special)
    for (T b : special) {
      check_pair(a, b);
      for (T c : special) check_triple(1, a, b, c);
    }
  std::mt19937_64 rng(20261130);
  using Bits = std::conditional_t<sizeof(T) == 4, std::uint32_t, std::uint64_t>;
  auto random_value = [&] {
    const Bits b = static_cast<Bits>(rng());
    T x;
    std::memcpy(&x, &b, sizeof x);
    return x;
  };
  std::uniform_real_distribution<T> near(T(-2), T(2));
  std::uniform_int_distribution<int> pick(0, 3);
  auto nearby = [&] {  // small integers and their neighbours: ties and equal values
    const T x = std::round(near(rng) * T(2)) / T(2);
    const int k = pick(rng);
    return k == 0 ? x : (k == 1 ? std::nextafter(x, T(3)) : (k == 2 ? -x : x * T(0.5)));
  };
  for (int i = 0; i < 1000000; ++i) {
    check_pair(random_value(), random_value());
    check_pair(nearby(), nearby());
    check_triple(i & 1, random_value(), random_value(), random_value());
    check_triple(1, nearby(), nearby(), nearby());
  }
  std::printf(
      "[minmod] %s: %zu of %zu pairs and triples differ from the textbook minmod (bound 0)\n", type,
      differ, checked);
  EXPECT_EQ(differ, 0u) << type;
}

TEST(ShallowWaterCell, MinmodAndLimitedSlopeGiveTheTextbookBits) {
  expect_minmod_is_textbook<float>("float");
  expect_minmod_is_textbook<double>("double");
}

}  // namespace
}  // namespace erodem::test
