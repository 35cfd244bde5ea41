// erodem — Green-Ampt infiltration (kernels/common/infiltration.h, model.md section 3.11)
// against its closed forms, on every target: the ponded cumulative infiltration, the ponding
// time of rain above K_sat, rain below K_sat, the finite store and the recovery between
// storms. Each test prints the measured figure beside its bound; a solver that infiltrates
// nothing (F = 0) or at a constant or explicit rate fails each one.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "common/infiltration.h"
#include "scenarios.hpp"
#include "target_test.hpp"
#include "validation_record.hpp"

namespace erodem::test {
namespace {

class Infiltration : public TargetTest {};

// Rawls et al. (1983)'s loam: K_sat 0.34 cm/h, psi 8.89 cm; delta theta 0.3.
constexpr double kKsat = 0.34e-2 / 3600.0, kPsi = 0.0889, kDeficit = 0.3;
constexpr double kS = kPsi * kDeficit;  // psi delta theta (m)

/// The Green-Ampt depth from F0 after t of ponding (reference_solutions.hpp), the loam's by
/// default.
double green_ampt_exact(double f0, double t, double k = kKsat, double s = kS) {
  return f0 + green_ampt_increment_exact(f0, t, k, s);
}

/// Green-Ampt with the loam above, every other process off, fixed steps of `dt` s.
Params infiltration_params(double dt) {
  Params p = quiet_params(FlowScheme::local_inertial, dt);
  p.infiltration.enabled = true;
  p.infiltration.ksat.value = kKsat;
  p.infiltration.suction.value = kPsi;
  p.infiltration.moisture_deficit.value = kDeficit;
  return p;
}

/// A flat closed tile of 4 x 4 cells of 2 km (Courant sqrt(g 0.1) 600 / 2000 = 0.3 at the
/// longest step) with `depth` m of water.
constexpr double kCellArea = 4e6;  // m^2
Terrain pond(double depth) {
  Terrain t = flat_terrain(4, 4, 2000.0);
  t.water_depth.assign(t.grid.cells(), depth);
  return t;
}

double max_of(const std::vector<double>& v) {
  return *std::max_element(v.begin(), v.end());
}
double min_of(const std::vector<double>& v) {
  return *std::min_element(v.begin(), v.end());
}

TEST_P(Infiltration, PondedGreenAmptFollowsTheImplicitClosedForm) {
  // 0.1 m of water over the loam for 2 h, in steps of 10 s and of 600 s: the infiltrated depth
  // F(t) against the implicit relation F - S ln(1 + F / S) = K_sat t solved here, at 1 min,
  // 10 min and 2 h (F = 1.8, 5.9 and 23.8 mm; the pond stays deeper than F). The per-step
  // relation is exact for any step (the rate depends on F alone), so both steps meet the
  // issue's 0.5 %; measured: rounding. The depth is 0.1 - F on every cell and the ledger's
  // infiltrated volume is F times the area. An idle soil is off by 100 %; an explicit rate
  // K (1 + S / F) from F = 0 is infinite.
  const double h0 = 0.1;
  for (const double dt : {10.0, 600.0}) {
    auto sim = make_simulation(pond(h0), infiltration_params(dt), target());
    double worst = 0.0, worst_depth = 0.0;
    for (const double t : {60.0, 600.0, 7200.0}) {
      if (t < dt) continue;
      sim.step(std::lround(t / dt) - sim.steps_done());
      const double exact = green_ampt_exact(0.0, sim.time());
      const auto f = sim.field(FieldId::infiltrated);
      const auto d = sim.field(FieldId::water_depth);
      const double e = std::max(std::abs(max_of(f) - exact), std::abs(min_of(f) - exact)) / exact;
      const double ed =
          std::max(std::abs(max_of(d) - (h0 - exact)), std::abs(min_of(d) - (h0 - exact)));
      worst = std::max(worst, e);
      worst_depth = std::max(worst_depth, ed);
      std::printf(
          "[green-ampt ponded] %s dt %.0f s: t %.0f s F %.6e m, exact %.6e m (relative "
          "%.1e, bound 5e-3)\n",
          target().label().c_str(), dt, sim.time(), max_of(f), exact, e);
    }
    const double f_end = green_ampt_exact(0.0, sim.time());
    const auto& L = sim.ledger();
    const double e_ledger = std::abs(L.infiltrated / (16 * kCellArea) - f_end) / f_end;
    const double closure = std::abs(L.relative_closure_error());
    std::printf(
        "[green-ampt ponded] %s dt %.0f s: max |depth - (h0 - F)| %.1e m (bound %.0e), "
        "ledger infiltrated / area vs F %.1e (bound %.0e), water closure %.1e of what "
        "moved (bound %.0e)\n",
        target().label().c_str(), dt, worst_depth, 5e-3 * f_end, e_ledger, 5e-3, closure,
        this->bound(1e-12, 1e-5));
    auto fig = [&](const char* q) {
      return figure("green_ampt_ponded", "green_ampt", q, 2000.0,
                    "F - S ln(1 + F / S) = K_sat t (Green & Ampt 1911)");
    };
    if (dt == 10.0) {
      validation::expect_below(fig("max |F / exact - 1| at 1 min, 10 min, 2 h"), worst, 5e-3);
      validation::expect_below(fig("|infiltrated / area / F - 1|"), e_ledger, 5e-3);
      validation::expect_below(fig("water closure / what moved"), closure,
                               this->bound(1e-12, 1e-5));
    } else {
      EXPECT_LT(worst, 5e-3);
      EXPECT_LT(e_ledger, 5e-3);
      EXPECT_LT(closure, this->bound(1e-12, 1e-5));
    }
    EXPECT_LT(worst_depth, 5e-3 * f_end) << "the depth loses what the soil takes";
  }
}

TEST_P(Infiltration, RainBelowKsatNeverPondsAndAboveItPondsOnTime) {
  // Rain on the dry loam for 1 h in steps of 10 s. At half K_sat no step ends with water on the
  // surface (the soil takes at least K_sat dt a step) and the soil holds all the rain (ledger
  // infiltrated = rain to rounding). At 10 K_sat the surface ponds when F reaches
  // F_p = S K / (r - K) (Mein & Larson 1973): at t_p = F_p / r = 313.7 s; the first step to
  // end with water ends within one step of t_p. After it F follows the ponded relation from
  // (t_p, F_p): F - F_p - S ln((F + S) / (F_p + S)) = K (t - t_p), within 0.5 % at 1 h (the
  // step that ponds takes the ponded rate for its whole length: an error of order dt). An
  // idle soil ponds at once; a soil at the constant rate K_sat ponds at 10 K_sat at once too.
  const double dt = 10.0, hour = 3600.0;
  {
    Params p = infiltration_params(dt);
    p.rain.rate = 0.5 * kKsat;
    auto sim = make_simulation(pond(0.0), p, target());
    double wettest = 0.0;
    for (long k = 0; k < std::lround(hour / dt); ++k) {
      sim.step();
      wettest = std::max(wettest, max_of(sim.field(FieldId::water_depth)));
    }
    const auto& L = sim.ledger();
    const double e = std::abs(L.infiltrated - L.rain) / L.rain;
    std::printf(
        "[green-ampt rain < K] %s: deepest water at a step's end %.1e m (bound 0); "
        "infiltrated %.6e m^3, rain %.6e m^3 (relative %.1e, bound %.0e)\n",
        target().label().c_str(), wettest, L.infiltrated, L.rain, e, this->bound(1e-12, 1e-5));
    EXPECT_EQ(wettest, 0.0) << "rain below K_sat never ponds";
    validation::expect_below(
        figure("green_ampt_rain", "green_ampt", "|infiltrated / rain - 1| (r = K_sat / 2)", 2000.0,
               "all the rain infiltrates below K_sat"),
        e, this->bound(1e-12, 1e-5));
  }
  {
    const double r = 10 * kKsat, fp = kS * kKsat / (r - kKsat), tp = fp / r;
    Params p = infiltration_params(dt);
    p.rain.rate = r;
    auto sim = make_simulation(pond(0.0), p, target());
    double t_ponded = -1.0;
    while (sim.time() < hour - 1e-9) {
      sim.step();
      if (t_ponded < 0 && max_of(sim.field(FieldId::water_depth)) > 0) t_ponded = sim.time();
    }
    const double f_exact = green_ampt_exact(fp, hour - tp);
    const double f = max_of(sim.field(FieldId::infiltrated));
    const double e = std::abs(f - f_exact) / f_exact;
    std::printf(
        "[green-ampt rain > K] %s: first ponded step ends at %.0f s, t_p %.1f s (bound: "
        "within %.0f s after); F(1 h) %.6e m, Mein-Larson %.6e m (relative %.1e, bound "
        "5e-3)\n",
        target().label().c_str(), t_ponded, tp, dt, f, f_exact, e);
    auto fig = [&](const char* q) {
      return figure("green_ampt_rain", "green_ampt", q, 2000.0,
                    "Mein & Larson (1973): F_p = S K / (r - K), then ponded Green-Ampt");
    };
    validation::expect_below(fig("|ponding time - t_p| (s), r = 10 K_sat"), std::abs(t_ponded - tp),
                             dt);
    validation::expect_below(fig("|F / exact - 1| at 1 h, r = 10 K_sat"), e, 5e-3);
    EXPECT_GE(t_ponded, tp) << "no water on the surface before the ponding time";
  }
}

TEST_P(Infiltration, FiniteStoreFillsAndStops) {
  // soil_depth 0.05 m: the store holds L delta theta = 15 mm. Under 0.1 m of water for 2 h
  // (26.2 mm without the limit) F stops at 15 mm and the rest stays on the surface. Bound: the
  // store to rounding (float32: half an ulp of 0.015 summed over the steps that filled it, 1e-6
  // relative). Unlimited, F is off by 59 %; idle, by 100 %.
  const double dt = 60.0, store = 0.05 * kDeficit;
  Params p = infiltration_params(dt);
  p.infiltration.soil_depth = ScalarOrRaster{0.05, {}};
  auto sim = make_simulation(pond(0.1), p, target());
  sim.step(120);
  const auto f = sim.field(FieldId::infiltrated);
  const double e = std::max(std::abs(max_of(f) - store), std::abs(min_of(f) - store)) / store;
  const double e_depth = std::abs(max_of(sim.field(FieldId::water_depth)) - (0.1 - store));
  std::printf(
      "[green-ampt store] %s: F %.6e m, store %.6e m (relative %.1e, bound %.0e); depth "
      "off by %.1e m\n",
      target().label().c_str(), max_of(f), store, e, this->bound(1e-12, 1e-6), e_depth);
  validation::expect_below(figure("green_ampt_store", "green_ampt", "|F / (L delta theta) - 1|",
                                  2000.0, "the store holds L delta theta"),
                           e, this->bound(1e-12, 1e-6));
  EXPECT_LT(e_depth, this->bound(1e-12, 1e-6));
}

TEST_P(Infiltration, RecoveryRestoresThePredictedCapacity) {
  // 10 mm of water on the dry loam soaks in within 1595 s (the ponded relation at F = 10 mm);
  // from the first dry step on, F decays as F e^(-k_r t) with SWMM's k_r = sqrt(K_sat in
  // in/h) / 75 per hour (1.355e-6 1/s for the loam: e-folding in 8.5 days). After 2 days dry F
  // is checked against that closed form (0.5 %), then 50 mm of water is put back and the
  // first step of 60 s takes the Green-Ampt increment from the recovered F (0.5 %): the
  // capacity came back as predicted. Without recovery F stays 10 mm (off by 26 %) and the
  // first step takes about 14 % less.
  const double dt = 60.0, day = 86400.0;
  auto sim = make_simulation(pond(0.01), infiltration_params(dt), target());
  sim.step(60);  // 1 h: soaked in
  ASSERT_EQ(max_of(sim.field(FieldId::water_depth)), 0.0);
  const double f1 = max_of(sim.field(FieldId::infiltrated));
  sim.step(std::lround(2 * day / dt));
  const double k_r = std::sqrt(kKsat * 3600.0 / 0.0254) / 75.0 / 3600.0;
  const double f_exact = f1 * std::exp(-k_r * 2 * day);
  const double f2 = max_of(sim.field(FieldId::infiltrated));
  const double e_recovered = std::abs(f2 - f_exact) / f_exact;

  sim.backend().set_field(FieldId::water_depth, std::vector<double>(sim.grid().cells(), 0.05));
  sim.step();
  const double taken = max_of(sim.field(FieldId::infiltrated)) - f2;
  const double taken_exact = green_ampt_exact(f2, dt) - f2;
  const double e_taken = std::abs(taken - taken_exact) / taken_exact;
  std::printf(
      "[green-ampt recovery] %s: F %.6e m after soaking, %.6e m after 2 d dry, exact "
      "%.6e m (relative %.1e, bound 5e-3); next 60 s take %.6e m, exact %.6e m "
      "(relative %.1e, bound 5e-3)\n",
      target().label().c_str(), f1, f2, f_exact, e_recovered, taken, taken_exact, e_taken);
  auto fig = [&](const char* q) {
    return figure("green_ampt_recovery", "green_ampt", q, 2000.0,
                  "F e^(-k_r t), k_r = sqrt(K_sat [in/h]) / 75 per hour (SWMM)");
  };
  validation::expect_below(fig("|F / exact - 1| after 2 days dry"), e_recovered, 5e-3);
  validation::expect_below(fig("|first step's infiltration / exact - 1| after"), e_taken, 5e-3);
  const auto& L = sim.ledger();
  const double soil = (L.infiltrated - L.soil_drained) / (16 * kCellArea);
  EXPECT_NEAR(soil, f2 + taken, this->bound(1e-12, 1e-6) * f1) << "infiltrated - drained = F";
}

TEST(GreenAmptIncrement, ClosedFormOverTheRangeOfSoilsAndSteps) {
  // green_ampt_increment (infiltration.h) alone, in float32 and float64, against the implicit
  // relation solved here, for K dt / S from 1e-8 to 1e4, F from 0 to 1 m, and the limits: no
  // suction (D = K dt exactly, also from F = 0), no conductivity (D = 0). Bound: 1e-5 relative
  // in float32 (five Newton steps reach rounding; a few ulps of the terms), 1e-12 in float64.
  double worst32 = 0, worst64 = 0;
  int cases = 0;
  for (const double k : {1e-7, 1e-6, 1e-5, 1e-4})
    for (const double s : {1e-4, 1e-3, 0.03, 0.3})
      for (const double f : {0.0, 1e-6, 1e-3, 0.1, 1.0})
        for (const double dt : {0.01, 1.0, 60.0, 3600.0}) {
          const double exact = green_ampt_increment_exact(f, dt, k, s);
          const double d64 = cell::green_ampt_increment<double>(f, k, s, dt);
          const float d32 =
              cell::green_ampt_increment<float>(static_cast<float>(f), static_cast<float>(k),
                                                static_cast<float>(s), static_cast<float>(dt));
          worst64 = std::max(worst64, std::abs(d64 - exact) / exact);
          worst32 = std::max(worst32, std::abs(d32 - exact) / exact);
          ++cases;
        }
  const double no_suction_0 = cell::green_ampt_increment<double>(0.0, 1e-5, 0.0, 60.0);
  const double no_suction_f = cell::green_ampt_increment<double>(0.01, 1e-5, 0.0, 60.0);
  const double no_k = cell::green_ampt_increment<double>(0.01, 0.0, 0.03, 60.0);
  std::printf(
      "[green-ampt increment] %d cases: worst relative error %.1e (float32, bound 1e-5), "
      "%.1e (float64, bound 1e-12); no suction from F = 0: %.6e m, from 1 cm: %.6e m "
      "(K dt = 6e-4 m); no conductivity: %.1e m\n",
      cases, worst32, worst64, no_suction_0, no_suction_f, no_k);
  EXPECT_LT(worst32, 1e-5);
  EXPECT_LT(worst64, 1e-12);
  EXPECT_DOUBLE_EQ(no_suction_0, 6e-4);
  EXPECT_DOUBLE_EQ(no_suction_f, 6e-4);
  EXPECT_EQ(no_k, 0.0);
}

ERODEM_INSTANTIATE_TARGETS(Infiltration);

}  // namespace
}  // namespace erodem::test
