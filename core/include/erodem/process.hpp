// erodem — the process table: one entry per process of the step (MODEL.md "One step"), in step
// order, with what the rest of the code derives from it instead of writing it again: the step
// sequence and the process names (Simulation), the sweeps over the grid each process runs with
// the fields they read and write (the bench's byte model, the check that every field a sweep
// reads is provided), the ledger tallies each process books (the ledger's update), whether the
// bed changes (the gauges), and the schema section of its parameters. The per-cell physics
// stays in kernels/common/*.h; docs/architecture.md ("Adding a process") says how an entry is
// added.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "erodem/backend.hpp"
#include "erodem/grid.hpp"
#include "erodem/ledger.hpp"
#include "erodem/params.hpp"

namespace erodem {

/// How a sweep touches a field.
enum class Access : std::uint8_t {
  read,               ///< its own cell
  read_neighbours,    ///< its own cell and its neighbours (the four, or further: a halo)
  write,              ///< writes its own cell, without reading the old value
  update,             ///< reads its own cell's old value and writes the new one
  update_neighbours,  ///< reads the old values of its own cell and its neighbours (a second
                      ///< buffer, or rows behind) and writes its own cell's new one
};

/// Whether a sweep that touches a field this way writes it.
constexpr bool writes(Access a) {
  return a == Access::write || a == Access::update || a == Access::update_neighbours;
}
/// Whether a sweep that touches a field this way reads it at a neighbouring cell: the halo
/// cells of that field must then hold the neighbours' current values (halo_fields).
constexpr bool reads_neighbours(Access a) {
  return a == Access::read_neighbours || a == Access::update_neighbours;
}

/// Which cells a sweep visits: the cells of the DEM (every interior row), the ghost cells
/// around them, a list of point cells (inflows), or none per cell (bookkeeping only).
enum class Domain : std::uint8_t { cells, halo, points };

/// One field a sweep uses, by name: a field of field_table() ("bed", "water_depth", ...), or
/// a grid input or intermediate of grid_inputs() / intermediate_fields() ("kind",
/// "rain_factor", "thermal_share", "depth_flow").
struct FieldUse {
  const char* field;
  Access access;
  /// How many rows beyond its own cell's a read at neighbours (read_neighbours,
  /// update_neighbours) reaches: -1 (the default) as far as any sweep of the step may, the
  /// MPI band's halo; 0 along its own row only. Which exchanges a band may skip
  /// (exact_in_band) follows from it; a value below the cell function's true reach would leave
  /// halo rows that differ from the neighbouring band's in the run (tests/mpi.sh).
  int rows = -1;
};

/// One pass over the grid: the unit of execution. A sweep may compose the cell functions of
/// several processes (a fused pass is then one entry with the union of their uses); its bytes
/// per cell are those of its distinct fields.
struct SweepInfo {
  const char* name;  ///< e.g. "erosion"; the OpenCL kernels that run it are `opencl_kernels`
  Domain domain;
  std::vector<FieldUse> uses;
  /// The OpenCL kernels that run it over the cells (for a cells sweep: the cell kernels whose
  /// work-group limits the backend's launch geometry; reductions are the backend's own).
  std::vector<const char*> opencl_kernels;
  /// Intermediates it leaves for later sweeps of the step at no traffic of its own (the
  /// water update leaves "depth_flow", the depth it started from, in its second buffer).
  std::vector<const char*> leaves = {};
  /// Run by the backends' generic cell loop, with no code of their own (one line in
  /// kernels/cpu/sweeps.cpp names its cell function): a cells sweep over the DEM rows whose
  /// cell function and OpenCL kernel (named as the sweep) take
  ///   cell:   (int x, int y, int W, <a pointer per use, in order>, area, dt, params,
  ///            <a real* per tally of `tallies`, in order>)
  ///   kernel: (int W, int H, <a buffer per use, in order>, area, dt, params, partials, stride)
  /// where a use is "kind" or a field of field_table(), `area` the per-row cell areas (m^2),
  /// `dt` the step (s), `params` the process's struct (kernels/cell_params.hpp), and the
  /// kernel sums each tally into slot ERODEM_TALLY_<NAME> of `partials` (reduce.cl).
  bool generic = false;
  /// A generic sweep's tallies (entries of tally_table()), in the order its cell function
  /// takes them: each one of the process's tallies.
  std::vector<const char*> tallies = {};
};

/// One tally of the ledger: a volume (m^3) a process books per step, added to a Ledger
/// member. The ledger adds the tallies in the order of tally_table().
struct TallyInfo {
  const char* name;  ///< the Ledger entry's name (ledger_entries())
  double StepTally::*step;
  double Ledger::*ledger;
};

/// One field's initial values: value(cell) at each DEM cell (row-major index row * nx + col).
struct InitialField {
  FieldId id;
  std::function<double(std::size_t cell)> value;
};

struct ProcessInfo {
  Process id;
  const char* name;            ///< process_name(), the bench's row names
  const char* schema_section;  ///< the config section of its parameters ("" for none)
  /// Whether the process runs in a step with these parameters.
  bool (*enabled)(const Params&);
  /// The sweeps it runs in one step with these parameters, in order (none: nothing per cell).
  std::vector<SweepInfo> (*sweeps)(const Params&);
  /// The Ledger members its tallies are booked into (entries of tally_table()).
  std::vector<const char*> tallies;
  /// The file of kernels/opencl/ with its kernels.
  const char* opencl_source;
  /// The initial values of fields it owns (fields of field_table()), from the terrain and
  /// the parameters: Simulation sets them when it is built, before the initial ledger (a
  /// restart then replaces them), a strip of rows at a time (no whole field in double beside
  /// the state: the setup's peak). nullptr: none (the backends start every field they do not
  /// build from the terrain at 0).
  std::vector<InitialField> (*initial)(const Terrain&, const Params&) = nullptr;
};

/// Which parameter fields the terrain classes' tables write (terrain_class.h): those of a
/// parameter some class gives a value of, where no raster of it overrides the tables and the
/// process that reads it runs (docs/model.md section 3.12).
struct ClassTables {
  bool manning = false;   ///< manning_n (flow)
  bool hardness = false;  ///< hardness (erosion; not over a raster or "noise")
  bool ksat = false;      ///< infiltration_ksat
  bool soil = false;      ///< infiltration_suction_deficit and infiltration_store
  bool talus = false;     ///< talus_slope (thermal then reads it)
};
ClassTables class_tables(const Params& params);

/// Every process, in step order (the sources run after the flow: model.md section 2).
const std::vector<ProcessInfo>& process_table();
/// The entry of `p`.
const ProcessInfo& process_info(Process p);
/// Every tally of the step, in the order the ledger adds them.
const std::vector<TallyInfo>& tally_table();

/// The grid inputs every sweep may read: the cell kinds and the per-row spacings and areas,
/// and the parameter fields (rasters or uniform values).
const std::vector<std::string>& grid_inputs();

/// The processes that run in a step with `params`, in order.
std::vector<Process> step_sequence(const Params& params);
/// The sweeps of those processes, in order, each with its process.
std::vector<std::pair<Process, SweepInfo>> step_sweeps(const Params& params);

/// The passes of a step with `params`: step_sequence() cut into runs of processes that a
/// backend may run as one pass over memory (Backend::run_pass), each run in step order. With
/// `fused` false every process is a pass of its own (the readable reference path); with it,
/// the longest run of fused_passes() that the sequence holds in full at each place is one
/// pass. Which parts of a pass a backend fuses is its own choice (Backend::fused_parts: the
/// CPU reference flow + sources + water, the OpenCL backend water + erosion, both outside a
/// periodic halo and an MPI band); fused or not, the results are the same bits
/// (tests/test_fused.cpp).
std::vector<std::vector<Process>> step_passes(const Params& params, bool fused);
/// The runs of processes the table lets a backend fuse with these parameters, longest first:
/// flow, sources and water (the water update reads the outflows of the rows around it as the
/// flow leaves them), with evaporation after them where it follows the water update in the
/// sequence (erosion, transport and thermal collapse off: the water-only step) or with erosion
/// where that does (erosion reads only its own cell of what the water update writes: its
/// depth and velocities); with local inertial or pipes flow and none of the four running a
/// generic sweep.
std::vector<std::vector<Process>> fused_passes(const Params& params);
/// A pass as one sweep for the byte model: the union of its processes' cells sweeps' uses,
/// each field counted once, as read where its first use reads it and as written where any use
/// writes it (a field one sweep of the pass writes and a later one reads stays in cache).
SweepInfo pass_sweep(const std::vector<Process>& pass, const Params& params);

/// Checks that every field a sweep of the sequence reads is provided before it: a grid input,
/// a state field (fields with `state` in field_table()), or a field an earlier sweep of the
/// step writes or leaves. Throws Error(ExitCode::internal) naming the sweep and the field.
void check_sweeps(const std::vector<std::pair<Process, SweepInfo>>& sweeps);

/// The halo exchange (boundary.periodic_x; the bands of rows of the MPI domain decomposition,
/// docs/mpi.md): where the halo stands for cells of the grid itself rather than for a boundary, the
/// backends copy, after every sweep, the fields it writes or leaves into the halo cells that
/// repeat them, before a later sweep reads them at a neighbour. This is the list: every field
/// a sweep writes or updates and every intermediate it leaves, but the grid inputs it never
/// writes ("kind", the per-row sizes). A cells sweep of a process with several (thermal's
/// share then apply) is exchanged before the next one runs; the backends call it in one place,
/// Backend::run's loop over the process's sweeps (CpuBackend, OpenClBackend after_sweep).
std::vector<std::string> halo_fields(const SweepInfo& sweep);

/// The fields that something reads at a neighbouring cell in a step of `params`: those that a
/// sweep of the step (any domain) reads with read_neighbours or update_neighbours, and, with
/// sections or outlets, what their faces read at the far cell (sections.h: the four outflows,
/// the sediment, depth_flow); never the grid inputs. Only these need their halo cells current:
/// a field no one reads at a neighbour is read in the halo by nothing that reaches an owned
/// cell, so its halo may hold what the rank computed there itself (docs/mpi.md).
std::vector<std::string> neighbour_read_fields(const Params& params);

/// halo_fields(sweep) less what `needed` (neighbour_read_fields) does not hold: what the
/// backends exchange after the sweep.
std::vector<std::string> halo_fields(const SweepInfo& sweep,
                                     const std::vector<std::string>& needed);

/// What Backend::run(p) does after the process's own loops, worked out once for a run: the
/// process's sweeps and the fields to exchange after each (empty without a shared halo).
struct SweepsTail {
  std::vector<SweepInfo> sweeps;
  /// exchange[k]: after sweep k, halo_fields(sweeps[k], needed), less, for a sweep of the
  /// process's own loops, what a later one of them reads at a neighbour and leaves as it is
  /// (the loop has exchanged that already: thermal's shares before it applies them)
  std::vector<std::vector<std::string>> exchange;
  /// unsent[k]: the fields of exchange[k] that an MPI band does not receive from its
  /// neighbours after sweep k, as no later read needs more of their halo rows than the band
  /// computes itself (exact_in_band); the periodic copy of the ghost columns still takes them.
  /// Empty outside a band.
  std::vector<std::vector<std::string>> unsent;
};

/// The rows of halo an MPI band holds on either side of its own rows (kernels/band_rows.hpp):
/// 2 with local inertial and the shallow water, whose faces read the cells and faces two rows
/// away, 1 with pipes, whose sweeps read the four neighbours only.
int band_halo_rows(const Params& params);

/// The SweepsTail of every process (indexed by Process) for a run of `params`: `halo` whether
/// the halo is shared (boundary.periodic_x, MPI bands); the exchanges hold only what
/// neighbour_read_fields(params) holds. `band_halo`: the halo rows of an MPI band (0: no
/// band), for SweepsTail::unsent.
std::vector<SweepsTail> sweeps_tails(const Params& params, bool halo, int band_halo = 0);

/// Which exchanges an MPI band of `h` halo rows (band_halo_rows(params), which the boundary's
/// reach assumes) may skip (docs/mpi.md "Halo rows computed exactly"): the fields of
/// tails[p].exchange[k] (sweeps_tails) that no later read needs from the neighbouring band, by a
/// data-flow pass over the step's sweeps in the order the backends run them (a process's own loops,
/// then their exchanges, then its generic sweeps, each with its exchange). It counts, for every
/// field, how many halo rows next to the own rows hold the neighbouring band's values (e, 0 .. h):
/// an exchange makes it h; a cells sweep computes the rows 1 .. H - 2 of its band (the flow also
/// the outermost, clamped: not counted), so what it writes is exact on min(h - 1, e_f - r_f) rows,
/// over every field f it reads r_f rows away (FieldUse::rows); a sweep over the point cells leaves
/// the others as they were and keeps min(e, e_f - r_f), and one over the ghost cells (the
/// boundary's, whose ghost columns on every row of the band read along their row) min(e, e_f). A
/// read r rows away needs e >= r: where it is less, the last sweep to write the field exchanges it.
/// The start of a step takes the end of the step before, from h everywhere (the initial and
/// restarted state hold every halo row), repeated until nothing changes; the faces of sections and
/// outlets read the cell beyond them one row away before the water update and the transport
/// (Backend::run). A read before an earlier own loop of its process has exchanged what it needs
/// throws Error(internal). The result: tails[p].unsent[k], the fields of exchange[k] that no read
/// needs from the neighbour (they may be exact on fewer rows than h: none reads further), the
/// others sent as before.
void exact_in_band(const Params& params, int h, std::vector<SweepsTail>& tails);

/// The tail of Backend::run(p) in both backends, the one place of the halo exchange: after the
/// process's own loops (which exchange in between where a pass reads what an earlier one of
/// theirs wrote), the exchange of their sweeps' fields; then each generic sweep
/// (`run_generic(sweep)`) and its exchange (`exchange(fields)`), as `tail` (sweeps_tails)
/// lists them: `exchange(fields, unsent)` with `unsent` the fields of those that an MPI band
/// does not send (SweepsTail::unsent).
template <class RunGeneric, class Exchange>
void run_sweeps_tail(const SweepsTail& tail, const RunGeneric& run_generic,
                     const Exchange& exchange) {
  static const std::vector<std::string> none;
  auto unsent = [&](std::size_t k) -> const std::vector<std::string>& {
    return k < tail.unsent.size() ? tail.unsent[k] : none;
  };
  for (std::size_t k = 0; k < tail.sweeps.size(); ++k)
    if (!tail.sweeps[k].generic && !tail.exchange[k].empty()) exchange(tail.exchange[k], unsent(k));
  for (std::size_t k = 0; k < tail.sweeps.size(); ++k)
    if (tail.sweeps[k].generic) {
      run_generic(tail.sweeps[k]);
      if (!tail.exchange[k].empty()) exchange(tail.exchange[k], unsent(k));
    }
}

/// Whether a sweep of the sequence writes the bed (erosion, slope collapse): the gauges must
/// then read the bed every step.
bool bed_changes(const Params& params);
/// Whether a sweep of the sequence (on any domain) writes or updates `field`: a state field
/// none writes keeps its initial values through the run, unless changed between steps (a
/// restart, Python's set_field, the terrain-class pass).
bool step_writes(const Params& params, const std::string& field);

/// Whether process `p` with these parameters may change the volumes of material or sediment
/// (FieldStats::material_volume, sediment_volume): a sweep of it over the DEM's cells or
/// point cells writes the bed, its residual or the sediment. Sweeps over the halo write the
/// ghost cells only, which no volume counts. A backend may keep the volumes it summed last
/// until such a process runs (CpuBackend::stats_row).
bool changes_material(Process p, const Params& params);
/// changes_material of every process of the table, indexed by Process (1 or 0): what a backend
/// that keeps the volumes looks up before each process it runs.
std::vector<char> material_changers(const Params& params);
/// Whether field `id` is one of the material volume's: the bed, its residual, the sediment (a
/// backend that keeps the volumes sums them again after such a field is set).
bool material_field(FieldId id);

/// The bytes a sweep moves per cell and step: every distinct field it reads, once, plus every
/// field it writes, once; `real_bytes` (4 or 8) per field, 1 byte for the cell kind. Neighbour
/// reads count once (they hit the cache lines the sweep brings in anyway); per-row arrays and
/// sweeps over the halo or point cells count 0. Writes count no write-allocate traffic (as
/// STREAM counts). `reads` and `writes` name the fields.
struct SweepBytes {
  int read = 0, write = 0;
  std::string reads, writes;
  int total() const { return read + write; }
};
SweepBytes sweep_bytes(const SweepInfo& sweep, int real_bytes);
/// The bytes per cell of every sweep of process `p` with these parameters, together.
SweepBytes process_bytes(Process p, const Params& params, int real_bytes);
/// The driver's reductions after every step (Simulation::step: the ledger's volumes, the
/// maxima, the first bad cell), as a sweep; without `material`, the sweep of a backend that
/// keeps the material and sediment volumes while no process changes them (changes_material):
/// it reads neither the bed, its residual nor the sediment.
const SweepInfo& stats_sweep(bool material = true);

/// Every OpenCL cell kernel of any configuration: the kernels of the cells sweeps of every
/// process with either flow and either transport scheme, and of stats_sweep(), once each (the
/// OpenCL backend's work-group size must suit all of them).
std::vector<std::string> opencl_cell_kernels();
/// The OpenCL program's files in order: reduce.cl (the reductions the kernels share), each
/// process's opencl_source in step order, then edges.cl and stats.cl.
std::vector<std::string> opencl_program_order();

}  // namespace erodem
