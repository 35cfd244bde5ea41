// erodem — analytical solutions: dam breaks (Stoker, Ritter), uniform Manning flow, rain
// run-off at equilibrium, thermal relaxation to the talus angle. Each test prints the measured
// figure beside its bound.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "scenarios.hpp"

namespace erodem::test {
namespace {

constexpr double kG = 9.81;

/// Stoker's (1957) wet-bed dam-break depth at distance x from the dam (m) and time t (s),
/// upstream depth h0, downstream h1 (m), flat frictionless bed.
struct Stoker {
  double h0, h1, h2 = 0, u2 = 0, shock = 0;
  Stoker(double up, double down) : h0(up), h1(down) {
    // Middle state: rarefaction u2 = 2 (c0 - c2) equals the shock's u2 = S (1 - h1 / h2),
    // S = sqrt(g h2 (h1 + h2) / (2 h1)); bisection on h2 in (h1, h0).
    const double c0 = std::sqrt(kG * h0);
    auto mismatch = [&](double h) {
      const double s = std::sqrt(kG * h * (h1 + h) / (2 * h1));
      return 2 * (c0 - std::sqrt(kG * h)) - s * (1 - h1 / h);
    };
    double lo = h1, hi = h0;
    for (int k = 0; k < 200; ++k) {
      const double mid = 0.5 * (lo + hi);
      (mismatch(mid) > 0 ? lo : hi) = mid;
    }
    h2 = 0.5 * (lo + hi);
    u2 = 2 * (c0 - std::sqrt(kG * h2));
    shock = std::sqrt(kG * h2 * (h1 + h2) / (2 * h1));
  }
  double depth(double x, double t) const {
    const double c0 = std::sqrt(kG * h0), c2 = std::sqrt(kG * h2);
    if (x <= -c0 * t) return h0;
    if (x <= (u2 - c2) * t) return std::pow(2 * c0 - x / t, 2) / (9 * kG);
    if (x <= shock * t) return h2;
    return h1;
  }
};

/// A 1-D channel along x of `n` cells of `dx` m (3 rows between closed walls), water h_up
/// upstream of x0 and h_down downstream.
Terrain dam_break_terrain(int n, double dx, double x0, double h_up, double h_down) {
  Terrain t = flat_terrain(n, 3, dx);
  t.water_depth.assign(t.grid.cells(), 0.0);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < n; ++c)
      t.water_depth[static_cast<std::size_t>(r) * n + c] = (c + 0.5) * dx < x0 ? h_up : h_down;
  return t;
}

std::vector<double> middle_row(const Simulation& sim, FieldId id) {
  const auto f = sim.field(id);
  const int nx = sim.grid().nx;
  return std::vector<double>(f.begin() + nx, f.begin() + 2 * nx);
}

class Analytical : public ::testing::TestWithParam<Target> {
 protected:
  const Target& target() const { return GetParam(); }
  void SetUp() override {
    if (target().backend == "opencl" && !opencl_available()) GTEST_SKIP() << "no OpenCL device";
  }
};

TEST_P(Analytical, StokerWetDamBreak) {
  const int n = 500;
  const double dx = 2.0, x0 = 500.0, t_end = 40.0;
  const Stoker exact(2.0, 1.0);
  for (FlowScheme scheme : {FlowScheme::local_inertial, FlowScheme::pipes}) {
    Params p = quiet_params(scheme, 0.05);
    p.flow.theta = 1.0;  // no diffusion, to see the scheme itself
    p.flow.pipe_area = 1.0;
    auto sim = make_simulation(dam_break_terrain(n, dx, x0, 2.0, 1.0), p, target());
    sim.step(static_cast<long>(t_end / 0.05 + 0.5));
    const auto d = middle_row(sim, FieldId::water_depth);
    double err = 0, norm = 0;
    for (int c = 0; c < n; ++c) {
      const double h = exact.depth((c + 0.5) * dx - x0, sim.time());
      err += std::abs(d[c] - h);
      norm += h;
    }
    const double rel = err / norm;
    std::printf(
        "[Stoker] %s %s: relative L1 depth error %.4f at t = %.1f s (h2 = %.4f m, "
        "shock %.3f m/s)%s\n",
        target().label().c_str(), scheme_name(scheme), rel, sim.time(), exact.h2, exact.shock,
        scheme == FlowScheme::local_inertial ? " (bound 0.10)" : " (reported)");
    if (scheme == FlowScheme::local_inertial) {
      EXPECT_LT(rel, 0.10);
    }
  }
}

TEST_P(Analytical, RitterDryDamBreakFront) {
  const int n = 500;
  const double dx = 2.0, x0 = 400.0, h0 = 1.0, t_end = 30.0;
  const double ritter = 2 * std::sqrt(kG * h0) * t_end;  // front travel (m)
  for (FlowScheme scheme : {FlowScheme::local_inertial, FlowScheme::pipes}) {
    Params p = quiet_params(scheme, 0.05);
    auto sim = make_simulation(dam_break_terrain(n, dx, x0, h0, 0.0), p, target());
    sim.step(static_cast<long>(t_end / 0.05 + 0.5));
    const auto d = middle_row(sim, FieldId::water_depth);
    int last = 0;
    for (int c = 0; c < n; ++c)
      if (d[c] > 1e-3 * h0) last = c;
    const double front = (last + 1) * dx - x0;
    const double rel = (front - ritter) / ritter;
    std::printf(
        "[Ritter] %s %s: front travelled %.1f m, Ritter 2 sqrt(g h0) t = %.1f m, "
        "error %+.1f %%\n",
        target().label().c_str(), scheme_name(scheme), front, ritter, 100 * rel);
    // The local-inertial scheme drops advection, and near a dry front the flow is
    // supercritical, where that term dominates: its front lags Ritter's (measured -56 % at
    // 2 m cells, 2026-11-22). Bound with margin; a front that did not move or overtook the
    // exact one would mean a broken scheme.
    if (scheme == FlowScheme::local_inertial) {
      EXPECT_GT(front, 0.3 * ritter);
      EXPECT_LT(front, 1.05 * ritter);
    }
  }
}

TEST_P(Analytical, ManningPlaneNormalDepth) {
  // A 2 km channel of slope S fed with q per unit width at the top, free outflow at the foot.
  const int n = 200;
  const double dx = 10.0, slope = 1e-3, manning = 0.03, q = 0.5;
  const double normal = std::pow(q * manning / std::sqrt(slope), 0.6);
  Terrain t = flat_terrain(n, 3, dx);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < n; ++c)
      t.bed[static_cast<std::size_t>(r) * n + c] = slope * (n - c - 0.5) * dx;
  t.water_depth.assign(t.grid.cells(), 0.5 * normal);
  Params p = quiet_params(FlowScheme::local_inertial, 1.0);
  p.flow.manning_n.value = manning;
  p.time.adaptive = true;
  p.time.cfl = 0.7;
  p.time.dt_max = 5.0;
  p.boundary.east = BoundaryKind::open;
  const double width = 3 * dx;
  p.inflow.push_back(InflowSpec{{{0.5 * dx, 0.0}, {0.5 * dx, width}}, {{0.0, q * width}}});
  auto sim = make_simulation(t, p, target());
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
  EXPECT_LT(worst, 0.02);
}

TEST_P(Analytical, RainOnTiltedPlaneReachesEquilibrium) {
  const int n = 40;
  const double dx = 10.0, slope = 0.01, rain = 50.0 / 1000.0 / 3600.0;  // 50 mm/h
  Terrain t = flat_terrain(n, n, dx);
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c)
      t.bed[static_cast<std::size_t>(r) * n + c] = slope * (n - r - 0.5) * dx;  // down to south
  for (FlowScheme scheme : {FlowScheme::local_inertial, FlowScheme::pipes}) {
    Params p = quiet_params(scheme, 1.0);
    p.flow.manning_n.value = 0.03;
    p.rain.rate = rain;
    p.time.adaptive = true;
    p.time.dt_max = 2.0;
    p.boundary.south = BoundaryKind::open;
    auto sim = make_simulation(t, p, target());
    while (sim.time() < 5400.0) sim.step();
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
    EXPECT_NEAR(ratio, 1.0, 0.02);
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
  const double tan_talus = std::tan(talus * M_PI / 180.0);
  const auto& L = sim.ledger();
  const double drift = std::abs(L.material - L.material_initial) / L.material_initial;
  const double peak = *std::max_element(b.begin(), b.end());
  std::printf(
      "[thermal] %s: steepest slope %.5f, tan(talus) %.5f, ratio %.5f (bound 1.01); "
      "peak %.2f m; material drift %.2e (bound %.0e)\n",
      target().label().c_str(), worst, tan_talus, worst / tan_talus, peak, drift,
      target().f64() ? 1e-12 : 1e-5);
  EXPECT_LT(worst, 1.01 * tan_talus);
  EXPECT_LT(peak, 19.0) << "the block must have collapsed";
  EXPECT_LT(drift, target().f64() ? 1e-12 : 1e-5);
}

}  // namespace

INSTANTIATE_TEST_SUITE_P(Cpu, Analytical,
                         ::testing::Values(Target{"cpu", Precision::float32},
                                           Target{"cpu", Precision::float64}),
                         [](const ::testing::TestParamInfo<Target>& i) { return i.param.label(); });
#ifdef ERODEM_HAVE_OPENCL
INSTANTIATE_TEST_SUITE_P(OpenCl, Analytical,
                         ::testing::Values(Target{"opencl", Precision::float32}),
                         [](const ::testing::TestParamInfo<Target>& i) { return i.param.label(); });
#endif

}  // namespace erodem::test
