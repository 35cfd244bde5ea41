// erodem — physics tests: analytical solutions and conservation, run on every backend and
// precision. Each test prints the measured figure beside its bound.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>

#include "erodem/error.hpp"
#include "scenarios.hpp"

namespace erodem::test {
namespace {

class Physics : public ::testing::TestWithParam<Target> {
 protected:
  const Target& target() const { return GetParam(); }
  void SetUp() override {
    if (target().backend == "opencl" && !opencl_available()) GTEST_SKIP() << "no OpenCL device";
  }
  /// Rounding-level bound: `f64` in float64, `f32` in float32.
  double bound(double f64, double f32) const { return target().f64() ? f64 : f32; }
};

double max_speed(const Simulation& sim) {
  const auto u = sim.field(FieldId::velocity_x), v = sim.field(FieldId::velocity_y);
  double m = 0;
  for (std::size_t i = 0; i < u.size(); ++i) m = std::max(m, std::hypot(u[i], v[i]));
  return m;
}

// ---- lake at rest ---------------------------------------------------------------------

TEST_P(Physics, LakeAtRestStaysAtRest) {
  for (FlowScheme scheme : {FlowScheme::pipes, FlowScheme::local_inertial}) {
    SCOPED_TRACE(scheme_name(scheme));
    Params p = quiet_params(scheme, 0.5);
    p.initial.water_level = 10.0;
    auto sim = make_simulation(bumpy_terrain(48, 10.0), p, target());
    sim.step(10000);
    const double speed = max_speed(sim);
    const double limit = bound(1e-9, 1e-4);
    std::printf("[lake at rest] %s %s: max speed after 10000 steps %.3e m/s (bound %.0e)\n",
                target().label().c_str(), scheme_name(scheme), speed, limit);
    EXPECT_LT(speed, limit);
  }
}

// ---- conservation in a closed box -----------------------------------------------------

/// A hump of water over the bumpy bed, sloshing inside closed walls.
Params sloshing_params(FlowScheme scheme) {
  Params p = quiet_params(scheme, 0.2);
  p.flow.manning_n.value = 0.02;
  return p;
}

Terrain sloshing_terrain() {
  Terrain t = bumpy_terrain(40, 10.0);
  t.water_depth.assign(t.grid.cells(), 0.0);
  for (int r = 0; r < 40; ++r)
    for (int c = 0; c < 40; ++c) {
      const auto i = static_cast<std::size_t>(r) * 40 + c;
      const double hump = 2.0 * std::exp(-(std::pow(c - 12.0, 2) + std::pow(r - 15.0, 2)) / 20.0);
      t.water_depth[i] = std::max(0.0, 9.0 + hump - t.bed[i]);
    }
  return t;
}

TEST_P(Physics, ClosedBoxConservesWaterAndMaterial) {
  for (FlowScheme scheme : {FlowScheme::pipes, FlowScheme::local_inertial}) {
    const char* name = scheme_name(scheme);
    SCOPED_TRACE(name);
    Params p = sloshing_params(scheme);
    p.erosion.enabled = true;
    p.erosion.sediment_capacity = 0.5;
    p.transport.scheme = TransportScheme::conservative;
    p.thermal.enabled = true;
    p.thermal.talus_angle = 20.0;
    auto sim = make_simulation(sloshing_terrain(), p, target());
    sim.step(10000);
    const auto& L = sim.ledger();
    const double water_drift = std::abs(L.water - L.water_initial) / L.water_initial;
    const double material_drift = std::abs(L.material - L.material_initial) / L.material_initial;
    const double limit = bound(1e-12, 1e-5);
    const double moved = max_abs(sim.field(FieldId::erosion));
    std::printf(
        "[closed box] %s %s: water drift %.3e, material drift %.3e (bound %.0e); "
        "max |erosion| %.3e m, clipped %.3e m^3\n",
        target().label().c_str(), name, water_drift, material_drift, limit, moved, L.clipped);
    EXPECT_LT(water_drift, limit);
    EXPECT_LT(material_drift, limit);
    EXPECT_GT(moved, 1e-4) << "erosion must have moved material for the test to mean anything";
    EXPECT_LT(L.clipped, 1e-6 * L.water_initial * bound(1e-6, 1.0));
  }
}

TEST_P(Physics, SemiLagrangianLossIsMeasured) {
  Params p = sloshing_params(FlowScheme::local_inertial);
  p.erosion.enabled = true;
  p.erosion.sediment_capacity = 0.5;
  p.transport.scheme = TransportScheme::semi_lagrangian;
  auto sim = make_simulation(sloshing_terrain(), p, target());
  sim.step(3000);
  const auto& L = sim.ledger();
  const double loss = -L.transport_change / L.material_initial;
  const double closure = std::abs(L.relative_material_closure_error());
  std::printf(
      "[semi-Lagrangian] %s: material changed by transport %.3e m^3 (%.3e relative); "
      "ledger closure with it %.3e (bound %.0e)\n",
      target().label().c_str(), -L.transport_change, loss, closure, bound(1e-12, 1e-5));
  EXPECT_NE(L.transport_change, 0.0) << "semi-Lagrangian advection is not conservative";
  EXPECT_LT(closure, bound(1e-12, 1e-5)) << "the ledger must account for the change";
}

// ---- depth never negative; instability stops the run ----------------------------------

TEST_P(Physics, DepthNeverNegativeWhileDraining) {
  for (FlowScheme scheme : {FlowScheme::pipes, FlowScheme::local_inertial}) {
    SCOPED_TRACE(scheme_name(scheme));
    // Thin water on a steep slope drains through an open edge: cells dry out every step.
    Terrain t = flat_terrain(30, 30, 5.0);
    for (int r = 0; r < 30; ++r)
      for (int c = 0; c < 30; ++c) t.bed[static_cast<std::size_t>(r) * 30 + c] = 0.2 * c;
    t.water_depth.assign(t.grid.cells(), 0.01);
    Params p = quiet_params(scheme, 0.05);
    p.flow.manning_n.value = 0.03;
    p.boundary.west = BoundaryKind::open;
    auto sim = make_simulation(t, p, target());
    double min_depth = 0;
    for (int k = 0; k < 40; ++k) {
      sim.step(50);
      const auto d = sim.field(FieldId::water_depth);
      min_depth = std::min(min_depth, *std::min_element(d.begin(), d.end()));
    }
    const auto& L = sim.ledger();
    std::printf(
        "[no negative depth] %s %s: min depth %.3e m, clipped %.3e m^3 of %.3e m^3, "
        "drained %.3e m^3, closure %.3e\n",
        target().label().c_str(), scheme_name(scheme), min_depth, L.clipped, L.water_initial,
        L.boundary_out, L.relative_closure_error());
    EXPECT_GE(min_depth, 0.0);
    EXPECT_GT(L.boundary_out, 0.1 * L.water_initial) << "the slope must drain";
    EXPECT_LT(L.clipped, bound(1e-12, 1e-5) * L.water_initial);
    EXPECT_LT(std::abs(L.relative_closure_error()), bound(1e-12, 1e-5));
  }
}

TEST_P(Physics, NanStopsTheRunNamingTheCell) {
  Params p = quiet_params(FlowScheme::local_inertial, 0.1);
  p.initial.water_level = 1.0;
  auto sim = make_simulation(flat_terrain(20, 10, 1.0), p, target());
  sim.step(5);
  auto d = sim.field(FieldId::water_depth);
  d[7 * 20 + 5] = std::nan("");
  sim.backend().set_field(FieldId::water_depth, d);
  try {
    sim.step();
    FAIL() << "a NaN depth must stop the run";
  } catch (const Error& e) {
    std::printf("[NaN] %s: %s\n", target().label().c_str(), e.what());
    EXPECT_EQ(e.code(), ExitCode::unstable);
    EXPECT_NE(std::string(e.what()).find("col 5, row 7"), std::string::npos) << e.what();
  }
}

TEST_P(Physics, CflViolationStopsTheRun) {
  Params p = quiet_params(FlowScheme::local_inertial, 2.0);  // 2 s on 1 m cells, 4 m deep
  p.initial.water_level = 4.0;
  auto sim = make_simulation(flat_terrain(20, 10, 1.0), p, target());
  try {
    sim.step();
    FAIL() << "dt sqrt(g d) / dx = 12.5 must stop the run";
  } catch (const Error& e) {
    std::printf("[CFL] %s: %s\n", target().label().c_str(), e.what());
    EXPECT_EQ(e.code(), ExitCode::unstable);
    EXPECT_NE(std::string(e.what()).find("CFL"), std::string::npos);
  }
}

}  // namespace

INSTANTIATE_TEST_SUITE_P(Cpu, Physics,
                         ::testing::Values(Target{"cpu", Precision::float32},
                                           Target{"cpu", Precision::float64}),
                         [](const ::testing::TestParamInfo<Target>& i) { return i.param.label(); });
#ifdef ERODEM_HAVE_OPENCL
INSTANTIATE_TEST_SUITE_P(OpenCl, Physics, ::testing::Values(Target{"opencl", Precision::float32}),
                         [](const ::testing::TestParamInfo<Target>& i) { return i.param.label(); });
#endif

}  // namespace erodem::test
