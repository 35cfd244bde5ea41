// erodem — periodic east-west edges (boundary.periodic_x) and the polar rows of lat/lon grids
// (boundary.latitude_cap): water crossing the seam, conserved; the cyclic shift of the grid
// giving the cyclically shifted run bit for bit (the seam is computed as any face inside);
// OpenCL against the CPU reference; a global GeoTIFF with a repeated column; the cap's walls
// and time step; the config errors; a restart across the seam.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "erodem/backends.hpp"
#include "erodem/boundary_codes.hpp"
#include "erodem/error.hpp"
#include "erodem/io/compare.hpp"
#include "erodem/io/raster.hpp"
#include "erodem/io/setup.hpp"
#include "erodem/process.hpp"
#include "erodem/schema.hpp"
#include "erodem/simulation.hpp"
#include "scenarios.hpp"
#include "temp_dir.hpp"

namespace erodem::test {
namespace {

constexpr int kNx = 40, kNy = 12;
constexpr double kCell = 10.0, kLevel = 0.2;  // m: cell size, still water level

/// One configuration of the seam tests.
struct SeamCase {
  std::string name;
  FlowScheme flow;
  bool erosion = false;  ///< erosion, conservative transport and thermal collapse too
  int order = 1;
  TransportScheme transport = TransportScheme::conservative;
  /// whether the shifted run is the shifted result bit for bit: not semi-Lagrangian
  /// transport, whose departure point x - u dt / dx rounds with the column's index x (its
  /// bound: the shifted run within 1e-4 of each field's largest value)
  bool bitwise = true;
  /// a snow pack that slides (two generic passes: shares, then moves) and melts, and
  /// Green-Ampt infiltration
  bool snow = false;
};

/// A channel along x between walls north and south, joined east to west: a wavy bed (periodic
/// in x), still water at 0.2 m and a 0.5 m hump on it centred on column `centre`.
Terrain seam_terrain(double centre) {
  Terrain t = flat_terrain(kNx, kNy, kCell);
  t.water_depth.assign(t.grid.cells(), 0.0);
  const double pi = 3.14159265358979323846;
  for (int r = 0; r < kNy; ++r)
    for (int c = 0; c < kNx; ++c) {
      const auto i = static_cast<std::size_t>(r) * kNx + c;
      // cyclic distance (cells) to the hump's centre
      double dist = std::fabs(c - centre);
      dist = std::min(dist, kNx - dist);
      t.bed[i] = 0.05 * std::sin(2 * pi * c / kNx) + 0.02 * std::cos(2 * pi * 3 * c / kNx) +
                 0.01 * std::sin(2 * pi * r / kNy);
      t.water_depth[i] = kLevel + 0.5 * std::exp(-dist * dist / 8.0) - t.bed[i];
    }
  return t;
}

/// The terrain with every raster shifted k columns east, cyclically.
Terrain shifted(const Terrain& t, int k) {
  Terrain s = t;
  const int nx = t.grid.nx;
  for (int r = 0; r < t.grid.ny; ++r)
    for (int c = 0; c < nx; ++c) {
      const auto from = static_cast<std::size_t>(r) * nx + c;
      const auto to = static_cast<std::size_t>(r) * nx + (c + k) % nx;
      s.bed[to] = t.bed[from];
      s.water_depth[to] = t.water_depth[from];
    }
  return s;
}

Params seam_params(const SeamCase& c) {
  Params p = quiet_params(c.flow, 0.2);
  p.flow.manning_n.value = 0.03;
  p.flow.order = c.order;
  p.boundary.periodic_x = true;
  p.erosion.enabled = c.erosion;
  p.transport.scheme = c.transport;
  if (c.snow) {
    p.snow.enabled = true;
    p.snow.initial.value = 0.05;
    p.snow.slide_angle = 0.02;  // degrees: the wavy bed's flanks slide
    p.snow.slide_rate = 0.01;
    p.snow.air_temperature = 2.0;
    p.snow.melt_factor = 5e-3 / 3600.0;
    p.infiltration.enabled = true;
    p.infiltration.ksat.value = 1e-5;
  }
  p.thermal.enabled = c.erosion;
  if (c.erosion) {
    p.erosion.law = ErosionLaw::mei;
    p.erosion.sediment_capacity = 0.5;
    p.thermal.talus_angle = 0.03;  // the wavy bed's flanks (about 0.05 degrees) collapse
  }
  return p;
}

class Seam : public ::testing::TestWithParam<SeamCase> {};

// (a) The hump spreads both ways; the half that leaves east enters west. Against the same run
// with closed east and west edges (where the west columns only see what reflects), the west
// columns gain water: an idle solver, or one that drops what leaves, fails that. The water is
// conserved to rounding (nothing leaves: the ledger's boundary outflow is 0, the seam's faces
// count none), and the run of the grid shifted k columns is the shifted run, bit for bit:
// every face across the seam is computed as the face inside it that it becomes after the
// shift.
TEST_P(Seam, WaterCrossesTheSeamConservedAndShiftInvariant) {
  const SeamCase& c = GetParam();
  const Params params = seam_params(c);
  const Terrain terrain = seam_terrain(kNx - 3);
  const Target cpu{"cpu", Precision::float32};
  Simulation sim = make_simulation(terrain, params, cpu);
  Params closed = params;
  closed.boundary.periodic_x = false;
  Simulation walls = make_simulation(terrain, closed, cpu);
  const double water0 = sim.ledger().water_initial;
  const int steps = 150;
  sim.step(steps);
  walls.step(steps);
  const auto& L = sim.ledger();
  // west columns 0..2: the water the hump sent across the seam
  auto west = [&](const Simulation& s) {
    const auto d = s.field(FieldId::water_depth);
    double v = 0.0;
    for (int r = 0; r < kNy; ++r)
      for (int col = 0; col < 3; ++col) v += d[static_cast<std::size_t>(r) * kNx + col];
    return v * kCell * kCell;
  };
  std::printf(
      "[periodic] %s: water %.9g -> %.9g m^3 (closure %.3e of the water moved), boundary out "
      "%.3g m^3; west columns 0-2 hold %.6g m^3 joined, %.6g m^3 with walls\n",
      c.name.c_str(), water0, L.water, L.relative_closure_error(), L.boundary_out, west(sim),
      west(walls));
  EXPECT_EQ(L.boundary_out, 0.0);
  if (c.snow) {
    // melt runs in and infiltration drains out: the ledger's closure, and both happened
    const auto snow = sim.field(FieldId::snow);
    const auto [lo, hi] = std::minmax_element(snow.begin(), snow.end());
    std::printf(
        "[periodic] %s: snow melted %.6g m^3, infiltrated %.6g m^3, the pack from %.6g "
        "to %.6g m (it slid: uniform melt leaves it uniform)\n",
        c.name.c_str(), L.snow_melted, L.infiltrated, *lo, *hi);
    EXPECT_GT(*hi - *lo, 1e-4);
    EXPECT_LT(std::fabs(L.relative_closure_error()), 1e-5);
    EXPECT_GT(L.snow_melted, 0.0);
    EXPECT_GT(L.infiltrated, 0.0);
  } else {
    EXPECT_LT(std::fabs(L.water - water0), 1e-6 * water0);
  }
  EXPECT_GT(west(sim), west(walls) + 1.0) << "no water crossed the seam";
  if (c.erosion) {
    EXPECT_LT(std::fabs(L.relative_material_closure_error()), 1e-5);
    EXPECT_GT(L.eroded + L.thermal_moved, 0.0);
  }

  // the run on the grid shifted 17 columns east
  const int k = 17;
  Simulation moved = make_simulation(shifted(terrain, k), params, cpu);
  moved.step(steps);
  std::vector<FieldId> ids{FieldId::water_depth, FieldId::velocity_x, FieldId::velocity_y,
                           FieldId::flux_left,   FieldId::flux_right, FieldId::flux_top,
                           FieldId::flux_bottom};
  if (c.erosion)
    for (FieldId id : {FieldId::bed, FieldId::sediment}) ids.push_back(id);
  if (c.snow)
    for (FieldId id : {FieldId::snow, FieldId::snow_liquid, FieldId::infiltrated})
      ids.push_back(id);
  for (FieldId id : ids) {
    const auto a = sim.field(id), b = moved.field(id);
    long differ = 0;
    double largest = 0.0, scale = 0.0;
    for (int r = 0; r < kNy; ++r)
      for (int col = 0; col < kNx; ++col) {
        const auto i = static_cast<std::size_t>(r) * kNx + col;
        const auto j = static_cast<std::size_t>(r) * kNx + (col + k) % kNx;
        differ += a[i] != b[j];
        largest = std::max(largest, std::fabs(a[i] - b[j]));
        scale = std::max(scale, std::fabs(a[i]));
      }
    if (c.bitwise) {
      EXPECT_EQ(differ, 0) << field_info(id).name << ": cells differing from the shifted run";
    } else {
      std::printf(
          "[periodic] %s %-11s shifted run: %ld cells differ, by at most %.3g (%.2g of "
          "the largest value; bound 1e-4)\n",
          c.name.c_str(), field_info(id).name, differ, largest, largest / scale);
      EXPECT_LE(largest, 1e-4 * scale) << field_info(id).name;
    }
  }
  // (the ledger sums the cells in row order: the shifted grid's sum rounds in another order)
  EXPECT_NEAR(moved.ledger().water, L.water, (c.bitwise ? 1e-12 : 1e-6) * L.water);
}

INSTANTIATE_TEST_SUITE_P(
    Schemes, Seam,
    ::testing::Values(SeamCase{"pipes", FlowScheme::pipes},
                      SeamCase{"local_inertial", FlowScheme::local_inertial},
                      SeamCase{"local_inertial_erosion", FlowScheme::local_inertial, true},
                      SeamCase{"local_inertial_semi_lagrangian", FlowScheme::local_inertial, true,
                               1, TransportScheme::semi_lagrangian, false},
                      SeamCase{"pipes_snow_infiltration", FlowScheme::pipes, false, 1,
                               TransportScheme::conservative, true, true},
                      SeamCase{"shallow_water", FlowScheme::shallow_water},
                      SeamCase{"shallow_water_order2", FlowScheme::shallow_water, false, 2}),
    [](const auto& i) { return i.param.name; });

// A hump centred on the seam (between the last column and the first) on a flat bed spreads
// symmetrically: the result mirrors across the seam (column c against column nx - 1 - c) to
// float64 rounding. A seam that delayed, damped or reflected the water on one side would break
// the mirror by the size of the hump's change (checked: it moved, > 1 mm at the seam).
TEST(Periodic, HumpOnTheSeamStaysSymmetric) {
  Terrain t = flat_terrain(kNx, kNy, kCell);
  t.water_depth.assign(t.grid.cells(), 0.0);
  for (int r = 0; r < kNy; ++r)
    for (int c = 0; c < kNx; ++c) {
      const double dist = std::min(c + 0.5, kNx - c - 0.5);  // to the seam
      t.water_depth[static_cast<std::size_t>(r) * kNx + c] =
          kLevel + 0.5 * std::exp(-dist * dist / 8.0);
    }
  for (FlowScheme scheme : {FlowScheme::pipes, FlowScheme::local_inertial}) {
    Params p = seam_params({"", scheme});
    Simulation sim = make_simulation(t, p, {"cpu", Precision::float64});
    sim.step(100);
    const auto d = sim.field(FieldId::water_depth);
    double worst = 0.0;
    for (int r = 0; r < kNy; ++r)
      for (int c = 0; c < kNx / 2; ++c) {
        const auto i = static_cast<std::size_t>(r) * kNx;
        worst = std::max(worst, std::fabs(d[i + c] - d[i + kNx - 1 - c]));
      }
    const double moved = std::fabs(d[0] - t.water_depth[0]);
    std::printf(
        "[periodic] %s: seam hump, largest mirror difference %.3g m, the seam cell moved "
        "%.4g m\n",
        scheme_name(scheme), worst, moved);
    EXPECT_GT(moved, 1e-3);
    EXPECT_LT(worst, 1e-12);
  }
}

// (b) The OpenCL backend runs the same seam: the project's agreement bound (relative L2 of every
// field 1e-5, test_agreement.cpp) after 150 steps, and the ledger's boundary outflow 0.
TEST(Periodic, OpenClMatchesCpu) {
  if (!opencl_available()) GTEST_SKIP() << "no OpenCL device";
  for (const SeamCase& c :
       {SeamCase{"pipes", FlowScheme::pipes},
        SeamCase{"local_inertial_erosion", FlowScheme::local_inertial, true},
        SeamCase{"local_inertial_semi_lagrangian", FlowScheme::local_inertial, true, 1,
                 TransportScheme::semi_lagrangian},
        SeamCase{"pipes_snow_infiltration", FlowScheme::pipes, false, 1,
                 TransportScheme::conservative, true, true},
        SeamCase{"shallow_water_order2", FlowScheme::shallow_water, false, 2}}) {
    const Params params = seam_params(c);
    const Terrain terrain = seam_terrain(kNx - 3);
    Simulation cpu = make_simulation(terrain, params, {"cpu", Precision::float32});
    Simulation ocl = make_simulation(terrain, params, {"opencl", Precision::float32});
    cpu.step(150);
    ocl.step(150);
    for (FieldId id :
         {FieldId::water_depth, FieldId::velocity_x, FieldId::flux_left, FieldId::flux_right,
          FieldId::bed, FieldId::sediment, FieldId::snow, FieldId::infiltrated}) {
      const auto diff = io::field_difference(ocl.field(id), cpu.field(id), kNx);
      std::printf("[periodic] %s %-11s opencl against cpu: relative L2 %.3e (bound 1e-5)\n",
                  c.name.c_str(), field_info(id).name, diff.rel_l2);
      EXPECT_LT(diff.rel_l2, 1e-5) << c.name << " " << field_info(id).name;
    }
    EXPECT_EQ(ocl.ledger().boundary_out, 0.0);
    EXPECT_NEAR(ocl.ledger().water, cpu.ledger().water, 1e-6 * cpu.ledger().water);
  }
}

// (f) A run restored from its state halfway continues as the uninterrupted one, bit for bit,
// with the halo of every field rebuilt from the DEM cells (set_field).
TEST(Periodic, RestartIsBitExact) {
  const Params params = seam_params({"", FlowScheme::local_inertial, true});
  const Terrain terrain = seam_terrain(kNx - 3);
  for (const char* backend : {"cpu", "opencl"}) {
    if (std::string(backend) == "opencl" && !opencl_available()) continue;
    const Target target{backend, Precision::float32};
    Simulation whole = make_simulation(terrain, params, target);
    whole.step(60);
    const RestartPoint half = whole.restart_point();
    whole.step(60);
    Simulation resumed = make_simulation(terrain, params, target);
    resumed.restore(half);
    resumed.step(60);
    for (FieldId id : {FieldId::water_depth, FieldId::bed, FieldId::sediment, FieldId::flux_left,
                       FieldId::velocity_x})
      EXPECT_EQ(resumed.field(id), whole.field(id)) << backend << " " << field_info(id).name;
    EXPECT_EQ(resumed.ledger().water, whole.ledger().water) << backend;
  }
}

// The halo exchange's list (process.hpp halo_fields): what a sweep writes or leaves, never the
// grid inputs.
TEST(Periodic, HaloFieldsAreWhatASweepWrites) {
  Params p;
  p.thermal.enabled = true;
  p.flow.scheme = FlowScheme::local_inertial;
  for (const auto& [process, sweep] : step_sweeps(p)) {
    const auto fields = halo_fields(sweep);
    if (std::string(sweep.name) == "thermal_share") {
      EXPECT_EQ(fields, std::vector<std::string>{"thermal_share"});
    }
    if (std::string(sweep.name) == "water_update") {
      EXPECT_EQ(fields, (std::vector<std::string>{"water_depth", "velocity_x", "velocity_y",
                                                  "depth_flow"}));
    }
    for (const auto& f : fields) EXPECT_NE(f, "kind");
  }
}

// What the halo exchanges (process.hpp neighbour_read_fields, halo_fields(sweep, needed)): the
// fields a sweep reads at a neighbour, and no other. The lists follow from the process table's
// accesses; a field missing here that a sweep reads at a neighbour would make the MPI bands
// and the periodic seam differ from the whole grid (tests/mpi.sh, this file's agreement tests),
// a field present that none reads only costs bytes.
TEST(Periodic, HaloExchangesOnlyWhatIsReadAtANeighbour) {
  auto has = [](const std::vector<std::string>& v, const char* f) {
    return std::find(v.begin(), v.end(), f) != v.end();
  };
  Params p;
  p.flow.scheme = FlowScheme::local_inertial;
  p.erosion.enabled = true;
  p.thermal.enabled = true;
  const auto needed = neighbour_read_fields(p);
  for (const char* f : {"bed", "water_depth", "flux_left", "flux_right", "flux_top", "flux_bottom",
                        "manning_n", "sediment", "depth_flow", "thermal_share", "wetness"})
    EXPECT_TRUE(has(needed, f)) << f;
  for (const char* f :
       {"kind", "velocity_x", "velocity_y", "bed_residual", "soil_thickness", "hardness"})
    EXPECT_FALSE(has(needed, f)) << f;
  for (const auto& [process, sweep] : step_sweeps(p)) {
    const auto fields = halo_fields(sweep, needed);
    if (std::string(sweep.name) == "water_update") {
      EXPECT_EQ(fields, (std::vector<std::string>{"water_depth", "depth_flow"}));
    }
    if (std::string(sweep.name) == "erosion_physical") {
      EXPECT_EQ(fields, (std::vector<std::string>{"bed", "sediment"}));
    }
    if (std::string(sweep.name) == "thermal_apply") {
      EXPECT_EQ(fields, std::vector<std::string>{"bed"});
    }
  }
  // water only, pipes: no sediment moves, no Manning n at the faces
  Params w;
  w.flow.scheme = FlowScheme::pipes;
  const auto water = neighbour_read_fields(w);
  EXPECT_FALSE(has(water, "sediment"));
  EXPECT_FALSE(has(water, "manning_n"));
  EXPECT_FALSE(has(water, "depth_flow"));
  EXPECT_TRUE(has(water, "flux_left"));
  // a section's faces read the far cell's outflows, sediment and flow depth
  w.section.push_back({"across", {{{0.0, 5.0}}, {{100.0, 5.0}}}});
  const auto with_section = neighbour_read_fields(w);
  EXPECT_TRUE(has(with_section, "sediment"));
  EXPECT_TRUE(has(with_section, "depth_flow"));
}

// What an MPI band need not receive (process.hpp exact_in_band): fields of whose halo rows no
// later read needs more than the band computes itself. The lists pin the data flow's result
// for the default configuration and its variants, so that a change of the process table that
// sends more or fewer fields shows here; whether the skipped fields' reads see the neighbour's
// values is tests/mpi.sh's part (every Mpi* scenario the serial run's bits at N = 1..4;
// docs/mpi.md "Halo rows computed exactly" has the mutations that fail it).
TEST(Periodic, BandsSkipTheExchangesNoReadNeeds) {
  using List = std::vector<std::string>;
  // sweep name -> {fields sent to the neighbouring bands, fields skipped}, after each sweep
  auto lists = [](const Params& p, int halo) {
    std::map<std::string, std::pair<List, List>> out;
    const auto tails = sweeps_tails(p, true, halo);
    for (const Process proc : step_sequence(p)) {
      const SweepsTail& t = tails.at(static_cast<std::size_t>(proc));
      for (std::size_t k = 0; k < t.sweeps.size(); ++k) {
        const List unsent = halo > 0 ? t.unsent.at(k) : List{};
        List sent;
        for (const auto& f : t.exchange[k])
          if (std::find(unsent.begin(), unsent.end(), f) == unsent.end()) sent.push_back(f);
        out[t.sweeps[k].name] = {sent, unsent};
      }
    }
    return out;
  };
  Params p;  // local inertial (a halo of 2 rows), the physical erosion law, transport, thermal
  p.flow.scheme = FlowScheme::local_inertial;
  p.erosion.enabled = true;
  p.thermal.enabled = true;
  auto l = lists(p, 2);
  // The ghost columns are filled on every row of the band, from their own row; the bed and the
  // depth are sent once, before the faces read them two rows away, and the sediment's halo no
  // read needs before erosion writes it.
  EXPECT_EQ(l["boundary_fill"], std::make_pair(List{"bed", "water_depth"}, List{"sediment"}));
  EXPECT_EQ(l["flow_local_inertial"].first,
            (List{"flux_left", "flux_right", "flux_top", "flux_bottom"}));
  // The depth the water update leaves is read next by the boundary (its own row) and by
  // erosion and evaporation (their own cell), until the boundary's exchange; the depth it
  // started from (depth_flow, exact on the halo row next to the own rows as that depth was) by
  // the transport one row away.
  EXPECT_EQ(l["water_update"], std::make_pair(List{}, List{"water_depth", "depth_flow"}));
  // Erosion computes its halo row from a sediment the transport left exact on no halo row
  // (the transport reads depth_flow one row away, exact on one): the transport and thermal
  // collapse, which read one row away, need the bed and the sediment sent.
  EXPECT_EQ(l["erosion_physical"], std::make_pair(List{"bed", "sediment"}, List{}));
  EXPECT_EQ(l["transport_conservative"], std::make_pair(List{}, List{"sediment"}));
  EXPECT_EQ(l["thermal_apply"], std::make_pair(List{}, List{"bed"}));
  // the wetness is computed on the halo row next to the own rows (rows 1 .. H - 2), and thermal
  // collapse reads it one row away
  EXPECT_EQ(l["evaporation"], std::make_pair(List{}, List{"wetness"}));
  std::size_t sent = 0, skipped = 0;
  for (const auto& [name, s] : l) {
    sent += s.first.size();
    skipped += s.second.size();
  }
  std::printf(
      "[band exchange] local inertial + erosion + thermal, halo 2: %zu fields sent a "
      "step, %zu skipped (and thermal's shares between its passes)\n",
      sent, skipped);
  EXPECT_EQ(sent, 8u);
  EXPECT_EQ(skipped, 6u);

  // outside a band (boundary.periodic_x alone): nothing skipped
  for (const auto& [name, s] : lists(p, 0)) EXPECT_TRUE(s.second.empty()) << name;

  // a section's faces read the far cell's outflows, sediment and flow depth one row away
  // before the water update and the transport, as those do themselves: the same lists
  Params with_section = p;
  with_section.section.push_back({"across", {{{0.0, 5.0}}, {{100.0, 5.0}}}});
  EXPECT_EQ(lists(with_section, 2), l);

  // pipes, a halo of 1 row: no cells sweep computes a halo row, so the wetness is sent, and
  // the bed after thermal collapse (a band of one row: an open ghost row reads its halo row)
  Params pipes = p;
  pipes.flow.scheme = FlowScheme::pipes;
  auto lp = lists(pipes, 1);
  EXPECT_EQ(lp["evaporation"], std::make_pair(List{"wetness"}, List{}));
  EXPECT_EQ(lp["thermal_apply"], std::make_pair(List{"bed"}, List{}));
  EXPECT_EQ(lp["boundary_fill"], std::make_pair(List{"bed", "water_depth"}, List{"sediment"}));

  // terrain classes (a process a step may skip) read the bed at the neighbours first in the
  // step: thermal collapse, the bed's last writer in the step before, sends it
  Params classes = p;
  classes.terrain_classes.enabled = true;
  classes.evaporation.rate = 1e-4;
  auto lc = lists(classes, 2);
  EXPECT_EQ(lc["thermal_apply"], std::make_pair(List{"bed"}, List{}));
  EXPECT_EQ(lc["terrain_class"].first, List{"manning_n"});
}

// ---- lat/lon grids ----------------------------------------------------------------------

const char* kWgs84 =
    "GEOGCS[\"WGS 84\",DATUM[\"WGS_1984\",SPHEROID[\"WGS 84\",6378137,298.257223563]],"
    "PRIMEM[\"Greenwich\",0],UNIT[\"degree\",0.0174532925199433],AUTHORITY[\"EPSG\",\"4326\"]]";

/// A global GeoTIFF of 10-degree cells, columns from -185 (centres -180 .. 180: the last
/// repeats the first) or from -180 (36 columns), rows from 90 north to 90 south; the bed a
/// smooth function of the cell centre's longitude, so the repeated column repeats it exactly.
std::string write_global(const TempDir& dir, bool repeated) {
  Grid g;
  g.nx = repeated ? 37 : 36;
  g.ny = 18;
  g.georef.transform = {repeated ? -185.0 : -180.0, 10.0, 0.0, 90.0, 0.0, -10.0};
  g.georef.crs_wkt = kWgs84;
  g.georef.has_transform = true;
  g.georef.is_geographic = true;
  g.dx.assign(18, 1.0);
  g.dy.assign(18, 1.0);
  g.area.assign(18, 1.0);
  std::vector<double> z(g.cells());
  const double pi = 3.14159265358979323846;
  for (int r = 0; r < g.ny; ++r)
    for (int c = 0; c < g.nx; ++c)
      z[static_cast<std::size_t>(r) * g.nx + c] =
          100.0 + 50.0 * std::cos(g.cell_center(c, r)[0] * pi / 180.0) + r;
  const std::string path = dir.file(repeated ? "global_37.tif" : "global_36.tif");
  io::write_geotiff(path, g, std::vector<float>(z.begin(), z.end()), "global", -9999.0);
  return path;
}

Params global_params(const std::string& path) {
  Params p = quiet_params(FlowScheme::local_inertial, 60.0);
  p.dem.path = path;
  p.time.adaptive = true;
  p.time.dt_max = 1e7;
  p.initial.water_depth.value = 1.0;
  return p;
}

bool has(const std::vector<std::string>& lines, const std::string& text) {
  for (const auto& l : lines)
    if (l.find(text) != std::string::npos) return true;
  return false;
}

// (c) A grid spanning 360 degrees is periodic by default, with a note; its repeated column
// (+180 after -180) is dropped with a note; boundary.periodic_x = false keeps the edges apart.
TEST(Periodic, GlobalGridJoinsItsEdgesAndDropsTheRepeatedColumn) {
  TempDir dir;
  for (bool repeated : {true, false}) {
    const Params p = global_params(write_global(dir, repeated));
    const Terrain t = io::load_terrain(p);
    EXPECT_EQ(t.grid.nx, 36);
    EXPECT_TRUE(spans_360(t.grid));
    EXPECT_EQ(has(t.notes, "repeats the first"), repeated);
    EXPECT_TRUE(periodic_x(t, p));
    const Simulation sim = io::make_simulation(p, "cpu");
    for (const auto& n : sim.setup_notes()) std::printf("[periodic] note: %s\n", n.c_str());
    EXPECT_TRUE(has(sim.setup_notes(), "the east and west edges are joined"));
    EXPECT_TRUE(has(sim.setup_notes(), "spans 360 degrees"));
    Params off = p;
    off.boundary.periodic_x = false;
    EXPECT_FALSE(periodic_x(t, off));
    EXPECT_FALSE(has(io::make_simulation(off, "cpu").setup_notes(), "joined"));
  }
  // A grid of less than 360 degrees is joined only when asked, and the note says it is not
  // a 360-degree grid.
  const Terrain strip = flat_terrain(8, 4, 10.0);
  Params asked = quiet_params(FlowScheme::pipes, 1.0);
  EXPECT_FALSE(periodic_x(strip, asked));
  asked.boundary.periodic_x = true;
  Simulation sim = make_simulation(strip, asked, {"cpu", Precision::float32});
  EXPECT_TRUE(has(sim.setup_notes(), "not a lat/lon grid spanning 360 degrees"));
}

// (d) Near the poles the cells narrow (10-degree cells: dx at 85 degrees is 0.087 of dx at 5
// degrees) and the setup warns with the latitude, dx and the time step limits; with
// boundary.latitude_cap = 60 the rows poleward of 60 degrees are walls, the warning goes, and
// the adaptive time step rises by the ratio of the narrowest active rows' dx (55 against 85
// degrees: about 6.6, to 1%).
TEST(Periodic, LatitudeCapMasksThePolarRowsAndRaisesTheStep) {
  TempDir dir;
  const Params p = global_params(write_global(dir, false));
  const Simulation open = io::make_simulation(p, "cpu");
  for (const auto& w : open.setup_warnings()) std::printf("[periodic] warning: %s\n", w.c_str());
  ASSERT_TRUE(has(open.setup_warnings(), "latitude 85 degrees"));
  EXPECT_TRUE(has(open.setup_warnings(), "boundary.latitude_cap"));
  Params capped_params = p;
  capped_params.boundary.latitude_cap = 60.0;
  const Simulation capped = io::make_simulation(capped_params, "cpu");
  const Terrain& t = capped.terrain();
  int walls = 0;
  for (int r = 0; r < t.grid.ny; ++r) {
    const bool polar = std::fabs(t.grid.cell_center(0, r)[1]) > 60.0;
    for (int c = 0; c < t.grid.nx; ++c)
      EXPECT_EQ(t.active(static_cast<std::size_t>(r) * t.grid.nx + c), !polar) << r << " " << c;
    walls += polar;
  }
  EXPECT_EQ(walls, 6);  // 85, 75, 65 north and south
  EXPECT_TRUE(has(capped.setup_notes(), "the 6 rows poleward of it are walls"));
  EXPECT_TRUE(capped.setup_warnings().empty());
  const double ratio = capped.next_dt() / open.next_dt();
  const double expected = t.grid.dx[3] / t.grid.dx[0];  // rows at 55 and 85 degrees
  std::printf("[periodic] latitude cap 60: dt %.4g s against %.4g s, ratio %.4f (dx ratio %.4f)\n",
              capped.next_dt(), open.next_dt(), ratio, expected);
  EXPECT_NEAR(ratio, expected, 0.01 * expected);
  EXPECT_GT(ratio, 5.0);
}

// (e) The config errors: one line, exit 78, naming the key.
TEST(Periodic, ConfigErrorsNameTheKey) {
  auto fails = [](const std::function<void()>& f, const std::string& key) {
    try {
      f();
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ExitCode::config) << e.what();
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
      return;
    }
    ADD_FAILURE() << "no error for " << key;
  };
  Params base;
  base.dem.synthetic = "ridged";
  auto with = [&](const std::string& setting) {
    Params p = base;
    apply_setting(p, setting);
    validate(p, "test");
  };
  fails([&] { with("boundary.east=periodic"); }, "boundary.west");
  fails([&] { with("boundary.west=periodic"); }, "boundary.east");
  fails([&] { with("boundary.north=periodic"); }, "boundary.north");
  fails([&] { with("boundary.latitude_cap=95"); }, "boundary.latitude_cap");
  fails([&] { with("boundary.latitude_cap=0"); }, "boundary.latitude_cap");
  fails([&] { with("boundary.periodic_x=3"); }, "boundary.periodic_x");
  fails(
      [&] {
        Params p = base;
        p.boundary.east = p.boundary.west = BoundaryKind::periodic;
        p.boundary.periodic_x = false;
        validate(p, "test");
      },
      "boundary.periodic_x");
  // both periodic: valid, and joined
  Params both = base;
  both.boundary.east = both.boundary.west = BoundaryKind::periodic;
  validate(both, "test");
  EXPECT_TRUE(periodic_x(flat_terrain(4, 4, 1.0), both));
  // a cap on a projected grid
  fails(
      [&] {
        Terrain t = flat_terrain(4, 4, 1.0);
        Params p = base;
        p.boundary.latitude_cap = 80.0;
        apply_latitude_cap(t, p);
      },
      "boundary.latitude_cap");
}

}  // namespace
}  // namespace erodem::test
