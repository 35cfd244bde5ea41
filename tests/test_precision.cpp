// erodem — float32 against float64 (issue 14, part 1): the eroded and deposited volumes of a
// float32 run, on the CPU reference and on OpenCL, agree with the float64 reference within
// 1 %, on terrain whose relief makes a plain float32 bed lose or bias per-step changes (one
// float32 ulp is 9.8e-4 m at 9000 m); and the ledger's material closure, judged against what
// moved, stays at the rounding of the bed pair. The full-size cases (the Puget Sound main job,
// one hour of storm over all of Big Tujunga) are run by experiments/precision/compare.py;
// these are their fast versions (and cases of the validation report, docs/validation.md).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

#include "common/compensated.h"
#include "erodem/io/setup.hpp"
#include "erodem/terrain_synth.hpp"
#include "scenarios.hpp"
#include "validation_record.hpp"

namespace erodem::test {
namespace {

/// Eroded and deposited volumes (m^3) from the erosion field (initial bed - bed) as a user
/// reads them from a result file: the cells that lost bed, and those that gained it.
struct Volumes {
  double eroded = 0, deposited = 0;
};

Volumes field_volumes(const Simulation& sim) {
  const auto e = sim.field(FieldId::erosion);
  const Grid& g = sim.grid();
  Volumes v;
  for (int r = 0; r < g.ny; ++r)
    for (int c = 0; c < g.nx; ++c) {
      const double x = e[static_cast<std::size_t>(r) * g.nx + c] * g.area[r];
      (x > 0 ? v.eroded : v.deposited) += std::abs(x);
    }
  return v;
}

/// One hour of 50 mm/h rain with erosion at its defaults, conservative transport, thermal
/// collapse, open edges, adaptive steps (dt_max 5 s).
Params storm_params() {
  Params p;
  p.rain.rate = 50.0 / 1000.0 / 3600.0;
  p.time.adaptive = true;
  p.time.duration = 3600.0;
  p.erosion.enabled = true;
  p.erosion.law = ErosionLaw::mei;  // the capacity law these figures were recorded with
  p.thermal.enabled = true;
  p.boundary.north = p.boundary.south = p.boundary.east = p.boundary.west = BoundaryKind::open;
  return p;
}

/// A ridged synthetic terrain of 0 - 9000 m relief, 128 x 128 cells of 200 m.
Terrain high_relief_terrain() {
  Terrain t = flat_terrain(128, 128, 200.0);
  t.bed = generate_terrain(SynthKind::ridged, 128, 128, 200.0, 9000.0, 14);
  return t;
}

/// A 256 x 256 crop of Big Tujunga (30 m, 550 - 2000 m).
Terrain tujunga_crop() {
  Params p;
  p.dem.path = tujunga_path();
  p.dem.window = std::array<int, 4>{420, 180, 256, 256};
  return io::load_terrain(p);
}

struct Outcome {
  Volumes field;
  Ledger ledger;
};

Outcome run_storm(const Terrain& terrain, const Target& target) {
  auto sim = make_simulation(terrain, storm_params(), target);
  while (sim.time() < 3600.0 - 1e-9) sim.step();
  return {field_volumes(sim), sim.ledger()};
}

void compare_precisions(const char* case_id, const char* name, const Terrain& terrain) {
  const Outcome ref = run_storm(terrain, Target{"cpu", Precision::float64});
  // An idle or erosion-free run scores 100 %; the plain float32 bed of erodem before
  // 2026-11-25 scored 2.2 % (Puget Sound) to 26 % (issue 14): 1 % is the target and
  // sits well below what the rounding of a plain bed costs on such relief.
  const double bound = 0.01;
  std::vector<Target> targets{Target{"cpu", Precision::float32}};
  if (opencl_available()) targets.push_back(Target{"opencl", Precision::float32});
  for (const auto& target : targets) {
    const Outcome got = run_storm(terrain, target);
    const double de = got.field.eroded / ref.field.eroded - 1,
                 dd = got.field.deposited / ref.field.deposited - 1;
    const double ge = got.ledger.eroded / ref.ledger.eroded - 1,
                 gd = got.ledger.deposited / ref.ledger.deposited - 1;
    const double closure = got.ledger.relative_material_closure_error();
    std::printf(
        "[precision] %s %s vs cpu_float64: eroded %.6e vs %.6e m^3 (%+.3f %%), deposited "
        "%.6e vs %.6e m^3 (%+.3f %%) (bound 1 %%); gross eroded %+.3f %%, deposited %+.3f %%; "
        "material closure %.3e m^3 = %.2e of %.3e m^3 moved (bound 1e-5; float64 %.2e)\n",
        name, target.label().c_str(), got.field.eroded, ref.field.eroded, 100 * de,
        got.field.deposited, ref.field.deposited, 100 * dd, 100 * ge, 100 * gd,
        got.ledger.material_closure_error(), closure, got.ledger.material_moved(),
        ref.ledger.relative_material_closure_error());
    EXPECT_GT(ref.field.eroded, 0.0) << "the scenario must erode";
    auto fig = [&](const char* quantity) {
      return validation::Figure{
          case_id,  target.label(),     "local_inertial",
          quantity, terrain.grid.dx[0], "the same run in float64 (cpu_float64)"};
    };
    for (auto [quantity, d] : {std::pair{"|eroded volume / float64's - 1|", de},
                               std::pair{"|deposited volume / float64's - 1|", dd}})
      validation::expect_below(fig(quantity), std::abs(d), bound);
    // The bed pair moves material between bed and sediment exactly but for the rounding of
    // the residual (2^-24 ulp(bed) per update) and of the per-cell sums of thermal collapse
    // and transport (an ulp of the moved layer): a few 1e-7 of what moved. A plain float bed
    // scored 1.1e-2 on Puget Sound (5.15e6 of 4.6e8 m^3).
    validation::expect_below(fig("material closure (relative to moved)"), std::abs(closure), 1e-5);
  }
  EXPECT_LT(std::abs(ref.ledger.relative_material_closure_error()), 1e-12);
}

TEST(Precision, Float32ErosionMatchesFloat64OnHighRelief) {
  compare_precisions("precision_ridged", "ridged 0-9000 m", high_relief_terrain());
}

// Until the thin-film fix of issue 14 this was reported only: thin films on steep cells ran at
// about dx/dt, and a change of rounding alone moved the float64 run's eroded volume by 1.8 %
// (float32 was +1.3 % eroded, +1.2 % deposited with the bed pair; +5 % with a plain float32
// bed on the whole tile). With the implicit friction and the rounding-robust face depth
// (docs/model.md 3.3) it agrees to a few hundredths of a percent, and the 1 % holds.
TEST(Precision, Float32ErosionMatchesFloat64OnTujungaCrop) {
  compare_precisions("precision_tujunga", "Big Tujunga 256^2", tujunga_crop());
}

/// The bed pair itself: a million steps of 1e-7 m of erosion on a bed at 9000 m (a plain
/// float32 bed, ulp 9.8e-4 m, keeps none of it): the bed gives exactly what the sediment
/// gains (the sediment, a float32 sum up to 0.1 m, rounds each 1e-7 m add at its own ulp),
/// and a bed pair alone, lowered by the same steps, ends 0.1 m lower to 1e-5 m: each update
/// rounds the residual (|lo| <= ulp(9000 m)/2 = 4.9e-4 m) at most by ulp(lo)/2 = 2.9e-11 m,
/// 2.9e-5 m over a million of them in the worst case; a plain float bed is 0.1 m off.
TEST(Precision, BedPairKeepsChangesBelowHalfAnUlp) {
  float hi = 9000.0f, lo = 0.0f, sed = 0.0f;
  double lost = 0;
  for (int k = 0; k < 1000000; ++k) {
    float s_err, b_err;
    const float m = 1e-7f;
    const float s_new = cell::two_sum<float>(sed, m, &s_err);
    const float h = cell::two_sum<float>(hi, -m, &b_err);
    hi = cell::two_sum<float>(h, (lo + b_err) + s_err, &lo);
    sed = s_new;
    lost += static_cast<double>(m) - static_cast<double>(s_err);
  }
  const double bed_change = 9000.0 - (static_cast<double>(hi) + lo);
  std::printf(
      "[bed pair] 1e6 x 1e-7 m at 9000 m: bed lowered %.9f m, sediment %.9f m, booked %.9f m "
      "(bound |bed - booked| < 1e-9 m; a plain float bed lowers by %.1f m)\n",
      bed_change, static_cast<double>(sed), lost, 9000.0 - static_cast<double>(9000.0f - 1e-7f));
  EXPECT_NEAR(bed_change, lost, 1e-9);
  EXPECT_NEAR(static_cast<double>(sed), lost, 1e-9 + 1e-7 * lost);
  float alone_hi = 9000.0f, alone_lo = 0.0f;
  for (int k = 0; k < 1000000; ++k)
    alone_hi = cell::bed_add<float>(alone_hi, alone_lo, -1e-7f, &alone_lo);
  const double alone = 9000.0 - (static_cast<double>(alone_hi) + alone_lo);
  const double exact = 1e6 * static_cast<double>(1e-7f);
  std::printf("[bed pair] the bed alone lowered %.9f m, exact %.9f m (bound 1e-5 m)\n", alone,
              exact);
  EXPECT_NEAR(alone, exact, 1e-5);
}

}  // namespace
}  // namespace erodem::test
