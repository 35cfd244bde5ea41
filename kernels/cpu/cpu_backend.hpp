// erodem — the CPU reference backend: the per-cell functions of kernels/common/*.h run over
// a padded raster by OpenMP threads, one row per iteration. Reductions are summed per row
// and then in row order, so results do not depend on the number of threads.
//
// Compiled once per x86-64 level into namespace erodem::ERODEM_CPU_NAMESPACE (cpu_v2,
// cpu_v3, cpu_v4; see cpu/isa_prelude.hpp, force-included); cpu/dispatch.cpp chooses.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "band_rows.hpp"
#include "cell_params.hpp"
#include "common/compat.h"
#include "common/erosion.h"
#include "erodem/backend.hpp"
#include "erodem/grid.hpp"
#include "erodem/initial_state.hpp"
#include "erodem/params.hpp"
#include "erodem/process.hpp"
#include "field_registry.hpp"
#include "stagger.hpp"
#include "stats_merge.hpp"

/// Before a cell loop whose iterations write only their own cells: tells GCC that the
/// output arrays do not overlap the inputs, so it vectorises without alias checks.
#if defined(__GNUC__) && !defined(__clang__)
#define ERODEM_IVDEP _Pragma("GCC ivdep")
#else
#define ERODEM_IVDEP
#endif

namespace erodem {
namespace ERODEM_CPU_NAMESPACE {

/// The name of this build's instruction set in Backend::device(): "SSE4.2" (x86-64-v2),
/// "AVX2" (x86-64-v3), "AVX-512" (x86-64-v4), "native" (ERODEM_NATIVE).
extern const char* const cpu_isa_label;

/// This build's CPU backend in the precision of params.numerics.precision (the body of
/// erodem::make_cpu_backend, which picks the build).
std::unique_ptr<Backend> make_cpu_backend_isa(const Terrain& terrain, const Params& params);

template <class Real>
class CpuBackend final : public Backend {
 public:
  CpuBackend(const Terrain& terrain, const Params& params);

  std::string name() const override { return "cpu"; }
  std::string device() const override;
  void begin_step(const StepInputs& in) override;
  void run(Process p) override;
  /// Flow + sources + water (+ evaporation) as one pass (run_flow_water) where it can: local
  /// inertial or pipes, no periodic halo, no MPI band; any other part as run() of its process.
  std::vector<std::vector<Process>> fused_parts(const std::vector<Process>& pass) const override;
  void run_fused(const std::vector<Process>& part) override;
  StepResult end_step() override;
  FieldStats stats() override;
  void set_probes(const std::vector<std::int64_t>& cells,
                  const std::vector<FieldId>& fields) override;
  void set_faces(const std::vector<Face>& faces) override;
  std::vector<double> sample(const std::vector<std::int64_t>& cells, FieldId id) const override;
  std::vector<double> field(FieldId id) const override;
  std::vector<double> field_rows(FieldId id, int row0, int row1) const override;
  OwnRows own_field_rows(FieldId id, int row0, int row1) const override;
  void set_field(FieldId id, const std::vector<double>& values) override;
  void set_field_rows(FieldId id, int row0, int row1, const std::vector<double>& values) override;
  HostView host_view(FieldId id) override;
  bool keeps_material_volumes() const override { return !material_viewed_; }

  // One function per process, each in kernels/cpu/<process>.cpp.
  void run_boundary();
  void run_sources(const StepInputs& in);
  void run_flow(Real dt);
  void run_water(Real dt, StepTally& tally);
  /// The fused pass of flow, sources and water (kernels/cpu/flow.cpp): each thread walks its
  /// block of rows once, the flow's outflows of a row, then the sources one row behind and
  /// the water update two rows behind (the rows whose depths and outflows are then final);
  /// the rows beside the next block's, which its flow still reads, after all blocks. The same
  /// cell functions in the same order per cell as run_flow, run_sources and run_water: the
  /// same bits, with the state read and written once instead of three times.
  /// With `evaporation`, the evaporation of each row after its water update, and, where the
  /// evaporation ends the step, the statistics of the row as it leaves it.
  void run_flow_water(Real dt, StepTally& tally, bool evaporation);
  void run_erosion(Real dt, StepTally& tally);
  void run_erosion_physical(Real dt, StepTally& tally);
  void run_transport(Real dt, StepTally& tally);
  void run_thermal(Real dt, StepTally& tally);
  /// A generic sweep of the process table (process.hpp SweepInfo::generic), in
  /// kernels/cpu/sweeps.cpp: the cell function the list there names for it, through generic_rows.
  void run_generic(const SweepInfo& sweep, Process process, Real dt, StepTally& tally);
  /// A generic sweep made ready to run row by row: row(y) runs its cell function over padded
  /// row y (1 .. H - 2) and keeps the row's tally sums; book() adds them, in row order, to the
  /// step's tallies once every row has run.
  struct GenericRows {
    std::function<void(int)> row;
    std::function<void(StepTally&)> book;
  };
  /// The generic sweep `sweep` of `process` (its cell function from the list in sweeps.cpp),
  /// ready to run; `depth`: the array its "water_depth" use reads and writes, where that is
  /// not the depth field's (the fused pass: the water update's output before the swap).
  GenericRows generic_rows(const SweepInfo& sweep, Process process, Real dt, Real* depth = nullptr);
  template <auto Cell>
  GenericRows cell_rows(const SweepInfo& sweep, Process process, Real dt, Real* depth);
  /// The halo exchange (process.hpp halo_fields): with boundary.periodic_x, copies the named
  /// fields (of the field table, or the intermediates "depth_flow", "thermal_share") into the
  /// ghost columns that repeat the opposite DEM columns; in a band of an MPI run, receives
  /// the halo rows from the neighbouring ranks (exchange_fields), but those of `unsent`, whose
  /// halo rows no later read needs from them (SweepsTail::unsent); nothing otherwise.
  void exchange_halo(const std::vector<std::string>& names,
                     const std::vector<std::string>& unsent = {});
  /// The halo exchange of padded fields (W_ x H_ each): their periodic ghost columns, then (a
  /// band of an MPI run) their band_.halo rows on either side from the neighbouring ranks, all
  /// the fields in one message each way.
  void exchange_fields(const std::vector<Real*>& fields) { exchange_fields(fields, fields); }
  /// The same, the periodic ghost columns of `copied` and the halo rows of `sent`.
  void exchange_fields(const std::vector<Real*>& copied, const std::vector<Real*>& sent);

 private:
  using Kind = cell::erodem_kind_t;
  /// Index of padded cell (x, y).
  std::size_t at(int x, int y) const {
    return static_cast<std::size_t>(x) + static_cast<std::size_t>(y) * W_;
  }
  /// Index in the padded raster (the band's, in an MPI run) of DEM cell `cell` (row-major
  /// (ny, nx)), which the raster holds (holds()).
  std::size_t padded(std::int64_t cell) const {
    return static_cast<std::size_t>(band_.padded(cell, nx_));
  }
  /// Local inertial or pipes: the new outflows of every padded row over the old ones in
  /// flux_ (in place, as the shallow-water scheme's too), each thread walking its
  /// block [y0, y1) of for_row_blocks top to bottom and calling after_row(y, y0, y1) once row
  /// y's outflows are stored (kernels/cpu/flow.cpp).
  template <class AfterRow>
  void flow_blocks(Real dt, const AfterRow& after_row);
  /// The rain on padded row y (1 .. H - 2), then the step's inflows at that row in the order
  /// of the step's list (`point_rows_`: the inflows' rows and indices, sorted by row).
  void sources_row(int y, Real dt, Real rate);
  /// Adds inflow `p` of the step to its cell's depth and sediment.
  void add_inflow(const PointSource& p);
  /// The water update of padded row y (1 .. H - 2) from the outflows `out` (left, right, top,
  /// bottom) into depth_next_ and the velocities, its tallies into row_sums_a_/b_/c_[y].
  void water_row(int y, Real dt, const std::array<const Real*, 4>& out);
  /// The statistics (stats()) of padded row y (1 .. H - 2) with the depths `depth`; the row's
  /// material and sediment volumes summed and kept in material_rows_, or, where
  /// `material_known`, taken from there.
  /// Cells per chunk of stats_row's maxima (a multiple of 16: whole vectors of row_pass's
  /// lanes), and at most this many cells searched for the one holding a row's largest value.
  static constexpr int kStatsChunk = 128;
  RowStats stats_row(int y, const Real* depth, bool material_known);
  /// Whether material_rows_ hold the volumes of the bed and sediment as they are now.
  bool material_known() const { return material_known_ && !material_viewed_; }
  /// Adds the water update's row sums to the step's tallies.
  void book_water_rows(Real dt, StepTally& tally);
  /// Whether the padded raster holds DEM cell `cell` (always, but in a band of an MPI run:
  /// its rows and its halo rows), and whether this rank owns it (its rows).
  bool holds(std::int64_t cell) const { return band_.holds(cell, nx_); }
  bool owns(std::int64_t cell) const { return band_.owns(cell, nx_); }
  /// value(cell) of the cells this rank owns, gathered from every rank into the order of
  /// `cells` (in one process: value(cell) of each).
  template <class F>
  std::vector<double> gather_cells(const std::vector<std::int64_t>& cells, const F& value) const;
  /// Calls f(y) for the padded rows [y0, y1) on the backend's threads.
  template <class F>
  void for_rows(int y0, int y1, const F& f) const {
#pragma omp parallel for schedule(static) num_threads(threads_)
    for (int y = y0; y < y1; ++y) f(y);
  }
  /// The calling thread's block [y0, y1) of the padded rows [0, H) in a parallel region: the
  /// team's threads take contiguous blocks in thread order (all rows without OpenMP).
  static std::pair<int, int> thread_row_block(int H) {
#ifdef _OPENMP
    const int t = omp_get_thread_num(), nt = omp_get_num_threads();
#else
    const int t = 0, nt = 1;
#endif
    return {static_cast<int>(static_cast<long>(H) * t / nt),
            static_cast<int>(static_cast<long>(H) * (t + 1) / nt)};
  }
  /// Calls f(y0, y1) once on each of the backend's threads with its block of the padded rows
  /// [0, H), the static blocks schedule(static) gives; for loops that walk their block top to
  /// bottom, carrying rows of faces from one row to the next.
  template <class F>
  void for_row_blocks(int H, const F& f) const {
#pragma omp parallel num_threads(threads_)
    {
      const auto [y0, y1] = thread_row_block(H);
      if (y0 < y1) f(y0, y1);
    }
  }
  /// Runs row(y, out) for the interior padded rows 1 .. H - 2 on the backend's threads, each
  /// over its block of rows top to bottom, where row y computes the new values of one field
  /// into `out` (W values; columns 1 .. W - 2) from the old values of rows y - 1 .. y + 1 of
  /// `field`, and writes them into `field` once no row reads row y's old values: row y - 1
  /// as soon as row y is computed, each block's first and last rows (which the neighbouring
  /// blocks read) after every thread has computed its block. The bits of the same loop into a
  /// second buffer swapped in, without that buffer (the bed's and the sediment's: 8 B per cell
  /// of a float32 run; docs/performance.md "Resident memory per cell").
  template <class RowFn>
  void rows_in_place(Real* field, const RowFn& row) const {
    const int W = W_, H = H_;
#pragma omp parallel num_threads(threads_)
    {
      const std::pair<int, int> block = thread_row_block(H - 2);
      const int y0 = block.first + 1, y1 = block.second + 1;
      const auto rows = row_scratch(3 * W);
      Real *first = rows.get(), *prev = first + W, *cur = prev + W;
      const auto write_back = [&](int y, const Real* r) {
        std::copy(r + 1, r + W - 1, field + static_cast<std::size_t>(y) * W + 1);
      };
      for (int y = y0; y < y1; ++y) {
        row(y, cur);
        if (y == y0) {
          std::swap(first, cur);  // the block's first row waits for the barrier
          continue;
        }
        if (y - 1 > y0) write_back(y - 1, prev);
        std::swap(prev, cur);
      }
#pragma omp barrier
      if (y0 < y1) write_back(y0, first);
      if (y1 - 1 > y0) write_back(y1 - 1, prev);
    }
  }
  /// Sums per-row partial sums (one per padded row) in row order (deterministic for any
  /// thread count): in an MPI run, those of the rows of every rank in global row order.
  double sum_rows(const std::vector<double>& rows) const;
  /// The partial sums of sum_row: cell x of a row goes to partial x % kSumLanes.
  static constexpr std::size_t kSumLanes = 16;
  /// The kSumLanes partial sums of a row combined in a fixed tree (lanes j and j + 8, then
  /// j and j + 4, j and j + 2, the last two).
  static double sum_lanes(const double* p) {
    double q[8];
    for (std::size_t j = 0; j < 8; ++j) q[j] = p[j] + p[j + 8];
    for (std::size_t j = 0; j < 4; ++j) q[j] += q[j + 4];
    return (q[0] + q[2]) + (q[1] + q[3]);
  }
  /// Sums a row of per-cell values in double in a fixed order: kSumLanes interleaved partial
  /// sums (cell x into partial x % kSumLanes, in x order), combined by sum_lanes. Independent
  /// chains of adds that the compiler keeps in vector registers (each partial is added to in
  /// the same order whatever the vector width, so the v2, v3 and v4 builds give the same bits);
  /// the same order on every run and for any number of threads (performance.md, "Sums in
  /// sixteen lanes").
  static double sum_row(const Real* v, std::size_t n) {
    const std::size_t whole = n - n % kSumLanes;
    double p[kSumLanes] = {};
    for (std::size_t x = 0; x < whole; x += kSumLanes)
      for (std::size_t j = 0; j < kSumLanes; ++j) p[j] += static_cast<double>(v[x + j]);
    for (std::size_t x = whole; x < n; ++x) p[x - whole] += static_cast<double>(v[x]);
    return sum_lanes(p);
  }
  /// sum_row of a row whose values are +0 but at the columns xs[0 .. count) (increasing), where
  /// they are value(x): the same bits, since adding +0 leaves a partial sum that started at +0
  /// as it is (no partial is ever -0). For a tally that only a few cells of a row have.
  template <class Value>
  static double sum_row_at(const int* xs, std::size_t count, const Value& value) {
    double p[kSumLanes] = {};
    for (std::size_t k = 0; k < count; ++k)
      p[static_cast<std::size_t>(xs[k]) % kSumLanes] += static_cast<double>(value(xs[k]));
    return sum_lanes(p);
  }
  /// The kinds of padded rows y - 1 .. y + 1 as int, in this thread's scratch (kept from call
  /// to call; valid until its next call): a pointer to row y's first. Cell loops that compare
  /// their neighbours' kinds take these: with the kinds' bytes, GCC works on 32 or 64 cells at
  /// once, widens every compare and spills throughout (performance.md "The CPU water update",
  /// "The statistics in one pass").
  const int* int_kinds_around(int y) const {
    thread_local std::vector<int> kinds;
    const std::size_t w = static_cast<std::size_t>(W_);
    if (kinds.size() < 3 * w) kinds.resize(3 * w);
    const Kind* from = kind_.data() + (static_cast<std::size_t>(y) - 1) * w;
    for (std::size_t k = 0; k < 3 * w; ++k) kinds[k] = from[k];
    return kinds.data() + w;
  }
  /// `count` rows of W values for a row's per-cell tallies, in this thread's scratch (kept from
  /// call to call; valid until its next call, so a row's function takes its rows once): each
  /// row's first and last value (the ghosts) +0, the others as the last call left them, for the
  /// cell loop to write (every cell function writes its tallies at each x in 1 .. W - 2) and
  /// sum_row to sum. An allocation and a zeroing per row took about 4 % of the water-only step.
  Real* tally_rows(int count) const {
    thread_local std::vector<Real> rows;
    const std::size_t w = static_cast<std::size_t>(W_), n = static_cast<std::size_t>(count) * w;
    if (rows.size() < n) rows.resize(n);
    for (std::size_t r = 0; r < n; r += w) rows[r] = rows[r + w - 1] = Real(0);
    return rows.data();
  }
  /// `n` zeros: rows_in_place's row buffers, one per thread and pass. (Per-row tallies take
  /// tally_rows.)
  static std::unique_ptr<Real[]> row_scratch(int n) {
    return std::unique_ptr<Real[]>(new Real[static_cast<std::size_t>(n)]());
  }
  /// A per-cell field: each array at its own offset modulo 4 KiB (stagger.hpp).
  using Field = std::vector<Real, StaggeredAllocator<Real>>;
  // Uniform parameters (docs/architecture.md): Manning n, hardness and the rain factor are
  // each held as one row of W copies where the run gives one value for every cell (no raster,
  // noise or class sets it), as an array of the padded raster otherwise; the cell functions
  // that read them take the pitch, W or 0 (param_index, common/compat.h), from their
  // parameter structs (set_param_pitches).
  /// Whether `f` is a parameter held as one row (every other field holds W x H_ values, and
  /// H_ >= 3: the padded raster, or a band with its halo rows).
  bool uniform(const Field& f) const {
    return f.size() == static_cast<std::size_t>(W_);
  }
  /// The values per row of `f` (its pitch): 0 for a uniform parameter, W otherwise.
  int pitch(const Field& f) const {
    return uniform(f) ? 0 : W_;
  }
  /// The index in `f` of padded cell p.
  std::size_t param_at(const Field& f, std::size_t p) const {
    return uniform(f) ? p % W_ : p;
  }
  /// A parameter from the padded state: one row where uniform, else every cell's value.
  void take_parameter(Field& dst, CellParameter& src, bool per_cell);
  /// Field `f` (a uniform parameter) as an array of every cell (before anything writes it),
  /// and the pitches updated.
  void make_per_cell(Field& f);
  /// The parameter structs' pitches from how the three parameters are held now.
  void update_param_pitches() {
    set_param_pitches(cell_, pitch(manning_), pitch(hardness_), pitch(rain_factor_));
  }
  /// The storage of field `id` to write or bind: a uniform parameter is first made an array
  /// of every cell (make_per_cell).
  Field* field_storage(FieldId id) {
    Field* f = fields_.get(id);
    if (f && uniform(*f)) make_per_cell(*f);
    return f;
  }
  friend class FieldRegistry<Field>;
  /// Field `id` (stored in `src`, from field_storage) at padded cell `p`, as field() gives
  /// it: the bed with its residual, the erosion from the bed pair and the initial bed, the bed
  /// shear stress from the depth, the velocities and Manning n (in double, as OpenCL's host).
  double value_at(FieldId id, const Field* src, std::size_t p) const {
    if (id == FieldId::shear_stress)
      return cell::bed_shear_stress<double>(
          depth_[p], velocity_x_[p], velocity_y_[p], manning_[param_at(manning_, p)],
          params_.flow.water_density, params_.flow.gravity, params_.numerics.velocity_min_depth);
    // the bed and the erosion include the bed's residual (exact in double)
    const double lo = static_cast<double>(bed_residual_[p]);
    return !src ? (static_cast<double>(bed0_[p]) - static_cast<double>(bed_[p])) - lo
           : id == FieldId::bed ? static_cast<double>(bed_[p]) + lo
                                : static_cast<double>((*src)[param_at(*src, p)]);
  }

  Params params_;
  CellParams<Real> cell_;  // the processes' run constants (cell_params.hpp)
  int nx_, ny_, W_, H_;    // the DEM (all of it) and the padded raster (a band's in MPI)
  // The padded rows held: all; a band's in an MPI run (band_rows.hpp, docs/mpi.md). H_ is
  // band_.rows.
  BandRows band_;
  std::vector<Real> halo_buffer_;  // exchange_fields: send up, receive up, send/receive down
  int threads_;
  bool periodic_ = false;  // boundary.periodic_x (PaddedState::periodic_x)
  // By Process: run()'s sweeps and what the halo exchanges after each, only fields read at a
  // neighbour (process.hpp sweeps_tails, neighbour_read_fields), worked out once
  std::vector<SweepsTail> tails_;
  std::vector<Kind> kind_;
  std::vector<Real> dx_, dy_, area_;  // per padded row
  // The bed is the pair bed_ + bed_residual_ (common/compensated.h); the residual is only
  // read and written at its own cell, so one buffer.
  // bed_next_ stays empty: erosion and thermal collapse update the bed in place
  // (rows_in_place); sediment_next_ holds the semi-Lagrangian transport's new sediment (the
  // conservative one updates it in place). FieldRegistry binds them as the twins of the bed
  // and the sediment, which set_field skips while empty.
  Field bed_, bed_next_, bed0_, bed_residual_;
  Field depth_, depth_next_;  // after `water`, depth_next_ holds the depth the water update
                              // started from (used by conservative transport)
  Field sediment_, sediment_next_;
  // left, right, top, bottom (m^3/s), updated in place by every scheme (local inertial and
  // pipes: flow_blocks; shallow water reads none of the previous step's)
  std::array<Field, 4> flux_;
  Field velocity_x_, velocity_y_;
  Field hardness_, manning_, wetness_, rain_factor_, thermal_share_;  // parameters: uniform()
  Field stage_depth_;  // shallow water, second order: the depth after Heun's first stage
  // Every field's storage by FieldId: the members above, and an array (zeros) for any other
  // field of ERODEM_FIELDS (field_registry.hpp).
  FieldRegistry<Field> fields_;
  std::vector<double> row_sums_a_, row_sums_b_, row_sums_c_;  // scratch for per-row reductions
  // The active cells beside a ghost or a wall, the only ones with a water exchange through the
  // domain's faces: their columns, row by row (edge_x_[edge_row_[y] .. edge_row_[y + 1]) for
  // padded row y). The kinds never change.
  std::vector<int> edge_x_, edge_row_;
  // 1 where the cells 1 .. W - 2 of padded row y are all active (row_active_[y]; the kinds
  // never change; all 0 under ERODEM_CPU_ACTIVE_ROWS=0): their loops may take the kinds as
  // constants (flow.cpp runs_of_active_kinds, performance.md "Rows of active cells").
  // rows_active(y0, y1): so are those of rows y0 .. y1, all inside the raster.
  // all_active_around(y): rows y - 1 .. y + 1, so each cell 2 .. W - 3 of row y and its four
  // neighbours are active.
  std::vector<unsigned char> row_active_;
  bool rows_active(int y0, int y1) const {
    if (y0 < 0 || y1 > H_ - 1) return false;
    for (int y = y0; y <= y1; ++y)
      if (!row_active_[static_cast<std::size_t>(y)]) return false;
    return true;
  }
  bool all_active_around(int y) const {
    return rows_active(y - 1, y + 1);
  }
  std::vector<std::vector<double>> row_sums_;  // per tally of a generic sweep (sweeps.cpp)
  std::vector<std::pair<int, std::size_t>> point_rows_;  // run_flow_water: (row, inflow index)
  // The fused pass with evaporation, when it ends the step (stats_in_pass_), takes the
  // statistics of each row it leaves (pass_stats_rows_, row y at y - 1); end_step uses them
  // while pass_stats_ holds (nothing ran after it).
  bool stats_in_pass_ = false, pass_stats_ = false;
  std::vector<RowStats> pass_stats_rows_;
  // The material and sediment volumes (m^3) of each padded row 1 .. H - 2 (row y at y - 1) as
  // stats_row last summed them. They hold while material_known_: every row summed since the
  // last process that may change them ran (changes_material_, by Process: the process table's
  // changes_material) and the bed, its residual or the sediment was last set (material_field). A
  // host view of the bed or the sediment (host_view) can be written at any time, so after one they
  // are summed every time (material_viewed_). Kept, they are the sums of the same values in the
  // same order: the same bits. A water-only step then reads 12 B per cell less in float32 (the bed,
  // its residual and the sediment; performance.md "Volumes that did not change").
  struct MaterialRow {
    double material = 0, sediment = 0;
  };
  std::vector<MaterialRow> material_rows_;
  std::vector<char> changes_material_;
  bool material_known_ = false, material_viewed_ = false;
  // The step under way (begin_step .. end_step): its inputs and its tallies so far.
  StepInputs step_inputs_;
  StepTally step_tally_;
  bool in_step_ = false;
  // The probes (set_probes): DEM cells and the fields end_step samples at them.
  std::vector<std::int64_t> probe_cells_;
  std::vector<FieldId> probe_fields_;
  // The faces of the sections and outlets (set_faces, common/sections.h): their codes and
  // what the step moved through them, measured before the water update and the transport
  // from the arrays those read.
  // In an MPI band: the codes of the band's own faces in its padded raster, -1 for the
  // others'; face_owner_ the rank of each (all 0 in one process).
  std::vector<int> face_codes_, face_owner_;
  std::vector<double> face_water_, face_sediment_;
  /// A value per face, every face's from its owner (the band's own in one process).
  std::vector<double> gather_faces(const std::vector<double>& values) const;
  void measure_water_faces();
  void measure_sediment_faces();
};

}  // namespace ERODEM_CPU_NAMESPACE
}  // namespace erodem
