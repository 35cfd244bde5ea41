// erodem — fused sweeps (process.hpp step_passes, Backend::run_pass): the CPU reference's
// pass of flow + sources + water (CpuBackend::run_flow_water) gives the bits of the three
// processes run one after the other, for local inertial and pipes, float32 and float64, with
// rain, a line inflow, a cross-section, erosion, transport and thermal collapse around it,
// and thread counts that cut the grid into blocks of every size the pass treats differently
// (blocks of 2 to 3 rows, where every row waits for the other blocks, up to one block).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ostream>
#include <random>
#include <string>
#include <vector>

#include "common/flow.h"
#include "erodem/backends.hpp"
#include "erodem/process.hpp"
#include "erodem/simulation.hpp"
#include "scenarios.hpp"

namespace erodem::test {
namespace {

constexpr int kNx = 37, kNy = 29;  // odd sizes: blocks of unequal rows
constexpr double kCell = 5.0;

/// A tilted, wavy valley with a pond: wet and dry cells, flow in every direction.
Terrain valley() {
  Terrain t = flat_terrain(kNx, kNy, kCell);
  t.water_depth.assign(t.grid.cells(), 0.0);
  for (int r = 0; r < kNy; ++r)
    for (int c = 0; c < kNx; ++c) {
      const auto i = static_cast<std::size_t>(r) * kNx + c;
      const double across = (c - 0.5 * kNx) / kNx;
      t.bed[i] =
          2.0 + 0.05 * r + 3.0 * across * across + 0.2 * std::sin(0.7 * c) * std::cos(0.5 * r);
      const double pond = 2.4 - t.bed[i];
      if (r > 8 && r < 16 && pond > 0) t.water_depth[i] = pond;
    }
  return t;
}

/// `steps` fixed steps of the flow scheme (0.05 s for the pipes, 0.2 s for local inertial),
/// Manning n 0.03, rain of 1e-4 m/s.
Params rain_params(FlowScheme flow, int steps) {
  Params p;
  p.flow.scheme = flow;
  p.flow.manning_n.value = 0.03;
  p.time.adaptive = false;
  p.time.dt = flow == FlowScheme::pipes ? 0.05 : 0.2;
  p.time.duration = steps * p.time.dt;
  p.rain.rate = 1e-4;  // m/s
  return p;
}

/// The valley's run: rain, an inflow along three cells, a section across the valley, open
/// edges, erosion + conservative transport + thermal collapse + evaporation.
Params valley_params(FlowScheme flow, Precision precision, int threads, bool fused, bool erosion) {
  Params p = rain_params(flow, 40);
  InflowSpec in;
  const double y = (kNy - 5 - 0.5) * kCell;  // row 5
  in.vertices = {{10.5 * kCell, y}, {12.5 * kCell, y}};
  in.hydrograph = {{0.0, 0.5}};
  in.sediment_concentration = 0.01;
  p.inflow = {in};
  p.section.push_back(SectionSpec{"across", {{0.0, 14.0 * kCell}, {kNx * kCell, 14.0 * kCell}}});
  p.erosion.enabled = erosion;
  p.erosion.law = ErosionLaw::mei;
  p.thermal.enabled = erosion;
  p.thermal.talus_angle = 20.0;
  p.evaporation.rate = 1e-7;
  p.boundary.north = p.boundary.south = p.boundary.east = p.boundary.west = BoundaryKind::open;
  p.numerics.precision = precision;
  p.numerics.threads = threads;
  p.numerics.fused_sweeps = fused;
  return p;
}

struct FusedCase {
  FlowScheme flow;
  Precision precision;
  int threads;
  /// erosion, transport and thermal collapse on: the pass is flow + sources + water; off (the
  /// water-only step): evaporation joins it and it takes the step's statistics
  bool erosion = true;
};

std::string case_name(const testing::TestParamInfo<FusedCase>& info) {
  const FusedCase& c = info.param;
  return std::string(c.flow == FlowScheme::pipes ? "pipes" : "local_inertial") +
         (c.precision == Precision::float64 ? "_float64" : "_float32") + "_threads" +
         std::to_string(c.threads) + (c.erosion ? "" : "_water_only");
}

void PrintTo(const FusedCase& c, std::ostream* os) {
  *os << case_name({c, 0});
}

class Fused : public testing::TestWithParam<FusedCase> {};

/// Puts an environment variable back as the test found it (set to its old value, or unset).
class RestoreEnv {
 public:
  explicit RestoreEnv(const char* name) : name_(name) {
    const char* v = std::getenv(name);
    had_ = v != nullptr;
    old_ = v ? v : "";
  }
  RestoreEnv(const RestoreEnv&) = delete;
  RestoreEnv& operator=(const RestoreEnv&) = delete;
  ~RestoreEnv() {
    if (had_)
      setenv(name_.c_str(), old_.c_str(), 1);
    else
      unsetenv(name_.c_str());
  }

 private:
  std::string name_, old_;
  bool had_ = false;
};

/// The number of values of `a` and `b` whose bits differ.
std::size_t differing(const std::vector<double>& a, const std::vector<double>& b) {
  std::size_t n = a.size() == b.size() ? 0 : 1 + a.size() + b.size();
  for (std::size_t i = 0; i < a.size() && i < b.size(); ++i)
    n += std::memcmp(&a[i], &b[i], sizeof(double)) != 0;
  return n;
}

/// The values of every field and the ledger entries whose bits differ between two runs, each
/// reported as a test failure.
struct Differences {
  std::size_t fields = 0, ledger = 0;
};
Differences compare_runs(Simulation& a, Simulation& b) {
  Differences d;
  for (const auto& f : field_table()) {
    const std::size_t n = differing(a.field(f.id), b.field(f.id));
    d.fields += n;
    EXPECT_EQ(n, 0u) << "field " << f.name;
  }
  for (const auto& e : ledger_entries()) {
    const double x = a.ledger().*e.member, y = b.ledger().*e.member;
    const bool differs = std::memcmp(&x, &y, sizeof(double)) != 0;
    d.ledger += differs;
    EXPECT_FALSE(differs) << "ledger " << e.name << ": " << x << " " << y;
  }
  return d;
}

TEST_P(Fused, FlowSourcesWaterInOnePassGiveTheSameBits) {
  const FusedCase c = GetParam();
  const Target target{"cpu", c.precision};
  auto fused = make_simulation(
      valley(), valley_params(c.flow, c.precision, c.threads, true, c.erosion), target);
  auto apart = make_simulation(
      valley(), valley_params(c.flow, c.precision, c.threads, false, c.erosion), target);
  // the fused pass is the one that runs (not the fallback through run())
  const auto passes = fused.passes();
  int fused_passes = 0;
  std::size_t fused_length = 0;
  for (const auto& pass : passes)
    for (const auto& part : fused.backend().fused_parts(pass))
      if (part.size() > 1) ++fused_passes, fused_length = part.size();
  ASSERT_EQ(fused_passes, 1);
  EXPECT_EQ(fused_length, c.erosion ? 3u : 4u);  // flow, sources, water (+ evaporation)
  ASSERT_EQ(apart.passes().size(), apart.sequence().size());
  fused.run();
  apart.run();
  ASSERT_EQ(fused.steps_done(), 40);
  ASSERT_EQ(apart.steps_done(), 40);

  // Bound: 0 values differ. The fused pass calls the same cell functions on the same inputs;
  // any row run out of order (its sources before a neighbour block's flow read its depth, its
  // water update before its neighbours' sources) changes depths there by a step's rain at
  // least, and the test fails. The state must also have moved (a pass that did nothing would
  // leave both runs alike only if neither did anything).
  const auto [total, ledger] = compare_runs(fused, apart);
  const auto depth = fused.field(FieldId::water_depth);
  const auto start = valley().water_depth;
  std::size_t moved = 0;
  for (std::size_t i = 0; i < depth.size(); ++i) moved += depth[i] != start[i];
  EXPECT_GT(moved, depth.size() / 2) << "the run left the depths as they were";
  // the statistics of the last step (the fused water-only pass takes them row by row)
  const FieldStats sa = fused.last_stats(), sb = apart.last_stats();
  EXPECT_EQ(std::memcmp(&sa.water_volume, &sb.water_volume, sizeof(double)), 0);
  EXPECT_EQ(std::memcmp(&sa.max_depth, &sb.max_depth, sizeof(double)), 0);
  EXPECT_EQ(std::memcmp(&sa.max_speed, &sb.max_speed, sizeof(double)), 0);
  EXPECT_EQ(sa.max_depth_cell, sb.max_depth_cell);
  EXPECT_EQ(sa.max_speed_cell, sb.max_speed_cell);
  EXPECT_EQ(sa.bad_cell, sb.bad_cell);
  ASSERT_EQ(fused.sections().size(), 1u);
  const double qa = fused.sections()[0].volume, qb = apart.sections()[0].volume;
  EXPECT_EQ(std::memcmp(&qa, &qb, sizeof(double)), 0) << qa << " " << qb;
  EXPECT_NE(qa, 0.0);
  std::printf(
      "[fused] %s: %zu of %zu field values differ, %zu ledger entries differ (bound 0); %zu of "
      "%zu depths moved; section volume %.9g m^3\n",
      case_name({c, 0}).c_str(), total, field_table().size() * depth.size(), ledger, moved,
      depth.size(), qa);
}

INSTANTIATE_TEST_SUITE_P(
    Cpu, Fused,
    testing::Values(FusedCase{FlowScheme::local_inertial, Precision::float32, 1},
                    FusedCase{FlowScheme::local_inertial, Precision::float32, 2},
                    FusedCase{FlowScheme::local_inertial, Precision::float32, 5},
                    FusedCase{FlowScheme::local_inertial, Precision::float32, 13},
                    FusedCase{FlowScheme::local_inertial, Precision::float64, 3},
                    FusedCase{FlowScheme::pipes, Precision::float32, 2},
                    FusedCase{FlowScheme::pipes, Precision::float32, 13},
                    FusedCase{FlowScheme::pipes, Precision::float64, 5},
                    FusedCase{FlowScheme::local_inertial, Precision::float32, 2, false},
                    FusedCase{FlowScheme::local_inertial, Precision::float32, 5, false},
                    FusedCase{FlowScheme::local_inertial, Precision::float64, 13, false},
                    FusedCase{FlowScheme::pipes, Precision::float32, 3, false}),
    case_name);

// The OpenCL backend runs the water update and erosion as one kernel (fused.cl,
// OpenClBackend::run_water_erosion) where erosion follows the water update. Fused or not, the
// same bits: every field, the ledger, the last statistics and the section, for both flow
// schemes and both erosion laws (each its own fused kernel). Bound: 0 differing values. The
// kernel runs the two processes' per-cell functions on the same numbers; erosion reading the
// depth the update started from instead of the new one, or the velocities of the step before,
// changes the bed and the sediment wherever water moves, and the test fails (checked: with
// the old depth in the fused kernels 320 and 2227 values differ under Mei's law, local
// inertial and pipes, 294 and 2141 under the physical law).
TEST(FusedOpenCl, WaterUpdateAndErosionInOneKernelGiveTheSameBits) {
  if (!opencl_available()) GTEST_SKIP() << "no OpenCL device";
  const Target target{"opencl", Precision::float32};
  for (const FlowScheme flow : {FlowScheme::local_inertial, FlowScheme::pipes})
    for (const ErosionLaw law : {ErosionLaw::mei, ErosionLaw::physical}) {
      Params pf = valley_params(flow, Precision::float32, 2, true, true);
      pf.erosion.law = law;
      // fine grains that the valley's slow water moves (the default threshold takes none
      // in the local-inertial run's 40 steps)
      pf.erosion.grain_size = 0.1e-3;
      pf.erosion.critical_shields = 0.001;
      pf.erosion.min_depth = 0.05;  // Mei's capacity reads the depth only through this ramp
      Params pa = pf;
      pa.numerics.fused_sweeps = false;
      auto fused = make_simulation(valley(), pf, target);
      auto apart = make_simulation(valley(), pa, target);
      int fused_parts = 0;
      for (const auto& pass : fused.passes())
        for (const auto& part : fused.backend().fused_parts(pass))
          if (part.size() > 1) {
            ++fused_parts;
            EXPECT_EQ(part, (std::vector<Process>{Process::water, Process::erosion}));
          }
      ASSERT_EQ(fused_parts, 1) << "the fused kernel is the one that runs";
      for (const auto& pass : apart.passes()) ASSERT_FALSE(apart.backend().fuses(pass));
      fused.run();
      apart.run();
      ASSERT_EQ(fused.steps_done(), 40);
      ASSERT_EQ(apart.steps_done(), 40);
      const auto [total, ledger] = compare_runs(fused, apart);
      const double eroded = fused.ledger().eroded, deposited = fused.ledger().deposited;
      EXPECT_GT(eroded + std::abs(deposited), 0.0)
          << "no erosion or deposition: the test would not see erosion's inputs";
      const FieldStats sa = fused.last_stats(), sb = apart.last_stats();
      EXPECT_EQ(std::memcmp(&sa.water_volume, &sb.water_volume, sizeof(double)), 0);
      EXPECT_EQ(std::memcmp(&sa.material_volume, &sb.material_volume, sizeof(double)), 0);
      EXPECT_EQ(std::memcmp(&sa.max_speed, &sb.max_speed, sizeof(double)), 0);
      const double qa = fused.sections()[0].volume, qb = apart.sections()[0].volume;
      EXPECT_EQ(std::memcmp(&qa, &qb, sizeof(double)), 0) << qa << " " << qb;
      std::printf(
          "[fused] OpenCL %s, %s law: water + erosion in one kernel: %zu field values differ, "
          "%zu ledger entries differ (bound 0); eroded %.6g m^3, deposited %.6g m^3\n",
          flow == FlowScheme::pipes ? "pipes" : "local inertial",
          law == ErosionLaw::physical ? "physical" : "Mei's", total, ledger, eroded, deposited);
    }
}

// The OpenCL step's reads (the statistics' rows, the tallies, the transport's change, the
// sections' faces) land in page-locked host memory on a GPU and are copied from there
// (read_batch, ERODEM_OPENCL_PINNED; performance.md). The same run with and without it must
// give the same bits in every field, the ledger, the statistics and the section's volumes:
// they are the same device values read another way. Bound: 0 differing values; a read copied
// from the wrong place in the staging area, or not copied, changes the ledger and the step's
// statistics, and so (adaptive dt aside) the section's volumes and the probes.
TEST(OpenClReads, PinnedStagingGivesTheSameBits) {
  if (!opencl_available()) GTEST_SKIP() << "no OpenCL device";
  const Target target{"opencl", Precision::float32};
  const RestoreEnv restore("ERODEM_OPENCL_PINNED");
  // probes on three cells (one on the section's row), read in the step's batch too
  const std::vector<std::int64_t> cells = {5 * kNx + 11, 14 * kNx + 7, (kNy - 2) * kNx + 3};
  const std::vector<FieldId> fields = {FieldId::water_depth, FieldId::velocity_x, FieldId::bed};
  for (const FlowScheme flow : {FlowScheme::local_inertial, FlowScheme::pipes}) {
    const Params p = valley_params(flow, Precision::float32, 2, true, true);
    setenv("ERODEM_OPENCL_PINNED", "1", 1);
    auto pinned = make_simulation(valley(), p, target);
    setenv("ERODEM_OPENCL_PINNED", "0", 1);
    auto pageable = make_simulation(valley(), p, target);
    // the staging is taken in the one and not in the other
    ASSERT_NE(pinned.backend().device().find("(page-locked reads)"), std::string::npos)
        << pinned.backend().device();
    ASSERT_EQ(pageable.backend().device().find("page-locked"), std::string::npos);
    pinned.set_probes(cells, fields);
    pageable.set_probes(cells, fields);
    pinned.run();
    pageable.run();
    ASSERT_EQ(pinned.steps_done(), 40);
    const auto [total, ledger] = compare_runs(pinned, pageable);
    EXPECT_GT(pinned.ledger().boundary_out, 0.0) << "no outflow: the tallies would be idle";
    EXPECT_NE(pinned.ledger().eroded, 0.0) << "no erosion: its tallies would be idle";
    const FieldStats sa = pinned.last_stats(), sb = pageable.last_stats();
    EXPECT_EQ(std::memcmp(&sa.water_volume, &sb.water_volume, sizeof(double)), 0);
    EXPECT_EQ(std::memcmp(&sa.material_volume, &sb.material_volume, sizeof(double)), 0);
    EXPECT_EQ(std::memcmp(&sa.max_speed, &sb.max_speed, sizeof(double)), 0);
    EXPECT_EQ(sa.max_depth_cell, sb.max_depth_cell);
    const double qa = pinned.sections()[0].volume, qb = pageable.sections()[0].volume;
    EXPECT_NE(qa, 0.0) << "no water through the section: its faces would be idle";
    EXPECT_EQ(std::memcmp(&qa, &qb, sizeof(double)), 0) << qa << " " << qb;
    // the probes: as the other path read them, and as the fields hold them
    ASSERT_NE(pinned.probes(), nullptr);
    ASSERT_NE(pageable.probes(), nullptr);
    const std::vector<double>& pa = *pinned.probes();
    const std::vector<double>& pb = *pageable.probes();
    ASSERT_EQ(pa.size(), cells.size() * fields.size());
    ASSERT_EQ(pb.size(), pa.size());
    std::size_t probes_differ = 0, probes_wet = 0;
    for (std::size_t f = 0; f < fields.size(); ++f) {
      const auto field = pinned.field(fields[f]);
      for (std::size_t c = 0; c < cells.size(); ++c) {
        const std::size_t k = f * cells.size() + c;
        probes_differ += std::memcmp(&pa[k], &pb[k], sizeof(double)) != 0;
        EXPECT_EQ(pa[k], static_cast<double>(field[static_cast<std::size_t>(cells[c])]))
            << "probe " << k;
        probes_wet += fields[f] == FieldId::water_depth && pa[k] > 0.0;
      }
    }
    EXPECT_EQ(probes_differ, 0u);
    EXPECT_GT(probes_wet, 0u) << "every probe dry: the probes would not tell a misread";
    std::printf(
        "[opencl reads] %s: page-locked staging against reads into pageable memory: %zu field "
        "values differ, %zu ledger entries differ, %zu of %zu probe values differ (bound 0); "
        "water out %.6g m^3, through the section %.6g m^3, max depth %.6g m\n",
        flow == FlowScheme::pipes ? "pipes" : "local inertial", total, ledger, probes_differ,
        pa.size(), pinned.ledger().boundary_out, qa, sa.max_depth);
  }
}

// Local inertial and pipes write the new outflows over the old ones (flow.cpp): a block of
// rows takes the unit discharges it needs of its neighbours' rows before a barrier. Blocks
// of every size, down to one row (31 threads for the 31 padded rows) and empty ones (40),
// give the bits of one thread, fused or not. Bound: 0 differing values; a unit discharge
// read after the neighbouring block wrote its row changes that face's discharge, and the
// depths and outflows beside it, from the next step on.
// The CPU loops that write a field over itself (the local-inertial and pipes outflows, flow.cpp;
// the bed by erosion and thermal collapse, the sediment by conservative transport,
// rows_in_place) give every thread count the bits of one thread: each block of rows takes or
// keeps what its neighbours' rows need of its own before a barrier.
TEST(InPlace, EveryBlockSizeGivesTheBitsOfOneThread) {
  const Target target{"cpu", Precision::float32};
  for (const FlowScheme flow : {FlowScheme::local_inertial, FlowScheme::pipes})
    for (const bool fused : {false, true}) {
      auto one = make_simulation(valley(), valley_params(flow, Precision::float32, 1, fused, true),
                                 target);
      one.run();
      for (const int threads : {2, 5, 13, 31, 40}) {
        auto many = make_simulation(
            valley(), valley_params(flow, Precision::float32, threads, fused, true), target);
        many.run();
        std::size_t total = 0;
        for (const auto& f : field_table()) total += differing(many.field(f.id), one.field(f.id));
        std::printf(
            "[in-place] %s%s, erosion, transport, thermal, %d threads against 1: %zu field "
            "values differ (bound 0)\n",
            flow == FlowScheme::pipes ? "pipes" : "local inertial", fused ? ", fused" : "", threads,
            total);
        EXPECT_EQ(total, 0u) << threads << " threads";
      }
    }
}

// The CPU pipes loop runs the rows whose cells and neighbour rows are all active through
// flow_pipes_cell_all_active, the kinds as constants (flow.cpp flow_blocks). It must give the
// bits of flow_pipes_cell_interior reading the same kinds from memory: three rows of 69 active
// cells (the 67 of the middle row between the ends), 20,000 random states each, float and
// double: surfaces from a few metres up to 4000 m, depths 0, films or metres (a third of them
// dry), old outflows 0 or up to 50 m^3/s (so that the outflow limit binds in some cells and not
// in others), pipe lengths and areas of a geographic row, dt from 1e-3 to 1 s. Bound: 0
// differing outflows. The cell's kind taken as fixed-level (the limit not applied) makes half
// of them differ.
template <class Real>
void expect_all_active_pipes_give_interior_bits(const char* type) {
  constexpr int W = 69, n = 3 * W;
  std::mt19937_64 rng(20261202);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<std::uint8_t> kind(n, ERODEM_CELL_ACTIVE);
  std::vector<Real> bed(n), depth(n), f[4], out_a[4], out_b[4];
  for (int k = 0; k < 4; ++k) f[k].resize(n), out_a[k].resize(n), out_b[k].resize(n);
  std::size_t differ = 0, checked = 0, limited = 0;
  for (int round = 0; round < 20000; ++round) {
    const double base = round % 3 == 0 ? 4000.0 * unit(rng) : 5.0 * unit(rng);
    for (int i = 0; i < n; ++i) {
      bed[i] = static_cast<Real>(base + 3.0 * unit(rng));
      const double kind_of_depth = unit(rng);
      depth[i] = static_cast<Real>(kind_of_depth < 0.33   ? 0.0
                                   : kind_of_depth < 0.66 ? 1e-4 * unit(rng)
                                                          : 3.0 * unit(rng));
      for (int k = 0; k < 4; ++k)
        f[k][i] = static_cast<Real>(unit(rng) < 0.3 ? 0.0 : 50.0 * unit(rng) * unit(rng));
    }
    const Real lx = static_cast<Real>(5.0 + 30.0 * unit(rng)),
               lt = static_cast<Real>(5.0 + 30.0 * unit(rng)),
               lb = static_cast<Real>(5.0 + 30.0 * unit(rng)),
               area = static_cast<Real>(lx * (0.5 * (lt + lb))),
               dt = static_cast<Real>(std::pow(10.0, -3.0 * unit(rng))),
               g = static_cast<Real>(9.81), a_pipe = static_cast<Real>(1.0 + 20.0 * unit(rng));
    for (int x = 1; x < W - 1; ++x) {
      cell::flow_pipes_cell_interior(x, 1, W, kind.data(), bed.data(), depth.data(), lx, lt, lb,
                                     area, f[0].data(), f[1].data(), f[2].data(), f[3].data(),
                                     out_a[0].data(), out_a[1].data(), out_a[2].data(),
                                     out_a[3].data(), dt, g, a_pipe);
      cell::flow_pipes_cell_all_active(x, 1, W, bed.data(), depth.data(), lx, lt, lb, area,
                                       f[0].data(), f[1].data(), f[2].data(), f[3].data(),
                                       out_b[0].data(), out_b[1].data(), out_b[2].data(),
                                       out_b[3].data(), dt, g, a_pipe);
      const int i = x + W;
      for (int k = 0; k < 4; ++k) {
        differ += std::memcmp(&out_a[k][i], &out_b[k][i], sizeof(Real)) != 0;
        ++checked;
      }
      // whether the limit binds: the outflows before it (a fixed-level cell's, which it does
      // not limit) ask for more than the cell holds (outflow_limit's own test)
      Real u[4];
      const auto eta = [&](int j) { return bed[j] + depth[j]; };
      cell::flow_pipes_outflows<Real>(ERODEM_CELL_FIXED, ERODEM_CELL_ACTIVE, ERODEM_CELL_ACTIVE,
                                      ERODEM_CELL_ACTIVE, ERODEM_CELL_ACTIVE, eta(i), eta(i - 1),
                                      eta(i + 1), eta(i - W), eta(i + W), f[0][i], f[1][i], f[2][i],
                                      f[3][i], lx, lt, lb, depth[i], area, dt, g, a_pipe, &u[0],
                                      &u[1], &u[2], &u[3]);
      limited += (u[0] + u[1] + u[2] + u[3]) * dt > depth[i] * area;
    }
  }
  std::printf(
      "[pipes all active] %s: %zu of %zu outflows differ from flow_pipes_cell_interior (bound 0); "
      "the limit binds in %zu of %zu cells\n",
      type, differ, checked, limited, checked / 4);
  EXPECT_EQ(differ, 0u) << type;
  EXPECT_GT(limited, checked / 40) << type;  // the limit binds in a share of the cells
  EXPECT_LT(limited, checked / 4 - checked / 40) << type;
}

TEST(PipesAllActive, KindsAsConstantsGiveTheBitsOfTheInteriorCell) {
  expect_all_active_pipes_give_interior_bits<float>("float");
  expect_all_active_pipes_give_interior_bits<double>("double");
}

/// A field of nx x ny cells of 5 m: a tilted, wavy slope with a pond in its middle rows, nodata
/// at the given cells.
Terrain slope(int nx, int ny, const std::vector<std::pair<int, int>>& nodata) {
  Terrain t = flat_terrain(nx, ny, kCell);
  t.water_depth.assign(t.grid.cells(), 0.0);
  for (int r = 0; r < ny; ++r)
    for (int c = 0; c < nx; ++c) {
      const auto i = static_cast<std::size_t>(r) * nx + c;
      t.bed[i] = 2.0 + 0.05 * r + 0.3 * std::sin(0.9 * c + 0.4 * r) + 0.02 * c;
      if (r > ny / 3 && r < 2 * ny / 3) t.water_depth[i] = std::max(0.0, 2.5 - t.bed[i]);
    }
  if (!nodata.empty()) {
    t.mask.assign(t.grid.cells(), 1);
    for (const auto& [r, c] : nodata) t.mask[static_cast<std::size_t>(r) * nx + c] = 0;
  }
  return t;
}

// The CPU flow loops take the kinds as constants in rows whose cells and neighbour rows are all
// active (CpuBackend::row_active_, flow.cpp; performance.md "Rows of active cells");
// ERODEM_CPU_ACTIVE_ROWS=0 turns that off, so every loop reads the kinds. The two must give the
// same bits: pipes and local inertial, fused and not, erosion + transport + thermal collapse +
// evaporation on, 30 steps of rain, open north and south edges, on grids 1 to 6 cells wide
// between walls (padded widths 3 to 8, where the ranges of constant kinds are empty, one cell
// or a few), and 37 x 29 three times: four nodata cells (the rows beside them take the general
// loops) with open east and west edges, periodic east and west edges (active ghost columns),
// and between walls. The constant kinds as a run has them by default (the variable unset).
// Bound: 0 values of any field and 0 ledger entries differ. Checked by hand: the pipes' range of
// constant kinds one column wider (to W - 2, beside the east ghost) and the east faces' (to W - 3)
// make every case between walls at least 2 (pipes) or 3 (local inertial) cells wide fail, 160 to
// 571 values differ.
TEST(ActiveRows, KindsAsConstantsGiveTheBitsOfTheGeneralLoops) {
  const Target target{"cpu", Precision::float32};
  const RestoreEnv restore("ERODEM_CPU_ACTIVE_ROWS");
  enum class Edges { open, walls, periodic };  // east and west; north and south open
  struct Grid {
    int nx, ny;
    std::vector<std::pair<int, int>> nodata;
    Edges edges;
  };
  std::vector<Grid> grids;
  for (int nx = 1; nx <= 6; ++nx) grids.push_back({nx, 12, {}, Edges::walls});
  grids.push_back({37, 29, {{9, 20}, {10, 21}, {20, 3}, {27, 30}}, Edges::open});
  grids.push_back({37, 29, {}, Edges::periodic});
  grids.push_back({37, 29, {}, Edges::walls});
  for (const FlowScheme flow : {FlowScheme::local_inertial, FlowScheme::pipes})
    for (const bool fused : {false, true})
      for (const Grid& g : grids) {
        Params p = rain_params(flow, 30);
        p.erosion.enabled = p.thermal.enabled = true;
        p.erosion.law = ErosionLaw::mei;
        p.thermal.talus_angle = 20.0;
        p.evaporation.rate = 1e-7;
        p.boundary.north = p.boundary.south = BoundaryKind::open;
        p.boundary.east = p.boundary.west = g.edges == Edges::periodic ? BoundaryKind::periodic
                                            : g.edges == Edges::walls  ? BoundaryKind::closed
                                                                       : BoundaryKind::open;
        p.numerics.threads = 2;
        p.numerics.fused_sweeps = fused;
        unsetenv("ERODEM_CPU_ACTIVE_ROWS");
        auto constant = make_simulation(slope(g.nx, g.ny, g.nodata), p, target);
        setenv("ERODEM_CPU_ACTIVE_ROWS", "0", 1);
        auto loaded = make_simulation(slope(g.nx, g.ny, g.nodata), p, target);
        constant.run();
        loaded.run();
        ASSERT_EQ(constant.steps_done(), 30);
        const auto [total, ledger] = compare_runs(constant, loaded);
        EXPECT_GT(constant.ledger().boundary_out, 0.0) << "no outflow";
        std::printf(
            "[active rows] %s%s, %d x %d%s%s: kinds as constants against loaded: %zu field "
            "values differ, %zu ledger entries (bound 0)\n",
            flow == FlowScheme::pipes ? "pipes" : "local inertial", fused ? ", fused" : "", g.nx,
            g.ny, g.nodata.empty() ? "" : ", nodata",
            g.edges == Edges::periodic ? ", periodic"
            : g.edges == Edges::walls  ? ", walls"
                                       : "",
            total, ledger);
      }
}

// Both backends keep each row's material and sediment volumes while no process that can
// change them runs (CpuBackend::material_rows_, OpenClBackend::material_rows_,
// changes_material): through the water-only steps, not after erosion, transport or thermal
// collapse. Either way they give, step by step, the bits of the statistics summed every time,
// which a twin run does that sets a field before each step (the sediment, to the values it
// holds: a set bed or sediment makes the backend sum the volumes again). Bound: 0 differing values.
// A process missing from changes_material leaves its change out of the kept volumes, which then
// stay at an earlier step's value while the summed ones move (the test demands the material
// move under erosion): with changes_material false for every process, the material and
// sediment volumes of every step of the erosion runs differ, 80 of 200 values in each of their
// twelve cases (checked on both backends, in their row and their rounded launches on PoCL).
TEST(KeptVolumes, GiveTheBitsOfVolumesSummedEveryStep) {
  std::vector<Target> targets{{"cpu", Precision::float32}, {"cpu", Precision::float64}};
  if (opencl_available()) targets.push_back({"opencl", Precision::float32});
  for (const Target& target : targets)
    for (const bool erosion : {false, true})
      for (const FlowScheme flow : {FlowScheme::local_inertial, FlowScheme::pipes})
        for (const bool fused : {false, true}) {
          const Params p = valley_params(flow, target.precision, 2, fused, erosion);
          auto kept = make_simulation(valley(), p, target);
          auto summed = make_simulation(valley(), p, target);
          const FieldStats first = kept.last_stats();
          std::size_t differ = 0;
          for (int s = 0; s < 40; ++s) {
            summed.backend().set_field(FieldId::sediment, summed.field(FieldId::sediment));
            kept.step();
            summed.step();
            const FieldStats a = kept.last_stats(), b = summed.last_stats();
            for (const auto member :
                 {&FieldStats::water_volume, &FieldStats::material_volume,
                  &FieldStats::sediment_volume, &FieldStats::max_depth, &FieldStats::max_speed})
              differ += std::memcmp(&(a.*member), &(b.*member), sizeof(double)) != 0;
          }
          const FieldStats last = kept.last_stats();
          const double water = last.water_volume - first.water_volume,
                       material = last.material_volume - first.material_volume;
          std::printf(
              "[kept volumes] %s %s %s%s%s: %zu of 200 statistics differ (bound 0); over 40 "
              "steps the water volume changed by %.6g m^3, the material volume by %.6g m^3\n",
              target.backend.c_str(),
              target.precision == Precision::float64 ? "float64" : "float32",
              flow == FlowScheme::pipes ? "pipes" : "local inertial", fused ? ", fused" : "",
              erosion ? ", erosion, transport, thermal" : ", water only", differ, water, material);
          EXPECT_EQ(differ, 0u);
          EXPECT_NE(water, 0.0);
          if (erosion) {
            EXPECT_NE(material, 0.0);
          }
          std::size_t ledger = 0;
          for (const auto& e : ledger_entries()) {
            const double x = kept.ledger().*e.member, y = summed.ledger().*e.member;
            ledger += std::memcmp(&x, &y, sizeof(double)) != 0;
          }
          EXPECT_EQ(ledger, 0u) << "ledger entries differ";
        }
}

// Changes between steps reach the kept volumes: the bed set through Backend::set_field, and
// written in place through a host view (after which the volumes are summed every time). Each
// raises the material volume by exactly what was added, float32's rounding of the new bed
// included (a kept volume would not move: the bound, 1e-9 of the change, is far below the
// change itself; the cells are summed in double, so only the sum's last bits round).
TEST(KeptVolumes, SeeTheBedSetBetweenSteps) {
  const Target target{"cpu", Precision::float32};
  auto sim = make_simulation(
      valley(), valley_params(FlowScheme::pipes, Precision::float32, 2, true, false), target);
  sim.step(3);
  const double area = kCell * kCell;
  const double before = sim.last_stats().material_volume;
  std::vector<double> bed = sim.field(FieldId::bed);
  for (double& b : bed) b += 0.5;  // 0.5 m on every cell: all of them are active
  sim.backend().set_field(FieldId::bed, bed);
  sim.step();
  const double set_rise = sim.last_stats().material_volume - before,
               set_expected = 0.5 * area * static_cast<double>(bed.size());
  // in place: 2 m onto one cell through the view (float32: the element is a float)
  const HostView v = sim.backend().host_view(FieldId::bed);
  ASSERT_NE(v.data, nullptr);
  const double before_view = sim.last_stats().material_volume;
  float* cell = static_cast<float*>(v.data) + 10 * v.row_stride + 10;
  const float old_bed = *cell;
  *cell += 2.0f;
  const double view_expected = (static_cast<double>(*cell) - old_bed) * area;  // float's 2 m
  sim.step();
  const double view_rise = sim.last_stats().material_volume - before_view;
  std::printf(
      "[kept volumes] material volume: +%.9g m^3 after set_field (expected %.9g), +%.9g m^3 "
      "after a write through the host view (expected %.9g)\n",
      set_rise, set_expected, view_rise, view_expected);
  EXPECT_NEAR(set_rise, set_expected, 1e-9 * set_expected);
  EXPECT_NEAR(view_rise, view_expected, 1e-9 * view_expected);
}

TEST(FusedPasses, TheTableCutsTheSequenceIntoPasses) {
  Params p;
  p.erosion.enabled = true;
  p.thermal.enabled = true;
  p.rain.rate = 1e-5;
  const auto seq = step_sequence(p);
  const auto fused = step_passes(p, true), apart = step_passes(p, false);
  EXPECT_EQ(apart.size(), seq.size());
  ASSERT_EQ(fused.size(), seq.size() - 3);  // flow, sources, water and erosion in one
  std::vector<Process> flat;
  for (const auto& pass : fused) flat.insert(flat.end(), pass.begin(), pass.end());
  EXPECT_EQ(flat, seq);  // the same processes in the same order
  const std::vector<Process> flow_water{Process::flow, Process::sources, Process::water};
  std::vector<Process> with_erosion = flow_water;
  with_erosion.push_back(Process::erosion);
  EXPECT_NE(std::find(fused.begin(), fused.end(), with_erosion), fused.end());
  // without erosion (thermal collapse on) the pass is the three
  Params no_erosion = p;
  no_erosion.erosion.enabled = false;
  const auto ne = step_passes(no_erosion, true);
  EXPECT_NE(std::find(ne.begin(), ne.end(), flow_water), ne.end());
  // without erosion and thermal collapse the evaporation follows the water update and joins
  // the pass
  Params water_only = p;
  water_only.erosion.enabled = water_only.thermal.enabled = false;
  const auto w = step_passes(water_only, true);
  EXPECT_EQ(w.size(), step_sequence(water_only).size() - 3);
  EXPECT_NE(std::find(w.begin(), w.end(),
                      std::vector<Process>{Process::flow, Process::sources, Process::water,
                                           Process::evaporation}),
            w.end());
  // the byte model: the pass reads the state once and writes it once: the kind (1 B), bed,
  // depth, Manning n, the 4 outflows and the rain factor (8 x 4 B) read, the depth, the 4
  // outflows and 2 velocities (7 x 4 B) written, 61 B, against 45 + 13 + 37 = 95 B for the
  // three sweeps
  int apart_bytes = 0;
  for (const Process q : flow_water) apart_bytes += process_bytes(q, p, 4).total();
  const SweepBytes b = sweep_bytes(pass_sweep(flow_water, p), 4);
  std::printf("[fused] bytes per cell: flow + sources + water %d apart, %d fused (%s / %s)\n",
              apart_bytes, b.total(), b.reads.c_str(), b.writes.c_str());
  EXPECT_EQ(apart_bytes, 95);
  EXPECT_EQ(b.total(), 61);
  // shallow water is not fused
  p.flow.scheme = FlowScheme::shallow_water;
  EXPECT_EQ(step_passes(p, true).size(), step_sequence(p).size());
}

}  // namespace
}  // namespace erodem::test
