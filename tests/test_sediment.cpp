// erodem — the physical erosion law (erosion.law = "physical", docs/model.md section 3.5) against
// closed forms: well-mixed settling, the threshold of motion and the equilibrium concentration,
// the adaptation of clear water along a uniform channel, Exner's porosity in a closed box, and a
// layered bed eroding through its soil into the bedrock. The flows are held fixed where the
// closed form needs it (run_processes: erosion, and transport, alone on a state set with
// set_field). Each test prints the measured figure beside its bound, and every bound fails for
// an idle solver (the state unchanged).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>

#include "erodem/io/setup.hpp"
#include "reference_solutions.hpp"
#include "scenarios.hpp"
#include "target_test.hpp"
#include "validation_record.hpp"

namespace erodem::test {
namespace {

namespace vr = validation;

class Sediment : public TargetTest {};

constexpr double kRho = 1000.0, kG = 9.81;

/// The published formulas, written out here in double apart from the kernels (erosion.h): the
/// settling velocity of Ferguson & Church (2004) with C1 = 18, C2 = 1; Soulsby & Whitehouse's
/// (1997) critical Shields number; Manning-Strickler's grain roughness (2.5 D)^(1/6) /
/// (8.1 sqrt g); Engelund & Hansen's (1967) total load carried at the flow's speed.
struct Grains {
  double d = 0.5e-3, rho_s = 2650.0, nu = 1e-6;
  double r() const { return rho_s / kRho - 1.0; }
  double settling() const {
    return r() * kG * d * d / (18.0 * nu + std::sqrt(0.75 * r() * kG * d * d * d));
  }
  double shields_crit() const {
    const double ds = d * std::pow(r() * kG / (nu * nu), 1.0 / 3.0);
    return 0.30 / (1.0 + 1.2 * ds) + 0.055 * (1.0 - std::exp(-0.020 * ds));
  }
  double skin_n() const { return std::pow(2.5 * d, 1.0 / 6.0) / (8.1 * std::sqrt(kG)); }
  /// Bed shear stress (Pa) of depth h (m), speed u (m/s) and Manning n.
  static double tau(double h, double u, double n) {
    return kRho * kG * n * n * u * u / std::cbrt(h);
  }
  /// The skin Shields number theta' of that flow (1).
  double theta_skin(double h, double u, double n) const {
    const double ratio = std::min(1.0, skin_n() * skin_n() / (n * n));
    return tau(h, u, n) * ratio / ((rho_s - kRho) * kG * d);
  }
  /// Engelund-Hansen's equilibrium volume concentration (1), thresholded at theta_c.
  double c_eq(double h, double u, double n) const {
    const double theta = tau(h, u, n) / ((rho_s - kRho) * kG * d);
    const double ts = theta_skin(h, u, n), tc = shields_crit();
    if (ts <= tc) return 0.0;
    const double te = theta * (1.0 - tc / ts);
    const double cf = kG * n * n / std::cbrt(h);
    const double q_t = 0.05 * std::sqrt(r() * kG * d * d * d) * std::pow(te, 2.5) / cf;
    return q_t / (u * h);
  }
  /// Garcia & Parker's (1991) pick-up E_s = A Z^5 / (1 + A Z^5 / 0.3), A = 1.3e-7, Z = u*'
  /// Re_p^0.6 / w_s (u*' = sqrt(tau' / rho)), 0 below theta_c.
  double e_s(double h, double u, double n) const {
    if (theta_skin(h, u, n) <= shields_crit()) return 0.0;
    const double tau_skin = tau(h, u, n) * std::min(1.0, skin_n() * skin_n() / (n * n));
    const double re_p = std::sqrt(r() * kG * d) * d / nu;
    const double z = std::sqrt(tau_skin / kRho) * std::pow(re_p, 0.6) / settling();
    const double az5 = 1.3e-7 * std::pow(z, 5.0);
    return az5 / (1.0 + az5 / 0.3);
  }
  /// The speed (m/s) at which theta' = factor * theta_c for depth h and Manning n.
  double speed_at(double factor, double h, double n) const {
    return std::sqrt(factor * shields_crit() / theta_skin(h, 1.0, n));
  }
};

/// Physical-law parameters of a quiet run (every other process off), steps of dt s, the grains
/// of `g`, and no slope dependence of theta_c (the beds here are flat or nearly so).
Params sediment_params(const Grains& g, double dt) {
  Params p = quiet_params(FlowScheme::local_inertial, dt);
  p.erosion.enabled = true;
  p.erosion.law = ErosionLaw::physical;
  p.erosion.grain_size = g.d;
  p.erosion.sediment_density = g.rho_s;
  p.erosion.kinematic_viscosity = g.nu;
  p.erosion.slope_threshold = false;
  p.flow.water_density = kRho;
  p.flow.gravity = kG;
  return p;
}

/// The mean of a field over the DEM cells.
double mean_of(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return s / static_cast<double>(v.size());
}

// ---- well-mixed settling ---------------------------------------------------------------

TEST_P(Sediment, SettlingDecaysAsExpOfMinusWsTOverH) {
  // Still water 0.5 m deep over a flat bed of 0.1 mm grains (w_s = 7.5 mm/s by Ferguson &
  // Church): no shear, so no entrainment, and the suspension settles as ds/dt = -w_s s / h:
  // s(t) = s0 exp(-w_s t / h). 100 s in steps of 1 s and of 10 s: the exact factor per step
  // makes both exact to rounding, where explicit Euler would be 1.1 % off at 1 s and 15 % at
  // 10 s. Bound 1 % (the issue's); an idle solver is off by exp(1.5) - 1 = 348 %. And Exner:
  // the bed rises by what settles over 1 - phi (0.4), (1 - phi) dz = s0 - s, to rounding:
  // 1e-12 in float64, 1e-5 in float32 (the suspension's float rounding, 2^-24 per step).
  Grains g;
  g.d = 0.1e-3;
  const double h = 0.5, s0 = 0.01, t_end = 100.0, w_s = g.settling();
  for (double dt : {1.0, 10.0}) {
    Params p = sediment_params(g, dt);
    auto sim = make_simulation(flat_terrain(6, 3, 10.0), p, target());
    set_uniform_flow(sim, h, 0.0);
    const std::size_t n = sim.grid().cells();
    sim.backend().set_field(FieldId::sediment, std::vector<double>(n, s0));
    run_processes(sim, {Process::erosion}, dt, static_cast<long>(t_end / dt + 0.5));
    const double s = mean_of(sim.field(FieldId::sediment));
    const double exact = s0 * std::exp(-w_s * t_end / h);
    const double bed = mean_of(sim.field(FieldId::bed));
    const double exner = std::abs((1.0 - 0.4) * bed - (s0 - s)) / (s0 - exact);
    vr::expect_below(figure("sediment_settling", "physical", "|s / s_exact - 1|", dt,
                            "s0 exp(-w_s t / h), w_s by Ferguson & Church (2004)"),
                     std::abs(s / exact - 1.0), 0.01);
    vr::expect_below(figure("sediment_settling", "physical",
                            "|(1 - phi) bed rise - settled| / settled", dt, "Exner with porosity"),
                     exner, bound(1e-12, 1e-5));
    std::printf("[settling] %s dt %g s: w_s %.5g m/s, s/s0 %.6f (exact %.6f), Exner %.2e\n",
                target().label().c_str(), dt, w_s, s / s0, exact / s0, exner);
  }
}

// ---- threshold of motion and the equilibrium concentration -----------------------------

TEST_P(Sediment, NoEntrainmentBelowTheShieldsThresholdAndEngelundHansenAbove) {
  // A uniform flow 2 m deep (Manning n 0.03) held fixed over a flat bed of 0.5 mm sand, clear
  // water, one step of 1 s (erosion alone). Speeds at theta' = f theta_c for f = 0.5, 0.99
  // (a deep slow channel: nothing may move, bound: exactly 0) and 1.01, 1.5, 3 (the sediment
  // after one step must be c_eq h (1 - exp(-w_s dt / h)) with c_eq of Engelund & Hansen
  // computed here in double: bound 1e-3 relative, float32 rounding of the stress and the
  // Shields ratio near the threshold (1 - theta_c / theta' = 0.0099 at f = 1.01 amplifies it
  // 100-fold)). An idle solver gives 0 above the threshold (error 1); one without the
  // threshold entrains below it.
  // Garcia & Parker's pick-up the same way (c_eq = E_s, the well-mixed column).
  const Grains g;
  const double h = 2.0, n = 0.03, dt = 1.0, w_s = g.settling();
  for (Pickup pickup : {Pickup::engelund_hansen, Pickup::garcia_parker})
    for (double f : {0.5, 0.99, 1.01, 1.5, 3.0}) {
      const bool eh = pickup == Pickup::engelund_hansen;
      Params p = sediment_params(g, dt);
      p.erosion.pickup = pickup;
      p.flow.manning_n.value = n;
      auto sim = make_simulation(flat_terrain(4, 3, 10.0), p, target());
      const double u = g.speed_at(f, h, n);
      set_uniform_flow(sim, h, u);
      run_processes(sim, {Process::erosion}, dt, 1);
      const double s = mean_of(sim.field(FieldId::sediment));
      const double c_eq = eh ? g.c_eq(h, u, n) : g.e_s(h, u, n);
      const double exact = c_eq * h * (1.0 - std::exp(-w_s * dt / h));
      const char* scheme = eh ? "physical, engelund_hansen" : "physical, garcia_parker";
      if (f < 1.0) {
        vr::expect_below(figure("sediment_threshold", scheme, "suspended after 1 s (m)", f,
                                "0 below theta_c (Soulsby & Whitehouse 1997)"),
                         s, 1e-300);
      } else {
        vr::expect_below(figure("sediment_threshold", scheme, "|s / s_closed_form - 1|", f,
                                eh ? "Engelund & Hansen (1967), thresholded at theta_c"
                                   : "Garcia & Parker (1991) pick-up"),
                         std::abs(s / exact - 1.0), 1e-3);
      }
      std::printf(
          "[threshold] %s %s theta'/theta_c %.2f: u %.4f m/s, s %.6e m (closed form "
          "%.6e)\n",
          target().label().c_str(), scheme, f, u, s, exact);
    }
}

// ---- adaptation along a uniform channel ------------------------------------------------

TEST_P(Sediment, ClearWaterAdaptsToEngelundHansenOverTheSettlingLength) {
  // Uniform flow 1 m deep at 1 m/s (n 0.03) held fixed along a flat channel of 0.1 mm sand
  // (w_s = 7.5 mm/s), clear water entering at the west wall; erosion and conservative
  // transport. Steady state: u dc/dx = (w_s / h) (c_eq - c), so c = c_eq (1 - exp(-x / L)) with
  // L = u h / w_s = 133 m, resolved by 27 cells of 5 m (the issue asks for 20); the channel is
  // 6 L long and runs 2.2 transit times. Figures: the mean |c - c_exact| / c_eq over the
  // channel (first-order upwind after a split exchange: a / 50 expected at a = dx / L =
  // 0.037; bound a / 10 as for the capacity law, an idle solver scores 0.83 and one without
  // transport 0.17), and the flux c u h leaving the last cell against Engelund & Hansen's q_t
  // (c there is 1 - e^-6 of c_eq: bound 1 %).
  Grains g;
  g.d = 0.1e-3;
  const double h = 1.0, u = 1.0, n = 0.03, dx = 5.0, w_s = g.settling();
  const double len = u * h / w_s, c_eq = g.c_eq(h, u, n);
  const int cells = static_cast<int>(6 * len / dx + 0.5);
  Params p = sediment_params(g, 0.4 * dx / u);
  p.flow.manning_n.value = n;
  auto sim = make_simulation(flat_terrain(cells, 3, dx), p, target());
  set_uniform_flow(sim, h, u);
  const double duration = 2.2 * cells * dx / u;
  run_processes(sim, {Process::erosion, Process::transport}, p.time.dt,
                static_cast<long>(duration / p.time.dt + 0.5));
  const Row row{cells, dx, 0.0};
  std::vector<double> c = middle_row(sim, FieldId::sediment);
  for (double& x : c) x /= h;
  const auto exact = row.sample([&](double x) { return c_eq * (1.0 - std::exp(-x / len)); });
  double err = 0;
  for (int k = 0; k < cells; ++k) err += std::abs(c[k] - exact[k]);
  err /= cells * c_eq;
  const double a = dx / len;
  vr::profile(figure("sediment_adaptation_physical", "physical", "", dx, ""), "physical",
              {"x", "concentration", "concentration_exact"},
              {row.sample([](double x) { return x; }), c, exact});
  vr::expect_below(figure("sediment_adaptation_physical", "physical",
                          "mean |c - c_exact| / c_eq (dx / L = 0.037)", dx,
                          "c_eq (1 - exp(-x w_s / (u h))), c_eq of Engelund & Hansen"),
                   err, 0.1 * a);
  const double q_t = c_eq * u * h;
  const double flux = c[cells - 1] * u * h;
  vr::expect_below(figure("sediment_adaptation_physical", "physical",
                          "|outlet flux / q_t - 1| (x = 6 L)", dx, "Engelund & Hansen's q_t"),
                   std::abs(flux / q_t - 1.0), 0.01);
  std::printf(
      "[adaptation] %s L %.1f m (%.1f cells), c_eq %.4e: error %.2e (bound %.2e), "
      "outlet flux %.5e of q_t %.5e m^2/s\n",
      target().label().c_str(), len, len / dx, c_eq, err, 0.1 * a, flux, q_t);
}

// ---- a channel fed at capacity ----------------------------------------------------------

TEST_P(Sediment, ChannelFedAtCapacityCarriesTheEquilibriumFlux) {
  // A 2 km channel of slope 1e-3 (n 0.03; ManningPlane, local inertial, adaptive steps) fed with
  // q = 1 m^2/s carrying Engelund & Hansen's c_eq of its normal flow (h = 0.969 m, u = 1.03 m/s:
  // theta' = 0.22, 7 times theta_c; c_eq = 2.6e-4) through a line inflow
  // (inflow.sediment_concentration), open outlet, 0.5 mm sand. After 8000 s the flow is uniform
  // and the sediment in equilibrium: the flux c q through the east faces of the middle half
  // must be Engelund & Hansen's q_t within 1 % (the bound; the normal depth itself is
  // met to 1e-4 here, ManningPlaneNormalDepth). An idle solver carries nothing; clear water fed
  // in would have to pick the load up first (a settling length of 14 m here, so the middle is
  // in equilibrium either way: the figure checks the closure's equilibrium, the inflow's
  // sediment is checked by the ledger, which must count it to close).
  const Grains g;
  ManningPlane plane;
  plane.q = 1.0;
  const double h = plane.normal_depth(), u = plane.q / h, n = plane.manning;
  const double c_eq = g.c_eq(h, u, n);
  Params p = plane.params(1.0);
  p.time.adaptive = true;
  p.time.dt_max = 5.0;
  p.erosion.enabled = true;
  p.erosion.law = ErosionLaw::physical;
  p.inflow[0].sediment_concentration = c_eq;
  auto sim = make_simulation(plane.terrain(), p, target());
  while (sim.time() < 8000.0) sim.step();
  const auto s = middle_row(sim, FieldId::sediment), d = middle_row(sim, FieldId::water_depth),
             f = middle_row(sim, FieldId::flux_right);
  double flux = 0;
  for (int c = plane.n / 4; c < 3 * plane.n / 4; ++c)
    flux += s[c] / d[c] * f[c] / plane.dx / (plane.n / 2);
  const double q_t = c_eq * plane.q;
  const Ledger& L = sim.ledger();
  vr::expect_below(
      figure("sediment_channel_at_capacity", "physical", "|sediment flux / q_t - 1| (middle half)",
             plane.dx, "Engelund & Hansen's q_t of the normal flow"),
      std::abs(flux / q_t - 1.0), 0.01);
  EXPECT_GT(L.sediment_inflow, 0.5 * q_t * 3 * plane.dx * 8000.0);
  EXPECT_LT(std::abs(L.relative_material_closure_error()), bound(1e-12, 1e-6));
  std::printf(
      "[channel at capacity] %s: c_eq %.4e, flux %.6e of q_t %.6e m^2/s (%.2e); sediment "
      "in %.4e m^3, out %.4e; material closure %.2e of what moved\n",
      target().label().c_str(), c_eq, flux, q_t, flux / q_t - 1.0, L.sediment_inflow,
      L.sediment_out, L.relative_material_closure_error());
}

// ---- sediment-laden sea water -----------------------------------------------------------

TEST_P(Sediment, SeaWaterBringsItsConcentrationIn) {
  // A dry basin of 30 x 10 cells of 2 m, its floor 0.5 to 1.1 m below the sea, behind the sea:
  // a fixed_level west edge, or a west column of nodata cells with boundary.nodata = "sea".
  // The sea water carries boundary.sediment_concentration = 0.02; the bed neither gives nor
  // takes (theta_c = 100, w_s = 1e-16 m/s), so after 300 steps of 0.1 s the suspended solid must
  // be 0.02 times the water that came in (the ledger's -boundary_out): bound 1e-12 (float64)
  // and 1e-5 (float32 rounding of s / d times the fluxes), and the ledger must count it as
  // sediment in (sediment_out = -0.02 x water in, material closure at rounding). Clear sea
  // water (the default) or a ghost that gave none would bring 0.
  const int nx = 30, ny = 10;
  const double dx = 2.0, dt = 0.1, c_b = 0.02;
  for (bool nodata_sea : {false, true}) {
    Terrain t = flat_terrain(nx, ny, dx);
    for (int r = 0; r < ny; ++r)
      for (int c = 0; c < nx; ++c)
        t.bed[static_cast<std::size_t>(r) * nx + c] = -0.5 - 0.6 * c / (nx - 1.0);
    Params p = sediment_params(Grains{}, dt);
    p.flow.manning_n.value = 0.03;
    p.boundary.sea_level = 0.0;
    p.boundary.sediment_concentration = c_b;
    p.erosion.critical_shields = 100.0;
    p.erosion.settling_velocity = 1e-16;  // settles w_s t / h = 6e-15 of it in 30 s
    if (nodata_sea) {
      t.mask.assign(t.grid.cells(), 1);
      for (int r = 0; r < ny; ++r) t.mask[static_cast<std::size_t>(r) * nx] = 0;
      p.boundary.nodata = NodataKind::sea;
    } else {
      p.boundary.west = BoundaryKind::fixed_level;
    }
    auto sim = make_simulation(t, p, target());
    sim.step(300);
    const Ledger& L = sim.ledger();
    const auto s = sim.field(FieldId::sediment);
    double suspended = 0;
    for (std::size_t i = 0; i < s.size(); ++i)
      if (t.active(i)) suspended += s[i] * dx * dx;
    const double water_in = -L.boundary_out;
    const double err = std::abs(suspended / (c_b * water_in) - 1.0);
    const char* scheme = nodata_sea ? "physical, sea nodata" : "physical, fixed_level edge";
    vr::expect_below(figure("sediment_sea_inflow", scheme, "|suspended / (c_b x water in) - 1|", dx,
                            "the sea's concentration times the water it gave"),
                     err, bound(1e-12, 1e-5));
    EXPECT_GT(water_in, 10.0) << "the sea must flood in";
    EXPECT_NEAR(L.sediment_out, -c_b * water_in, 1e-5 * c_b * water_in);
    EXPECT_LT(std::abs(L.relative_material_closure_error()), bound(1e-12, 1e-6));
    std::printf(
        "[sea sediment] %s %s: water in %.4f m^3, suspended %.6e m^3 (%.2e off), "
        "sediment out %.6e, material closure %.2e\n",
        target().label().c_str(), scheme, water_in, suspended, err, L.sediment_out,
        L.relative_material_closure_error());
  }
}

// ---- Exner in a closed box -------------------------------------------------------------

TEST_P(Sediment, ExnerWithPorosityInAClosedBox) {
  // A 64 x 64 crop of Big Tujunga, closed edges, 100 mm/h for 600 s on the default physical
  // law (0.5 mm sand, porosity 0.4, 1 m of soil): nothing leaves, so the solid the bed gives
  // is what the water holds: (1 - phi) dV_bed + V_suspended = 0. Relative to the volume
  // eroded; bound 1e-12 in float64 (the fields' rounding), 1e-6 in float32 (the bed's
  // bulk change m / (1 - phi) is rounded once per cell and step, 2^-24). The ledger's material
  // closure (with the bed bulking) is printed too. It must move material: eroded > 1 m^3 (an
  // idle solver: 0).
  Params p;
  p.dem.path = tujunga_path();
  p.dem.window = std::array<int, 4>{500, 250, 64, 64};
  p.time.dt = 1.0;
  p.flow.manning_n.value = 0.035;
  p.rain.rate = 100.0 / 3.6e6;
  p.erosion.enabled = true;
  p.evaporation.rate = 0.0;
  auto sim = make_simulation(io::load_terrain(p), p, target());
  const auto bed0 = sim.field(FieldId::bed);
  sim.step(600);
  const auto bed = sim.field(FieldId::bed), s = sim.field(FieldId::sediment);
  const Grid& gr = sim.grid();
  double d_bed = 0, susp = 0;
  for (int r = 0; r < gr.ny; ++r)
    for (int c = 0; c < gr.nx; ++c) {
      const std::size_t i = static_cast<std::size_t>(r) * gr.nx + c;
      d_bed += (bed[i] - bed0[i]) * gr.area[r];
      susp += s[i] * gr.area[r];
    }
  const Ledger& L = sim.ledger();
  const double exner = std::abs((1.0 - 0.4) * d_bed + susp) / L.eroded;
  vr::expect_above(
      figure("sediment_exner_box", "physical", "eroded (m^3 of solid)", 30.0, "material must move"),
      L.eroded, 1.0);
  vr::expect_below(
      figure("sediment_exner_box", "physical", "|(1 - phi) dV_bed + V_suspended| / V_eroded", 30.0,
             "Exner with porosity, closed box"),
      exner, bound(1e-12, 1e-6));
  std::printf(
      "[exner] %s eroded %.4e m^3, deposited %.4e, suspended %.4e, bed change %.4e: "
      "Exner %.2e; ledger material closure %.2e of %.3e moved\n",
      target().label().c_str(), L.eroded, L.deposited, susp, d_bed, exner,
      L.relative_material_closure_error(), L.material_moved());
}

// ---- a layered bed, detachment limited -------------------------------------------------

TEST_P(Sediment, LayeredBedErodesItsSoilThenTheBedrockAtTheirRates) {
  // Cohesive soil (M 1e-3 kg/m^2/s, tau_c 0.1 Pa, porosity 0.4) 1 cm thick over cohesive
  // bedrock (M 1e-4, tau_c 0.1 Pa, porosity 0) under a uniform flow held fixed with tau_b = 1
  // Pa; settling 1e-9 m/s, so nothing deposits (detachment limited). Closed form: the bed
  // sinks at E_s / (1 - phi) = (M_s / rho_s) (tau / tau_c - 1) / 0.6 = 5.66e-6 m/s until the
  // soil is gone at t* = L (1 - phi) / E_s = 1767 s, then at E_r = 3.40e-7 m/s. Steps of 10 s
  // over 3000 s. Figures (bound 1 % each; an idle solver: 100 %): the soil's rate at t = 500 s,
  // the time the soil runs out (interpolated), the bedrock's rate between 2000 and 3000 s, and
  // the depth eroded at 3000 s. With morfac 10 the same bed in a tenth of the time.
  const Grains g;
  const double h = 1.0, n = 0.03, tau = 1.0, thick = 0.01;
  const double u = std::sqrt(tau * std::cbrt(h) / (kRho * kG * n * n));
  const double e_s = 1e-3 / g.rho_s * (tau / 0.1 - 1.0), e_r = 1e-4 / g.rho_s * (tau / 0.1 - 1.0);
  for (double morfac : {1.0, 10.0}) {
    const double dt = 10.0 / morfac, t_star = thick * 0.6 / e_s / morfac;
    Params p = sediment_params(g, dt);
    p.flow.manning_n.value = n;
    p.erosion.settling_velocity = 1e-9;
    p.erosion.soil_thickness.value = thick;
    p.erosion.soil = BedLayer{SedimentClosure::cohesive, 0.4, 1.0, 1e-3, 0.1, {}};
    p.erosion.bedrock = BedLayer{SedimentClosure::cohesive, 0.0, 1.0, 1e-4, 0.1, {}};
    p.erosion.morfac = morfac;
    auto sim = make_simulation(flat_terrain(4, 3, 10.0), p, target());
    set_uniform_flow(sim, h, u);
    std::vector<double> t{0}, sunk{0}, soil{thick};
    for (int k = 1; k * dt <= 3000.0 / morfac + 1e-9; ++k) {
      run_processes(sim, {Process::erosion}, dt, 1);
      t.push_back(k * dt);
      sunk.push_back(-mean_of(sim.field(FieldId::bed)));
      soil.push_back(mean_of(sim.field(FieldId::soil_thickness)));
    }
    const auto at = [&](double time) {
      const std::size_t k = static_cast<std::size_t>(time / dt + 0.5);
      return sunk[std::min(k, sunk.size() - 1)];
    };
    const double soil_rate = at(500.0 / morfac) / (500.0 / morfac) / morfac;
    // the soil is gone where the bed has sunk by its thickness (linear within the step)
    double t_out = t.back();
    for (std::size_t k = 1; k < sunk.size(); ++k)
      if (sunk[k] >= thick && sunk[k - 1] < thick) {
        t_out = t[k - 1] + (thick - sunk[k - 1]) / (sunk[k] - sunk[k - 1]) * dt;
        EXPECT_LE(soil[k], 0.0) << "the soil is not gone where the bed sank by its thickness";
        break;
      }
    const double rock_rate =
        (at(3000.0 / morfac) - at(2000.0 / morfac)) / (1000.0 / morfac) / morfac;
    // in morphological time (simulated time times morfac) the same bed at every morfac
    const double total = at(3000.0 / morfac),
                 total_exact = thick + e_r * (3000.0 - t_star * morfac);
    const char* scheme = morfac > 1 ? "physical, morfac 10" : "physical";
    const std::string ref = "detachment-limited layered bed (Partheniades)";
    vr::expect_below(
        figure("sediment_layers", scheme, "|soil rate / closed form - 1|", dt, ref.c_str()),
        std::abs(soil_rate / (e_s / 0.6) - 1.0), 0.01);
    vr::expect_below(figure("sediment_layers", scheme, "|t_soil_gone / t* - 1|", dt, ref.c_str()),
                     std::abs(t_out / t_star - 1.0), 0.01);
    vr::expect_below(
        figure("sediment_layers", scheme, "|bedrock rate / closed form - 1|", dt, ref.c_str()),
        std::abs(rock_rate / e_r - 1.0), 0.01);
    vr::expect_below(
        figure("sediment_layers", scheme, "|eroded depth / closed form - 1|", dt, ref.c_str()),
        std::abs(total / total_exact - 1.0), 0.01);
    std::printf(
        "[layers] %s morfac %g: soil %.5e m/s (%.5e), gone at %.1f s (%.1f), rock "
        "%.5e m/s (%.5e), sunk %.6f m (%.6f)\n",
        target().label().c_str(), morfac, soil_rate, e_s / 0.6, t_out, t_star, rock_rate, e_r,
        total, total_exact);
  }
}

ERODEM_INSTANTIATE_TARGETS(Sediment);

}  // namespace
}  // namespace erodem::test
