// erodem — terrain classes (kernels/common/terrain_class.h, model.md section 3.12): the class
// rule against an independent evaluation of it, the recomputation interval, and the class
// tables driving the physics against closed forms: Green-Ampt infiltration with each class's
// soil, and slope collapse to each class's talus angle. On every target; each test prints the
// measured figure beside its bound. A solver that never classifies, or classifies and ignores
// the tables, fails each of them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "erodem/error.hpp"
#include "erodem/schema.hpp"
#include "scenarios.hpp"
#include "target_test.hpp"
#include "validation_record.hpp"

namespace erodem::test {
namespace {

class TerrainClasses : public TargetTest {};

enum Code { kGrass = 0, kMud = 1, kRock = 2, kSnow = 3, kWater = 4 };

/// The test's own evaluation of the rule of model.md section 3.12 (not the kernel's code): the
/// slope by central differences over the grid's cells (one-sided at the edges; the test
/// terrains have no nodata), then the first of snow, water, rock, mud that holds, else grass.
std::vector<int> expected_classes(const Terrain& t, const std::vector<double>& wetness,
                                  const std::vector<double>& snow, const Params& p) {
  const int nx = t.grid.nx, ny = t.grid.ny;
  const auto& tc = p.terrain_classes;
  std::vector<int> out(t.bed.size());
  for (int r = 0; r < ny; ++r)
    for (int c = 0; c < nx; ++c) {
      const auto z = [&](int cc, int rr) { return t.bed[static_cast<std::size_t>(rr) * nx + cc]; };
      const int c0 = std::max(c - 1, 0), c1 = std::min(c + 1, nx - 1);
      const int r0 = std::max(r - 1, 0), r1 = std::min(r + 1, ny - 1);
      const double gx = (z(c1, r) - z(c0, r)) / ((c1 - c0) * t.grid.dx[0]);
      const double gy = (z(c, r1) - z(c, r0)) / ((r1 - r0) * t.grid.dy[0]);
      const double slope = std::sqrt(gx * gx + gy * gy);
      const std::size_t i = static_cast<std::size_t>(r) * nx + c;
      const double b = t.bed[i];
      int k = kGrass;
      if (snow[i] > tc.snow_depth || (tc.snow_line && b > *tc.snow_line))
        k = kSnow;
      else if (wetness[i] > tc.water_wetness)
        k = kWater;
      else if (slope > tc.rock_slope && (!tc.rock_elevation || b > *tc.rock_elevation))
        k = kRock;
      else if (wetness[i] > tc.mud_wetness)
        k = kMud;
      out[i] = k;
    }
  return out;
}

/// A 12 x 8 tile of 100 m cells: flat at 0 m west of column 6, a ramp rising 100 m per cell
/// (slope 1) from there; snow on rows 0-1 of the flat part, water-wet rows 2-3 and mud-wet
/// rows 4-5 (wetness 0.5 m and 0.05 m), rows 6-7 dry. With the rule's thresholds below every
/// class appears, each far from its thresholds (no tie decides a cell).
struct RuleTile {
  Terrain terrain = flat_terrain(12, 8, 100.0);
  std::vector<double> wetness, snow;
  RuleTile() {
    wetness.assign(terrain.grid.cells(), 0.0);
    snow.assign(terrain.grid.cells(), 0.0);
    for (int r = 0; r < 8; ++r)
      for (int c = 0; c < 12; ++c) {
        const std::size_t i = static_cast<std::size_t>(r) * 12 + c;
        terrain.bed[i] = c >= 6 ? (c - 5) * 100.0 : 0.0;
        if (r <= 1 && c < 4) snow[i] = 0.05;
        if (r == 2 || r == 3) wetness[i] = 0.5;
        if (r == 4 || r == 5) wetness[i] = 0.05;
      }
  }
};

Params rule_params() {
  Params p = quiet_params(FlowScheme::local_inertial, 1.0);
  auto& tc = p.terrain_classes;
  tc.enabled = true;
  tc.interval = 3;
  tc.snow_depth = 0.01;
  tc.snow_line = 450.0;  // columns 10, 11 (500 m, 600 m)
  tc.water_wetness = 0.3;
  tc.rock_slope = 0.7;
  tc.rock_elevation = 150.0;  // not column 6 (100 m), although its slope is 1
  tc.mud_wetness = 0.01;
  // the tables: Manning n by class, K_sat by class (infiltration on, no water: it takes none)
  tc.grass.manning_n = 0.04;
  tc.mud.manning_n = 0.05;
  tc.rock.manning_n = 0.025;
  tc.snow.manning_n = 0.02;
  // water keeps flow.manning_n
  p.flow.manning_n.value = 0.03;
  p.infiltration.enabled = true;
  tc.grass.ksat = 1e-5;
  tc.mud.ksat = 1e-7;
  return p;
}

std::vector<int> codes(const std::vector<double>& field) {
  std::vector<int> out;
  for (double v : field) out.push_back(static_cast<int>(std::lround(v)));
  return out;
}

TEST_P(TerrainClasses, RuleMatchesAnIndependentEvaluationAndTheTablesFillTheFields) {
  // One step classifies the tile (the first step of a run classifies); the class of every cell
  // must equal the test's own evaluation of the rule exactly (codes, no tolerance: every cell
  // is far from its thresholds), all five classes must appear, and the Manning n and K_sat
  // fields must hold each class's table value (flow.manning_n for water, which gives none;
  // infiltration.ksat for the classes without a K_sat), to the precision's rounding. An idle
  // pass leaves every cell grass (0) and the fields uniform.
  const RuleTile tile;
  const Params p = rule_params();
  auto sim = make_simulation(tile.terrain, p, target());
  // the initial state is classified when the simulation is built (the first snapshot shows
  // its classes): dry, no pack, so grass, rock and the snow line's cells
  const std::vector<double> none(tile.terrain.grid.cells(), 0.0);
  const auto initial = codes(sim.field(FieldId::terrain_class));
  const auto initial_want = expected_classes(tile.terrain, none, none, p);
  std::size_t initial_wrong = 0;
  for (std::size_t i = 0; i < initial.size(); ++i) initial_wrong += initial[i] != initial_want[i];
  EXPECT_EQ(initial_wrong, 0u) << "the classes of the initial state";
  sim.backend().set_field(FieldId::wetness, tile.wetness);
  sim.backend().set_field(FieldId::snow, tile.snow);
  sim.step();
  const auto got = codes(sim.field(FieldId::terrain_class));
  const auto want = expected_classes(tile.terrain, tile.wetness, tile.snow, p);
  std::size_t wrong = 0;
  std::vector<int> count(5, 0);
  for (std::size_t i = 0; i < got.size(); ++i) {
    wrong += got[i] != want[i];
    if (want[i] >= 0 && want[i] < 5) ++count[static_cast<std::size_t>(want[i])];
  }
  const auto& tc = p.terrain_classes;
  const double n_of[5] = {*tc.grass.manning_n, *tc.mud.manning_n, *tc.rock.manning_n,
                          *tc.snow.manning_n, p.flow.manning_n.value};
  const double k_of[5] = {*tc.grass.ksat, *tc.mud.ksat, p.infiltration.ksat.value,
                          p.infiltration.ksat.value, p.infiltration.ksat.value};
  const auto n = sim.field(FieldId::manning_n);
  const auto k = sim.field(FieldId::infiltration_ksat);
  double e_n = 0.0, e_k = 0.0;
  for (std::size_t i = 0; i < n.size(); ++i) {
    e_n = std::max(e_n, std::abs(n[i] - n_of[want[i]]) / n_of[want[i]]);
    e_k = std::max(e_k, std::abs(k[i] - k_of[want[i]]) / k_of[want[i]]);
  }
  const double bound = this->bound(1e-15, 1e-7);  // one rounding of the table's value
  std::printf(
      "[terrain classes rule] %s: initially %zu, after the first step %zu of %zu cells off the "
      "rule (bound 0); cells by class "
      "grass %d mud %d rock %d snow %d water %d; max relative |n - table| %.1e, |K_sat - table| "
      "%.1e (bound %.0e)\n",
      target().label().c_str(), initial_wrong, wrong, got.size(), count[0], count[1], count[2],
      count[3], count[4], e_n, e_k, bound);
  EXPECT_EQ(wrong, 0u);
  for (int c = 0; c < 5; ++c) EXPECT_GT(count[static_cast<std::size_t>(c)], 0) << "class " << c;
  auto fig = [&](const char* q) {
    return figure("terrain_class_rule", "terrain_classes", q, 100.0,
                  "the rule evaluated independently");
  };
  validation::expect_below(fig("cells off the rule"), static_cast<double>(wrong), 0.5);
  validation::expect_below(fig("max relative |manning_n - class table|"), e_n, bound);
  validation::expect_below(fig("max relative |K_sat - class table|"), e_k, bound);
}

TEST_P(TerrainClasses, ClassesFollowTheStateEveryIntervalStepsOnly) {
  // interval = 3: steps 0, 3, 6 ... classify. A pack put on a grass cell after the first step
  // leaves it grass through steps 1 and 2 and makes it snow at step 3; its Manning n follows.
  // A pass that classified every step would make it snow at step 1; one that never
  // reclassified, never.
  const RuleTile tile;
  const Params p = rule_params();
  auto sim = make_simulation(tile.terrain, p, target());
  sim.step();
  const std::size_t cell = 7 * 12 + 2;  // row 7, column 2: dry, flat, grass
  ASSERT_EQ(codes(sim.field(FieldId::terrain_class))[cell], kGrass);
  std::vector<double> snow(tile.terrain.grid.cells(), 0.0);
  snow[cell] = 0.05;
  sim.backend().set_field(FieldId::snow, snow);
  std::vector<int> seen;
  for (int s = 1; s <= 4; ++s) {
    sim.step();
    seen.push_back(codes(sim.field(FieldId::terrain_class))[cell]);
  }
  const double n = sim.field(FieldId::manning_n)[cell];
  std::printf(
      "[terrain classes interval] %s: class after steps 1..4: %d %d %d %d (expected 0 0 "
      "3 3); Manning n then %.4g (snow's 0.02)\n",
      target().label().c_str(), seen[0], seen[1], seen[2], seen[3], n);
  EXPECT_EQ(seen, (std::vector<int>{kGrass, kGrass, kSnow, kSnow}));
  EXPECT_NEAR(n, 0.02, 1e-8);
}

TEST_P(TerrainClasses, EachClassInfiltratesWithItsOwnGreenAmptSoil) {
  // A flat tile ponded 0.5 m deep for 2 h (steps of 10 s): the wet half (wetness 0.05 m when
  // the first step classifies: mud) has a clay-like soil, K_sat 1e-7 m/s, psi 0.3 m, delta
  // theta 0.4; the dry half (grass) keeps the uniform loam (K_sat 0.34 cm/h, psi 0.0889 m,
  // delta theta 0.3). Classes are fixed after the first step (interval 10^9). Each class's
  // infiltrated depth must follow the implicit Green-Ampt closed form of its own soil within
  // 0.5 % (the infiltration issue's bound; the scheme's error here is 1e-4 of F, at
  // rounding in float32). Without the class table the mud cells would take the loam's F,
  // 1.75 times theirs: off by 75 %.
  const double dt = 10.0, t_end = 7200.0, depth0 = 0.5;
  Terrain t = flat_terrain(8, 4, 500.0);
  t.water_depth.assign(t.grid.cells(), depth0);
  Params p = quiet_params(FlowScheme::local_inertial, dt);
  p.flow.manning_n.value = 0.03;
  p.time.duration = t_end;
  p.infiltration.enabled = true;
  const double k_loam = 0.34e-2 / 3600.0, s_loam = 0.0889 * 0.3;
  p.infiltration.ksat.value = k_loam;
  p.infiltration.suction.value = 0.0889;
  p.infiltration.moisture_deficit.value = 0.3;
  auto& tc = p.terrain_classes;
  tc.enabled = true;
  tc.interval = 1000000000;
  tc.mud.ksat = 1e-7;
  tc.mud.suction = 0.3;
  tc.mud.moisture_deficit = 0.4;
  const double k_mud = 1e-7, s_mud = 0.3 * 0.4;
  std::vector<double> wet(t.grid.cells(), 0.0);
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) wet[static_cast<std::size_t>(r) * 8 + c] = 0.05;
  auto sim = make_simulation(t, p, target());
  sim.backend().set_field(FieldId::wetness, wet);
  sim.step(std::lround(t_end / dt));
  const double f_mud = green_ampt_increment_exact(0.0, t_end, k_mud, s_mud);
  const double f_loam = green_ampt_increment_exact(0.0, t_end, k_loam, s_loam);
  const auto f = sim.field(FieldId::infiltrated);
  const auto cls = codes(sim.field(FieldId::terrain_class));
  double e_mud = 0.0, e_loam = 0.0;
  int n_mud = 0, n_grass = 0;
  for (std::size_t i = 0; i < f.size(); ++i) {
    if (cls[i] == kMud) {
      ++n_mud;
      e_mud = std::max(e_mud, std::abs(f[i] - f_mud) / f_mud);
    } else if (cls[i] == kGrass) {
      ++n_grass;
      e_loam = std::max(e_loam, std::abs(f[i] - f_loam) / f_loam);
    }
  }
  const auto depth = sim.field(FieldId::water_depth);
  const double min_depth = *std::min_element(depth.begin(), depth.end());
  std::printf(
      "[terrain classes infiltration] %s: %d mud cells, max |F - F_GA(clay)| / F_GA %.2e "
      "(F_GA %.4f m); %d grass cells, max |F - F_GA(loam)| / F_GA %.2e (F_GA %.4f m); bound "
      "5e-3; least depth %.3f m (ponded throughout)\n",
      target().label().c_str(), n_mud, e_mud, f_mud, n_grass, e_loam, f_loam, min_depth);
  EXPECT_EQ(n_mud, 16);
  EXPECT_EQ(n_grass, 16);
  EXPECT_GT(min_depth, 0.0) << "the closed form is the ponded one";
  auto fig = [&](const char* q) {
    return figure("terrain_class_infiltration", "green_ampt", q, 500.0,
                  "implicit Green-Ampt F(t) of each class's soil");
  };
  validation::expect_below(fig("max |F - F_GA| / F_GA, mud (clay table)"), e_mud, 5e-3);
  validation::expect_below(fig("max |F - F_GA| / F_GA, grass (uniform loam)"), e_loam, 5e-3);
}

TEST_P(TerrainClasses, EachClassCollapsesToItsOwnTalusAngle) {
  // A ramp along x of 40 cells of 1 m (3 rows), rising 2 m per cell (63 degrees): the cells
  // above 40 m are snow (terrain_classes.snow_line) with a talus angle of 20 degrees, the rest
  // grass at 45 degrees; classes fixed after the first step. Slope collapse (K_t dt = 1,
  // 3000 steps) relaxes every drop a cell gives across to its own class's talus slope: the
  // largest drop out of a snow cell must lie within 1 % of tan 20 degrees = 0.364 m, out of a
  // grass cell within 1 % of tan 45 degrees = 1 m. Material is conserved (to rounding). With
  // one talus angle for all, the snow cells would stand at 1 m (off by 175 %); an idle pass,
  // at 2 m.
  const int n = 40;
  Terrain t = flat_terrain(n, 3, 1.0);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < n; ++c) t.bed[static_cast<std::size_t>(r) * n + c] = 2.0 * c;
  Params p = quiet_params(FlowScheme::local_inertial, 1.0);
  p.thermal.enabled = true;
  p.thermal.rate = 1.0;
  p.thermal.talus_angle = 45.0;
  auto& tc = p.terrain_classes;
  tc.enabled = true;
  tc.interval = 1000000000;
  tc.rock_slope = 100.0;  // no rock: the ramp's cells are snow or grass
  tc.snow_line = 40.0;
  tc.snow.talus_angle = 20.0;
  auto sim = make_simulation(t, p, target());
  const double material0 = sim.diagnostics().material_volume;
  sim.step(3000);
  const auto bed = sim.field(FieldId::bed);
  const auto cls = codes(sim.field(FieldId::terrain_class));
  double drop_snow = 0.0, drop_grass = 0.0;
  int n_snow = 0;
  for (int c = 0; c < n; ++c) {
    const std::size_t i = static_cast<std::size_t>(n) + c;  // the middle row
    double out = 0.0;
    if (c > 0) out = std::max(out, bed[i] - bed[i - 1]);
    if (c + 1 < n) out = std::max(out, bed[i] - bed[i + 1]);
    if (cls[i] == kSnow) {
      ++n_snow;
      drop_snow = std::max(drop_snow, out);
    } else {
      drop_grass = std::max(drop_grass, out);
    }
  }
  const double tan_snow = std::tan(20.0 * M_PI / 180.0), tan_grass = 1.0;
  const double e_snow = std::abs(drop_snow - tan_snow) / tan_snow;
  const double e_grass = std::abs(drop_grass - tan_grass) / tan_grass;
  const double e_material =
      std::abs(sim.diagnostics().material_volume - material0) / std::max(material0, 1.0);
  std::printf(
      "[terrain classes talus] %s: %d snow cells, largest drop %.4f m (tan 20 = %.4f, off "
      "%.2e); grass largest drop %.4f m (tan 45 = 1, off %.2e); bound 1e-2; material change "
      "%.1e of the total\n",
      target().label().c_str(), n_snow, drop_snow, tan_snow, e_snow, drop_grass, e_grass,
      e_material);
  EXPECT_GT(n_snow, 5);
  auto fig = [&](const char* q) {
    return figure("terrain_class_talus", "thermal", q, 1.0,
                  "the talus slope of each class's table");
  };
  validation::expect_below(fig("|largest drop - tan 20| / tan 20, snow"), e_snow, 1e-2);
  validation::expect_below(fig("|largest drop - tan 45| / tan 45, grass"), e_grass, 1e-2);
  EXPECT_LT(e_material, this->bound(1e-12, 1e-6));
}

TEST_P(TerrainClasses, ARasterOverridesTheClassTable) {
  // flow.manning_n given as a raster (here put on the terrain as load_terrain would): the
  // class tables' Manning n must leave it as it is, cell for cell; the K_sat table still
  // applies (no K_sat raster).
  const RuleTile tile;
  Params p = rule_params();
  Terrain t = tile.terrain;
  t.manning_n.assign(t.grid.cells(), 0.0);
  for (std::size_t i = 0; i < t.manning_n.size(); ++i) t.manning_n[i] = 0.01 + 1e-4 * i;
  p.flow.manning_n.path = "manning.tif";
  auto sim = make_simulation(t, p, target());
  sim.backend().set_field(FieldId::wetness, tile.wetness);
  sim.step();
  const auto n = sim.field(FieldId::manning_n);
  double e = 0.0;
  for (std::size_t i = 0; i < n.size(); ++i)
    e = std::max(e, std::abs(n[i] - t.manning_n[i]) / t.manning_n[i]);
  const auto k = sim.field(FieldId::infiltration_ksat);
  const auto cls = codes(sim.field(FieldId::terrain_class));
  double e_k = 0.0;
  for (std::size_t i = 0; i < k.size(); ++i)
    if (cls[i] == kMud) e_k = std::max(e_k, std::abs(k[i] - 1e-7) / 1e-7);
  std::printf(
      "[terrain classes raster] %s: max relative |n - raster| %.1e, mud |K_sat - table| "
      "%.1e (bound %.0e)\n",
      target().label().c_str(), e, e_k, this->bound(1e-15, 1e-7));
  EXPECT_LT(e, this->bound(1e-15, 1e-7));
  EXPECT_LT(e_k, this->bound(1e-15, 1e-7));
}

ERODEM_INSTANTIATE_TARGETS(TerrainClasses);

TEST(TerrainClassesConfig, ClassValuesNeedTheClassesAndSoilsComeOneWay) {
  // A class's parameter without terrain_classes.enabled, and a class soil beside a soil
  // raster, are configuration errors naming the key.
  Params p = rule_params();
  p.dem.synthetic = "hill";
  p.terrain_classes.enabled = false;
  try {
    validate(p, "test.toml");
    ADD_FAILURE() << "class values without the classes were accepted";
  } catch (const Error& e) {
    std::printf("[terrain classes config] %s\n", e.what());
    EXPECT_EQ(e.code(), ExitCode::config);
    EXPECT_NE(std::string(e.what()).find("terrain_classes.grass"), std::string::npos) << e.what();
  }
  p = rule_params();
  p.dem.synthetic = "hill";
  p.terrain_classes.mud.suction = 0.2;
  p.infiltration.moisture_deficit.path = "deficit.tif";
  try {
    validate(p, "test.toml");
    ADD_FAILURE() << "a class suction beside a moisture-deficit raster was accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ExitCode::config);
    EXPECT_NE(std::string(e.what()).find("terrain_classes.mud"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace erodem::test
