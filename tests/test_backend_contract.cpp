// erodem — the backend contract (backend.hpp): a step is begin_step, run per process and
// end_step, which returns the step's tallies, the statistics and the probe samples. On every
// target: end_step's tallies and statistics equal those of the old path (run(p, in, tally)
// per process, then stats(); CPU: a digest recorded from it) and do not depend on waits, bit
// for bit; the probes, sample() and the gauges of a result file equal whole-field reads bit
// for bit.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "erodem/io/results.hpp"
#include "erodem/io/run_session.hpp"
#include "erodem/io/setup.hpp"
#include "erodem/process.hpp"
#include "erodem/schema.hpp"
#include "target_test.hpp"
#include "temp_dir.hpp"
#ifdef ERODEM_HAVE_OPENCL
#include "opencl/opencl_backend.hpp"
#endif

namespace erodem::test {
namespace {

/// A 32 x 32 synthetic valley with every process on: rain, a point inflow, erosion,
/// `transport`, thermal collapse, evaporation, an open and a fixed-level edge (coast cells);
/// adaptive steps for local inertial, fixed ones for the pipes.
Params valley_storm(const Target& target, FlowScheme flow, TransportScheme transport) {
  Params p;
  p.dem.synthetic = "valley";
  p.dem.size = 32;
  p.dem.seed = 3;
  p.dem.relief = 40.0;
  p.dem.cell_size = 10.0;
  p.initial.water_depth.value = 0.05;
  p.time.adaptive = flow == FlowScheme::local_inertial;  // pipes: fixed steps
  p.time.dt = 0.05;
  p.time.dt_max = 2.0;
  p.flow.scheme = flow;
  p.rain.rate = 80e-3 / 3600;  // m/s
  p.inflow.push_back({{{155.0, 255.0}}, {{0.0, 0.5}, {60.0, 2.0}}});
  p.erosion.enabled = true;
  p.erosion.law = ErosionLaw::mei;  // the capacity law these figures were recorded with
  p.erosion.sediment_capacity = 0.2;
  p.erosion.dissolving_rate = 0.01;
  p.erosion.deposition_rate = 0.05;
  p.transport.scheme = transport;
  p.thermal.enabled = true;
  p.thermal.talus_angle = 30.0;
  p.thermal.rate = 0.05;
  p.evaporation.rate = 1e-6;
  p.boundary.east = BoundaryKind::open;
  p.boundary.west = BoundaryKind::fixed_level;
  p.boundary.sea_level = 1.0;
  p.numerics.precision = target.precision;
  validate(p, "valley_storm");
  return p;
}

struct Schemes {
  FlowScheme flow;
  TransportScheme transport;
  const char* label;
};
const Schemes kSchemes[] = {
    {FlowScheme::local_inertial, TransportScheme::conservative, "local_inertial+conservative"},
    {FlowScheme::pipes, TransportScheme::semi_lagrangian, "pipes+semi_lagrangian"},
};

/// Whether two doubles hold the same bits.
bool same_bits(double a, double b) {
  return std::memcmp(&a, &b, sizeof(double)) == 0;
}

/// The members of a FieldStats that differ in their bits ("" when none).
std::string stats_differences(const FieldStats& a, const FieldStats& b) {
  std::string out;
  auto num = [&](const char* name, double x, double y) {
    if (!same_bits(x, y)) out += std::string(" ") + name;
  };
  num("water_volume", a.water_volume, b.water_volume);
  num("material_volume", a.material_volume, b.material_volume);
  num("sediment_volume", a.sediment_volume, b.sediment_volume);
  num("max_depth", a.max_depth, b.max_depth);
  num("max_speed", a.max_speed, b.max_speed);
  if (a.max_depth_cell != b.max_depth_cell) out += " max_depth_cell";
  if (a.max_speed_cell != b.max_speed_cell) out += " max_speed_cell";
  if (a.bad_cell != b.bad_cell) out += " bad_cell";
  return out;
}

/// The tallies (tally_table()) that differ in their bits ("" when none).
std::string tally_differences(const StepTally& a, const StepTally& b) {
  std::string out;
  for (const auto& t : tally_table())
    if (!same_bits(a.*t.step, b.*t.step)) out += std::string(" ") + t.name;
  return out;
}

/// The tallies the recorded digests (old_path_digest) cover: those of tally_table() when they
/// were recorded (2026-11-26, before the snow pack); later ones are 0 in valley_storm.
constexpr std::size_t kRecordedTallies = 10;

/// FNV-1a over the bits of every recorded tally and statistic of a step, chained over the
/// steps. A tally added to the table later must be 0 here (valley_storm does not run its
/// process): else the digest would not be comparable, and this throws.
std::uint64_t digest(std::uint64_t h, const StepTally& t, const FieldStats& st) {
  auto add = [&](const void* p, std::size_t n) {
    const auto* b = static_cast<const unsigned char*>(p);
    for (std::size_t k = 0; k < n; ++k) h = (h ^ b[k]) * 0x100000001b3ULL;
  };
  const auto& table = tally_table();
  for (std::size_t k = 0; k < table.size(); ++k) {
    if (k < kRecordedTallies)
      add(&(t.*table[k].step), sizeof(double));
    else if (t.*table[k].step != 0.0)
      throw std::runtime_error(std::string("digest: tally ") + table[k].name + " is not 0");
  }
  for (const double v :
       {st.water_volume, st.material_volume, st.sediment_volume, st.max_depth, st.max_speed})
    add(&v, sizeof v);
  for (const std::int64_t c : {st.max_depth_cell, st.max_speed_cell, st.bad_cell})
    add(&c, sizeof c);
  return h;
}

/// Cells of an n x n grid to probe: the corners, the edges' middles, inner cells, one twice.
std::vector<std::int64_t> probe_cells(std::int64_t n) {
  return {0,           n - 1,     n * (n - 1),         n * n - 1, n / 2,
          n * (n / 2), 5 * n + 7, (n / 2) * n + n / 2, 5 * n + 7};
}

/// Every field of the field table.
std::vector<FieldId> every_field() {
  std::vector<FieldId> out;
  for (const auto& f : field_table()) out.push_back(f.id);
  return out;
}

class BackendContract : public TargetTest {};

/// The digest of 30 steps' tallies and statistics of valley_storm, as the path before the
/// backend contract gave them (run(p, in, tally) per process, then stats(); 5f71b35 compared
/// both paths bit for bit on every target): CPU only, whose bits do not depend on the
/// instruction set or the thread count (test_cpu_isa.cpp); OpenCL's belong to one device.
/// Float64 local inertial recorded again on 2026-11-27, when its cube root became
/// cbrt_f64_positive (compat.h; within 1 ulp as the C library's, which it replaced: was
/// 0x218ca05766e5842d); pipes take no cube root and kept theirs. All four recorded again on
/// 2026-11-29, when the CPU's row sums (sum_row) and the statistics' volumes moved from four
/// partial sums and one running sum to sixteen partial sums (performance.md, "Sums in sixteen
/// lanes"; every field kept its bits; were 0xad8184f0755a5e10, 0x60cd89222141a995,
/// 0x8706ca05ca84c2d5, 0xd9ec0168a9106f3a).
std::uint64_t old_path_digest(const Target& t, FlowScheme flow) {
  const bool li = flow == FlowScheme::local_inertial;
  if (t.backend != "cpu") return 0;
  if (t.f64()) return li ? 0x4abfc11e008dc6f1ULL : 0xc5370fa82ee0124aULL;
  return li ? 0x1216715d3afb16afULL : 0xfe856bb7888ac17aULL;
}

// end_step gives the tallies and statistics the old path gave, and waits do not change them:
// two simulations from the same state, one stepped with begin_step, run(p), end_step, the
// other with finish() after every process and stats() halfway through the step (where the
// old lifetime rule delivered the OpenCL tallies); every tally and statistic of every step
// compared bit for bit, and on the CPU the digest of the 30 steps against the old path's.
TEST_P(BackendContract, EndStepEqualsTheOldPath) {
  for (const auto& s : kSchemes) {
    const Params p = valley_storm(target(), s.flow, s.transport);
    Simulation a = io::make_simulation(p, target().backend);
    Simulation b = io::make_simulation(p, target().backend);
    const double dt = a.next_dt();
    const auto seq = a.sequence();
    int differing = 0;
    double moved = 0;
    std::uint64_t h = 0xcbf29ce484222325ULL;
    Backend& plain = a.backend();
    Backend& waited = b.backend();
    for (int step = 0; step < 30; ++step) {
      StepInputs in = a.inputs_for(dt);
      in.t = step * dt;
      plain.begin_step(in);
      for (const Process proc : seq) plain.run(proc);
      const StepResult r = plain.end_step();
      waited.begin_step(in);
      for (std::size_t k = 0; k < seq.size(); ++k) {
        waited.run(seq[k]);
        waited.finish();
        if (k == seq.size() / 2) (void)waited.stats();
      }
      const StepResult w = waited.end_step();
      const std::string dt_ = tally_differences(r.tally, w.tally),
                        ds = stats_differences(r.stats, w.stats);
      if (!dt_.empty() || !ds.empty()) {
        ++differing;
        ADD_FAILURE() << s.label << " step " << step << ": differ:" << dt_ << ds;
      }
      moved += r.tally.water_exchanged;
      h = digest(h, r.tally, r.stats);
    }
    const std::uint64_t want = old_path_digest(target(), s.flow);
    std::printf(
        "[backend contract] %s %s: 30 steps (%.3g m^3 of water exchanged): end_step with "
        "finish() after every process and stats() within the step against without: %d steps "
        "differ (bound 0); digest %016llx, the old path's %016llx%s\n",
        target().label().c_str(), s.label, moved, differing, static_cast<unsigned long long>(h),
        static_cast<unsigned long long>(want), want ? "" : " (not recorded: CPU only)");
    if (want) {
      EXPECT_EQ(h, want) << "the tallies and statistics differ from the old path's";
    }
    EXPECT_GT(moved, 0.0) << "the water moved";
  }
}

// The probes of end_step and sample() equal whole-field reads bit for bit: every field of
// the field table at corners, edges and inner cells, after every step of both schemes.
TEST_P(BackendContract, ProbesAndSampleEqualFieldReads) {
  for (const auto& s : kSchemes) {
    const Params p = valley_storm(target(), s.flow, s.transport);
    Simulation sim = io::make_simulation(p, target().backend);
    const std::int64_t n = sim.grid().nx;
    const auto cells = probe_cells(n);
    const auto fields = every_field();
    Backend& be = sim.backend();
    be.set_probes(cells, fields);
    const double dt = sim.next_dt();
    long compared = 0, differing = 0;
    for (int step = 0; step < 20; ++step) {
      StepInputs in = sim.inputs_for(dt);
      in.t = step * dt;
      be.begin_step(in);
      for (const Process proc : sim.sequence()) be.run(proc);
      const StepResult r = be.end_step();
      ASSERT_EQ(r.probes.size(), fields.size() * cells.size());
      for (std::size_t k = 0; k < fields.size(); ++k) {
        const auto whole = be.field(fields[k]);
        const auto sampled = be.sample(cells, fields[k]);
        ASSERT_EQ(sampled.size(), cells.size());
        for (std::size_t j = 0; j < cells.size(); ++j) {
          const double want = whole[static_cast<std::size_t>(cells[j])];
          const double probe = r.probes[k * cells.size() + j];
          compared += 2;
          if (!same_bits(probe, want) || !same_bits(sampled[j], want)) {
            ++differing;
            ADD_FAILURE() << s.label << " step " << step << " " << field_info(fields[k]).name
                          << " cell " << cells[j] << ": field " << want << ", probe " << probe
                          << ", sample " << sampled[j];
          }
        }
      }
    }
    std::printf(
        "[backend contract] %s %s: %ld probe and sample values of %zu fields at %zu cells over "
        "20 steps against field()[cell]: %ld differ (bound 0)\n",
        target().label().c_str(), s.label, compared, fields.size(), cells.size(), differing);
    // No probes: end_step gives none; sample() of no cells is empty; a cell off the grid is
    // a usage error.
    be.set_probes({}, {});
    be.begin_step(sim.inputs_for(dt));
    EXPECT_TRUE(be.end_step().probes.empty());
    EXPECT_TRUE(be.sample({}, FieldId::water_depth).empty());
    for (const std::int64_t bad : {std::int64_t{-1}, n * n}) {
      try {
        (void)be.sample({0, bad}, FieldId::water_depth);
        ADD_FAILURE() << "sample of cell " << bad << " did not throw";
      } catch (const Error& e) {
        EXPECT_EQ(e.code(), ExitCode::usage) << e.what();
      }
      EXPECT_THROW(be.set_probes({bad}, {FieldId::bed}), Error);
    }
  }
}

// field_rows and set_field_rows (the result writer's and the initial fields' strips) are
// field() and set_field() a strip at a time: every field of the table read in strips of 7
// rows (the last one short) is field() bit for bit after 5 steps of both schemes, a field set
// in strips reads back as the same values set whole on a second simulation, and rows off the
// grid or a wrong count of values are errors. Bound: 0 values differ.
TEST_P(BackendContract, FieldRowsAreTheFieldAStripAtATime) {
  for (const auto& s : kSchemes) {
    const Params p = valley_storm(target(), s.flow, s.transport);
    Simulation sim = io::make_simulation(p, target().backend);
    Simulation whole_sim = io::make_simulation(p, target().backend);
    sim.step(5);
    const int nx = sim.grid().nx, ny = sim.grid().ny;
    Backend& be = sim.backend();
    long compared = 0, differing = 0;
    for (const FieldId id : every_field()) {
      const auto whole = be.field(id);
      std::vector<double> strips;
      for (int row0 = 0; row0 < ny; row0 += 7) {
        const auto part = be.field_rows(id, row0, std::min(ny, row0 + 7));
        strips.insert(strips.end(), part.begin(), part.end());
      }
      ASSERT_EQ(strips.size(), whole.size()) << field_info(id).name;
      for (std::size_t i = 0; i < whole.size(); ++i) {
        ++compared;
        if (!same_bits(strips[i], whole[i])) ++differing;
      }
    }
    // a state field with twins (the depth) and one without (the hardness), set in strips
    for (const FieldId id : {FieldId::water_depth, FieldId::hardness}) {
      std::vector<double> values(static_cast<std::size_t>(nx) * ny);
      for (std::size_t i = 0; i < values.size(); ++i)
        values[i] = 0.001 * static_cast<double>(i % 97);
      for (int row0 = 0; row0 < ny; row0 += 7) {
        const int row1 = std::min(ny, row0 + 7);
        be.set_field_rows(
            id, row0, row1,
            std::vector<double>(values.begin() + static_cast<std::ptrdiff_t>(row0) * nx,
                                values.begin() + static_cast<std::ptrdiff_t>(row1) * nx));
      }
      whole_sim.backend().set_field(id, values);
      const auto a = be.field(id), b = whole_sim.backend().field(id);
      for (std::size_t i = 0; i < a.size(); ++i) {
        ++compared;
        if (!same_bits(a[i], b[i])) ++differing;
      }
    }
    std::printf(
        "[backend contract] %s %s: %ld values read or set in strips of 7 rows against "
        "whole fields: %ld differ (bound 0)\n",
        target().label().c_str(), s.label, compared, differing);
    EXPECT_EQ(differing, 0);
    for (const auto& [row0, row1] : {std::pair{3, 2}, std::pair{-1, 2}, std::pair{0, ny + 1}}) {
      try {
        (void)be.field_rows(FieldId::bed, row0, row1);
        ADD_FAILURE() << "field_rows(" << row0 << ", " << row1 << ") did not throw";
      } catch (const Error& e) {
        EXPECT_EQ(e.code(), ExitCode::usage) << e.what();
      }
    }
    try {
      be.set_field_rows(FieldId::sediment, 0, 2, std::vector<double>(static_cast<std::size_t>(nx)));
      ADD_FAILURE() << "set_field_rows with one row of values for two did not throw";
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ExitCode::data) << e.what();
    }
  }
}

// The gauges of a result file equal whole-field reads bit for bit: a run with four gauges
// through io::RunSession (which registers them as the simulation's probes, gathered by
// end_step), after every step the expected row from field(): depth, bed + depth and
// hypot(vx, vy) at the gauge cells; and the same run written by a ResultWriter whose gauges
// are not the simulation's probes (record_step samples them).
TEST_P(BackendContract, GaugesEqualWholeFieldReads) {
  TempDir dir;
  Params p = valley_storm(target(), FlowScheme::local_inertial, TransportScheme::conservative);
  p.time.steps = 40;
  p.output.every = 1000;
  p.output.fields = {"water_depth"};
  p.output.restart_state = false;
  p.output.gauges = {{15.0, 15.0}, {155.0, 155.0}, {305.0, 305.0}, {155.0, 255.0}};
  p.output.path = dir.file("probed.h5");
  io::SessionOptions options;
  options.backend = target().backend;
  options.command_line = "test_backend_contract";
  io::RunSession session(p, options);
  const auto cells = session.writer()->gauge_cells();
  ASSERT_EQ(cells.size(), 4u);
  std::vector<double> want;  // [step][gauge][depth, level, speed]
  long probed = 0;
  session.advance({}, {}, [&](const Simulation& sim) {
    if (sim.probes() && sim.probe_cells() == cells) ++probed;
    const auto d = sim.field(FieldId::water_depth), b = sim.field(FieldId::bed),
               vx = sim.field(FieldId::velocity_x), vy = sim.field(FieldId::velocity_y);
    for (const std::int64_t cell : cells) {
      const auto i = static_cast<std::size_t>(cell);
      want.insert(want.end(), {d[i], b[i] + d[i], std::hypot(vx[i], vy[i])});
    }
  });
  session.finish();
  EXPECT_EQ(probed, 40) << "the steps whose gauges came from the probes";

  // The same run, its gauges sampled by record_step (not registered as probes).
  p.output.path = dir.file("sampled.h5");
  Simulation sim = io::make_simulation(p, target().backend);
  {
    io::ResultWriter writer(p.output.path, sim, "test_backend_contract", false);
    writer.snapshot(sim);
    while (!sim.finished()) {
      sim.step();
      writer.step_done(sim);
    }
    EXPECT_TRUE(sim.probe_cells().empty());
    writer.finish(sim);
  }

  long compared = 0, differing = 0;
  for (const char* name : {"probed.h5", "sampled.h5"}) {
    const auto g = io::ResultReader(dir.file(name)).gauges();
    ASSERT_EQ(g.time.size(), 40u) << name;
    for (std::size_t step = 0; step < g.time.size(); ++step)
      for (std::size_t j = 0; j < cells.size(); ++j) {
        const double* w = &want[(step * cells.size() + j) * 3];
        const double got[3] = {g.water_depth[step][j], g.water_level[step][j], g.speed[step][j]};
        for (int k = 0; k < 3; ++k) {
          ++compared;
          if (!same_bits(got[k], w[k])) {
            ++differing;
            ADD_FAILURE() << name << " step " << step + 1 << " gauge " << j << " series " << k
                          << ": " << got[k] << ", field reads " << w[k];
          }
        }
      }
  }
  std::printf(
      "[backend contract] %s: %ld gauge values (4 gauges, 40 steps, depth, level, speed; "
      "probed and sampled) against whole-field reads: %ld differ (bound 0); %ld of 40 steps "
      "took the gauges from the step's probes\n",
      target().label().c_str(), compared, differing, probed);
}

// A step outside begin_step .. end_step is a programming error, named as such.
TEST_P(BackendContract, RunOutsideAStepIsAnError) {
  const Params p =
      valley_storm(target(), FlowScheme::local_inertial, TransportScheme::conservative);
  Simulation sim = io::make_simulation(p, target().backend);
  Backend& be = sim.backend();
  try {
    be.run(Process::flow);
    ADD_FAILURE() << "run() outside a step did not throw";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ExitCode::internal) << e.what();
  }
  EXPECT_THROW(be.end_step(), Error);
}

/// The statistics of `depth`, `u`, `v` (whole DEM fields, row-major) over the cells `mask`
/// leaves active, by one scan in row-major order (independent of the backends' loops): the
/// volumes added row by row (each row's sum in x order, then the rows in order), the first cell
/// of the largest depth and of the largest squared speed, and the first active cell whose
/// depth is negative or not finite (bed and sediment are finite here).
FieldStats scan_stats(const Grid& g, const std::vector<std::uint8_t>& mask,
                      const std::vector<double>& depth, const std::vector<double>& u,
                      const std::vector<double>& v) {
  FieldStats st;
  st.max_depth = 0.0;
  st.max_speed = 0.0;
  double max_d = -1, max_v2 = -1;
  for (int y = 0; y < g.ny; ++y) {
    double row = 0;
    for (int x = 0; x < g.nx; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * g.nx + x;
      if (!mask[i]) continue;
      row += depth[i] * g.area[y];
      if (st.bad_cell < 0 && !(depth[i] >= 0 && std::isfinite(depth[i])))
        st.bad_cell = static_cast<std::int64_t>(i);
      if (depth[i] > max_d) {
        max_d = depth[i];
        st.max_depth = std::max(0.0, depth[i]);
        st.max_depth_cell = static_cast<std::int64_t>(i);
      }
      const double v2 = u[i] * u[i] + v[i] * v[i];
      if (v2 > max_v2) {
        max_v2 = v2;
        st.max_speed = std::hypot(u[i], v[i]);
        st.max_speed_cell = static_cast<std::int64_t>(i);
      }
    }
    st.water_volume += row;
  }
  return st;
}

// The statistics take the first cell of each tie in row-major order, skip the nodata cells
// (which hold the largest depth and speed here), never rank a NaN, and name the first active
// cell that is not physical; the water volume is the per-row sums' in row order. Four states
// on a 300 x 19 grid with 5 nodata cells (rows of three chunks of the CPU's row maxima),
// against scan_stats of the fields read back: ties of the largest depth (two cells in the
// second chunk of a row, one in its third, one in a later row) and of the squared speed ((3,
// 4) and (-4, 3) in the second and third chunks of one row, then (4, -3), (0, -5): 25
// m^2/s^2); a still state of zero depths (-0 in each row's first chunk, +0 beyond) whose first
// active cell wins both; NaN depths; negative depths with finite volumes (a nodata cell first
// in both). Cells must be equal; the volume bit for bit on the CPU (its sums are the scan's:
// the ledger's bits), within 1e-6 on OpenCL (float partial sums on the device). A backend that
// kept the last cell or chunk of a tie, let a nodata cell in, ranked a NaN or looked for bad
// cells only where a volume is not finite fails a cell comparison.
TEST_P(BackendContract, StatisticsTakeTheFirstCellOfATie) {
  const int nx = 300, ny = 19;  // 3 chunks of the CPU's row maxima (kStatsChunk 128)
  Terrain t;
  t.grid = Grid::uniform(nx, ny, 10.0);
  t.bed.resize(t.grid.cells());
  for (std::size_t i = 0; i < t.bed.size(); ++i)
    t.bed[i] = 5.0 + 0.01 * static_cast<double>(i % nx);
  t.mask.assign(t.grid.cells(), 1);
  auto at = [&](int x, int y) { return static_cast<std::size_t>(y) * nx + x; };
  for (const std::size_t i : {at(0, 0), at(4, 1), at(15, 6), at(140, 3), at(299, 18)})
    t.mask[i] = 0;
  Params p;
  p.dem.synthetic = "valley";  // the schema's requirement; the backend takes the terrain above
  p.dem.cell_size = 10.0;
  p.numerics.precision = target().precision;
  validate(p, "ties");
  std::unique_ptr<Backend> be = make_backend(target().backend, t, p);

  struct State {
    const char* label;
    std::vector<double> depth, u, v;
  };
  const std::size_t n = t.grid.cells();
  std::vector<State> states;
  {
    State s{"ties", std::vector<double>(n, 0.25), std::vector<double>(n, 0.5),
            std::vector<double>(n, -1.0)};
    s.depth[at(4, 1)] = 0.9;    // nodata: not ranked
    s.depth[at(140, 3)] = 0.9;  // nodata: not ranked
    // the first two in the second chunk of row 3, the third in its third chunk
    for (const std::size_t i : {at(150, 3), at(200, 3), at(270, 3), at(2, 15)}) s.depth[i] = 0.75;
    s.u[at(15, 6)] = 9.0;                           // nodata
    s.u[at(135, 2)] = 3.0, s.v[at(135, 2)] = 4.0;   // second chunk
    s.u[at(260, 2)] = -4.0, s.v[at(260, 2)] = 3.0;  // third chunk of the same row
    s.u[at(5, 10)] = 4.0, s.v[at(5, 10)] = -3.0;
    s.u[at(0, 18)] = 0.0, s.v[at(0, 18)] = -5.0;
    states.push_back(s);
  }
  {
    State s{"still", std::vector<double>(n, 0.0), std::vector<double>(n, 0.0),
            std::vector<double>(n, 0.0)};
    // -0 in the first chunk of every row, +0 beyond, and +0 and -0 alternating in row 0
    for (std::size_t i = 0; i < n; ++i)
      if (i % nx < 128 || (i < static_cast<std::size_t>(nx) && i % 2)) s.depth[i] = -0.0;
    states.push_back(s);
  }
  {
    State s = states[0];
    s.label = "nan";
    const double nan = std::numeric_limits<double>::quiet_NaN();
    s.depth[at(4, 1)] = nan;  // nodata: not bad
    s.depth[at(9, 4)] = nan;
    s.depth[at(3, 12)] = nan;
    s.depth[at(290, 3)] = 0.95;  // the largest beside them (third chunk)
    states.push_back(s);
  }
  {
    State s = states[0];
    s.label = "negative";      // finite volumes: only a depth below 0 shows the bad cells
    s.depth[at(4, 1)] = -0.5;  // nodata: not bad
    s.depth[at(12, 2)] = -0.01;
    s.depth[at(3, 7)] = -0.02;
    states.push_back(s);
  }
  int differing = 0;
  for (const State& s : states) {
    be->set_field(FieldId::water_depth, s.depth);
    be->set_field(FieldId::velocity_x, s.u);
    be->set_field(FieldId::velocity_y, s.v);
    const FieldStats got = be->stats();
    const FieldStats want =
        scan_stats(t.grid, t.mask, be->field(FieldId::water_depth), be->field(FieldId::velocity_x),
                   be->field(FieldId::velocity_y));
    // 0 where the two agree bit for bit (the still state's 0 and the NaN state's NaN)
    const double vol_rel =
        same_bits(got.water_volume, want.water_volume)
            ? 0.0
            : std::abs(got.water_volume - want.water_volume) / std::abs(want.water_volume);
    std::printf(
        "[backend contract] %s statistics of '%s': max depth %.6g m at cell %lld (scan: %.6g at "
        "%lld), max speed %.6g m/s at %lld (scan: %.6g at %lld), first bad cell %lld (scan: "
        "%lld), water %.17g m^3 (scan: %.17g; relative difference %.2e, bound %s)\n",
        target().label().c_str(), s.label, got.max_depth,
        static_cast<long long>(got.max_depth_cell), want.max_depth,
        static_cast<long long>(want.max_depth_cell), got.max_speed,
        static_cast<long long>(got.max_speed_cell), want.max_speed,
        static_cast<long long>(want.max_speed_cell), static_cast<long long>(got.bad_cell),
        static_cast<long long>(want.bad_cell), got.water_volume, want.water_volume, vol_rel,
        target().backend == "cpu" ? "0" : "1e-6");
    const bool cells = got.max_depth_cell == want.max_depth_cell &&
                       got.max_speed_cell == want.max_speed_cell && got.bad_cell == want.bad_cell;
    const bool values =
        same_bits(got.max_depth, want.max_depth) && same_bits(got.max_speed, want.max_speed);
    const bool volume = target().backend == "cpu" ? same_bits(got.water_volume, want.water_volume)
                                                  : vol_rel <= 1e-6;
    EXPECT_TRUE(cells) << s.label << ": the cells differ from the scan's";
    EXPECT_TRUE(values) << s.label << ": the largest depth or speed differs from the scan's";
    EXPECT_TRUE(volume) << s.label << ": the water volume differs from the scan's";
    differing += !(cells && values && volume);
  }
  EXPECT_EQ(differing, 0);
}

// The OpenCL backend's device buffers (Backend::device_bytes, docs/performance.md "Resident
// memory"): a 256^2 fBm terrain, 3 steps, float32, Manning n, the hardness and the rain factor
// given as one value each. The default erosion configuration (local inertial, the physical
// erosion law, conservative transport, thermal collapse) holds the kinds (1 B) and 15 fields of
// 4 B per cell: bed, the spare (the second buffer of the bed and of the sediment, and the face
// pass's south faces), the initial bed, the bed residual, depth, depth_next (which holds the
// face pass's east faces and the thermal shares while it is not read), wetness, sediment, four
// outflows, two velocities and the soil: 61 B, the CPU reference's 15 with the spare in place
// of its thermal-share field. Until
// 2026-11-28 it also held the outflows' second buffers (16 B) and the three parameters per cell
// (12 B); until 2026-11-29 the sediment's own second buffer, the two face fields and the thermal
// shares (16 B): 77 B. Water only (no erosion, no thermal collapse) it needs no soil: 14 fields,
// 57 B; the pipes, which write their outflows in place too and need no face fields, no spare:
// 13 fields, 53 B; second-order shallow water, which writes them in place too (since 2026-11-28
// 11:10), those 13, the two unit discharges and their second buffers and the first stage's
// depth: 18 fields, 73 B; on CPU devices (whole-row launches) since 2026-11-30 the spare too,
// which holds the cells' velocities for the interior kernels during the flow (depth_next_ the
// other half; PoCL's flow 5.3x faster for it, performance.md): 19 fields, 77 B. Measured on
// PoCL (2026-11-29) 64.3, 60.1, 56.0 and 76.6 (before: 80.8, 68.4, 60.1, 80.8), and 80.8 for
// the shallow water with the spare (2026-11-30): about 3.5 B per cell at this size do not grow
// with the cells (each field buffer is 4 KiB longer for its offset, stagger.hpp; the reductions'
// partials; the kinds' list of edge cells). The bounds, 68, 64, 60 and 80 B per cell (84 for the
// shallow water with whole-row launches), fail with any one field more (+4.1 B), with the
// parameters per cell (+12) or with the outflows' second buffers (+16).
// A parameter set through set_field (Manning n here) is then held per cell: +4 B, and the
// fields read back the same bits as before.
class OpenClMemory : public TargetTest {};

TEST_P(OpenClMemory, TheStateOnceAndUniformParametersAsOneRow) {
  struct Case {
    FlowScheme flow;
    bool erosion;
    double bound;  // B per cell
    const char* label;
  };
  for (const Case& c :
       {Case{FlowScheme::local_inertial, true, 68.0,
             "local inertial + erosion + transport + thermal"},
        Case{FlowScheme::local_inertial, false, 64.0, "local inertial, water only"},
        Case{FlowScheme::pipes, false, 60.0, "pipes, water only"},
        Case{FlowScheme::shallow_water, false, 80.0, "shallow water (order 2), water only"}}) {
    const bool erosion = c.erosion;
    Params p;
    p.flow.scheme = c.flow;
    if (c.flow == FlowScheme::shallow_water) p.flow.order = 2;
    p.dem.synthetic = "fbm";
    p.dem.size = 256;
    p.dem.seed = 1;
    p.dem.relief = 200.0;
    p.dem.cell_size = 10.0;
    p.time.adaptive = false;
    p.time.dt = 0.5;
    p.initial.water_depth.value = 0.2;
    p.rain.rate = 20e-3 / 3600;
    p.erosion.enabled = erosion;
    p.thermal.enabled = erosion;
    p.numerics.precision = target().precision;
    validate(p, "opencl_memory");
    Simulation sim = io::make_simulation(p, target().backend);
    sim.step(3);
    const double cells = static_cast<double>(sim.grid().cells());
    const double per_cell = static_cast<double>(sim.backend().device_bytes()) / cells;
    double bound = c.bound;
#ifdef ERODEM_HAVE_OPENCL
    // on CPU devices the shallow water's velocities for its interior kernels fill the spare
    const auto* cl = dynamic_cast<const opencl::OpenClBackend*>(&sim.backend());
    if (c.flow == FlowScheme::shallow_water && cl != nullptr && cl->whole_rows()) bound += 4.0;
#endif
    const auto depth = sim.field(FieldId::water_depth);
    const auto manning = sim.field(FieldId::manning_n);
    sim.backend().set_field(FieldId::manning_n, manning);
    const double after_set = static_cast<double>(sim.backend().device_bytes()) / cells;
    std::size_t differ = 0;
    const auto manning_again = sim.field(FieldId::manning_n);
    const auto depth_again = sim.field(FieldId::water_depth);
    for (std::size_t i = 0; i < manning.size(); ++i)
      differ += !same_bits(manning[i], manning_again[i]) || !same_bits(depth[i], depth_again[i]);
    std::printf(
        "[opencl memory] %s, 256^2, 3 steps: device buffers %.1f B per cell (bound %.0f); after "
        "set_field(manning_n) %.1f (+%.2f, bounds 4.06 and 4.13: now per cell); values read back "
        "that differ %zu (bound 0)\n",
        c.label, per_cell, bound, after_set, after_set - per_cell, differ);
    EXPECT_LE(per_cell, bound);
    // one buffer of the padded grid (258^2 x 4 B: 4.06 B per DEM cell) and, where the device
    // takes the staggered offsets, 4 KiB more (4.13)
    EXPECT_GE(after_set - per_cell, 4.06);
    EXPECT_LE(after_set - per_cell, 4.13);
    EXPECT_EQ(differ, 0u);
  }
}

ERODEM_INSTANTIATE_TARGETS(BackendContract);
ERODEM_INSTANTIATE_OPENCL_TARGETS(OpenClMemory);
GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(OpenClMemory);  // a build without OpenCL

}  // namespace
}  // namespace erodem::test
