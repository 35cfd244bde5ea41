// erodem — the interface every compute backend (CPU reference, OpenCL) implements. The
// simulation driver runs a backend through the step sequence of MODEL.md one process at a
// time, so each process can be timed, switched off or compared on its own.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "erodem/fields.hpp"
#include "erodem/ledger.hpp"

namespace erodem {

/// The processes of one step (MODEL.md "One step"). Simulation::sequence() runs them in this
/// order but for sources, which run after flow (model.md section 2).
enum class Process {
  boundary,       ///< ghost cells take the state the edge conditions give them
  sources,        ///< rain and point/line inflows
  flow,           ///< outflow fluxes (pipes or local_inertial)
  water,          ///< depth and velocity update
  erosion,        ///< erosion / deposition
  transport,      ///< suspended sediment transport
  thermal,        ///< slope collapse
  evaporation,    ///< evaporation and the wetness running mean
  snow,           ///< degree-day melt of the snow pack into the depth
  infiltration,   ///< Green-Ampt infiltration of the depth into the soil store
  terrain_class,  ///< the terrain classes and the parameter fields their tables give
};
const char* process_name(Process p);

/// Water added at one cell in this step by a point or line inflow.
struct PointSource {
  std::int64_t cell = 0;  ///< row-major DEM cell index (row * nx + col)
  double volume = 0.0;    ///< m^3 added this step
  double sediment = 0.0;  ///< m^3 of solid sediment it brings (inflow.sediment_concentration)
};

/// What a process needs to know about the current step.
struct StepInputs {
  double t = 0.0;                ///< time at the start of the step (s)
  double dt = 0.0;               ///< step (s)
  double rain_rate = 0.0;        ///< uniform rain rate this step (m/s), times the rain factor
  double air_temperature = 0.0;  ///< snow.air_temperature T_ref this step (degrees C)
  /// Level of the fixed-level cells this step (m; boundary.stage at the midpoint); NaN:
  /// boundary.sea_level.
  double boundary_level = std::numeric_limits<double>::quiet_NaN();
  std::vector<PointSource> points;  ///< inflows this step
  /// Terrain classes: classify the cells this step (a step of terrain_classes.interval), or
  /// only write the class tables from the classes held (the first step after a restart).
  bool classify = true;
};

/// Reductions over the active cells, for the ledger and the stability check.
struct FieldStats {
  double water_volume = 0.0;     ///< sum d * area (m^3)
  double material_volume = 0.0;  ///< sum (b + b_residual + s) * area (m^3)
  double sediment_volume = 0.0;  ///< sum s * area (m^3)
  double max_depth = 0.0;        ///< m
  std::int64_t max_depth_cell = -1;
  double max_speed = 0.0;  ///< m/s
  std::int64_t max_speed_cell = -1;
  std::int64_t bad_cell = -1;  ///< first cell with NaN, infinite or negative state; -1: none
};

/// A face of the grid that a section or outlet measures (sections.hpp): the east face
/// (axis 0) or the south face (axis 1) of DEM cell (col, row). col = -1 (axis 0) or row = -1
/// (axis 1) is the ghost beyond the west or north edge, so every face of the grid, the edge
/// faces included, has one name. Positive through it: eastwards (axis 0), southwards (axis 1).
struct Face {
  int col = 0;
  int row = 0;
  int axis = 0;
};

/// What one step gives back (Backend::end_step): its tallies, the statistics of the state it
/// ends in, and the probe fields at the probe cells (Backend::set_probes).
struct StepResult {
  StepTally tally;   ///< the volumes the step's processes moved, each summed as the process ran
  FieldStats stats;  ///< the reductions over the state at the end of the step (as stats())
  /// probes[k * cells + j]: probe field k at probe cell j, as field(id)[cell] would give it
  /// (the bed with its residual); empty without probes.
  std::vector<double> probes;
  /// face_water[j]: the net discharge (m^3/s) the water update moved through face j of
  /// Backend::set_faces (positive eastwards / southwards), from the outflows it applied;
  /// face_sediment[j]: the sediment flux (m^3/s of solid) through it, from the face fluxes
  /// and concentrations the transport reads (0 in a step without transport). Empty without
  /// faces.
  std::vector<double> face_water, face_sediment;
};

/// Where a backend keeps a field of the DEM grid in host memory (the CPU reference does):
/// DEM cell (row r, col c) is the element at `data + (r * row_stride + c) * element_size`
/// bytes. `data` is null where the field is not host-resident (OpenCL) or derived (erosion).
/// Valid until the next run() or set_field(): processes write into a second buffer and swap.
struct HostView {
  void* data = nullptr;
  std::size_t element_size = 0;   ///< bytes: 4 (float32) or 8 (float64)
  std::ptrdiff_t row_stride = 0;  ///< elements between the starts of two rows
};

/// Rows [row0, row1) of a field, row-major ((row1 - row0), nx), as Backend::own_field_rows
/// gives them: the rows of a strip that this process computes.
struct OwnRows {
  int row0 = 0, row1 = 0;  ///< DEM rows [row0, row1); row0 == row1: none
  std::vector<double> values;
};

/// Checks that every cell of `cells` is a DEM cell of an nx x ny grid (0 <= cell < nx ny):
/// Error(ExitCode::usage) naming `what` and the first cell that is not.
void check_cells(const std::vector<std::int64_t>& cells, int nx, int ny, const char* what);
/// Throws Error(usage) unless [row0, row1) are rows of a grid of nx x ny cells (row0 <= row1),
/// naming field `id`.
void check_row_range(FieldId id, int row0, int row1, int nx, int ny);
/// check_row_range, and Error(data) unless `count` (values given for field `id`) is
/// (row1 - row0) * nx.
void check_rows(FieldId id, int row0, int row1, std::size_t count, int nx, int ny);

/// The faces as the backends index them: 2 * (padded cell index) + axis, with the padded
/// index (col + 1) + (row + 1) * (nx + 2) of the cell west or north of the face.
/// Error(ExitCode::usage) for a face off the grid.
std::vector<int> padded_faces(const std::vector<Face>& faces, int nx, int ny);

/// Device time of one kernel (or of the reads: "read"), summed since the backend was built.
struct KernelTime {
  std::string name;
  long calls = 0;
  double seconds = 0;  ///< device time, from the profiling events (end - start)
};

class Backend {
 public:
  virtual ~Backend() = default;
  /// "cpu" or "opencl".
  virtual std::string name() const = 0;
  /// What runs the kernels, e.g. "CPU reference, float32, 2 threads".
  virtual std::string device() const = 0;
  /// Why this backend runs the simulation, in words (make_backend: "--backend cpu", or the
  /// rule of --backend auto and what it found), for the log and the result file.
  const std::string& choice_reason() const { return choice_reason_; }
  void set_choice_reason(std::string reason) { choice_reason_ = std::move(reason); }
  /// Starts a step with its inputs (time, dt, rain rate, point inflows); the step's tallies
  /// start at zero. A step begun and not ended is discarded, tallies and all.
  virtual void begin_step(const StepInputs& in) = 0;
  /// Runs one process of the step sequence with the inputs of begin_step(); its tallies
  /// stay with the backend (on OpenCL on the device) until end_step(). Outside a step:
  /// Error(ExitCode::internal).
  virtual void run(Process p) = 0;
  /// Runs a pass of step_passes() (process.hpp): consecutive processes of the sequence that
  /// the backend may run as fewer passes over memory. Each part of fused_parts(pass) in turn:
  /// a part of one process by run(), a longer one by run_fused(). The same bits as run() of
  /// each process in turn (the CPU reference fuses flow + sources + water, the OpenCL backend
  /// water + erosion).
  void run_pass(const std::vector<Process>& pass) {
    for (const auto& part : fused_parts(pass)) {
      if (part.size() == 1)
        run(part.front());
      else
        run_fused(part);
    }
  }
  /// Runs a part of a pass that fused_parts() gives as one sweep; outside a step:
  /// Error(ExitCode::internal). This default (for a backend that fuses nothing): run() of
  /// each.
  virtual void run_fused(const std::vector<Process>& part) {
    for (const Process p : part) run(p);
  }
  /// The parts of `pass` (a pass of step_passes()) that run_pass runs as one sweep each, in
  /// order, every process of the pass in one; a part of one process runs as run() runs it.
  /// This default: every process alone.
  virtual std::vector<std::vector<Process>> fused_parts(const std::vector<Process>& pass) const {
    std::vector<std::vector<Process>> parts;
    for (const Process p : pass) parts.push_back({p});
    return parts;
  }
  /// Whether run_pass(pass) runs any part of it as one sweep (fused_parts).
  bool fuses(const std::vector<Process>& pass) const {
    for (const auto& part : fused_parts(pass))
      if (part.size() > 1) return true;
    return false;
  }
  /// Whether stats() keeps the material and sediment volumes it summed last while no process
  /// that changes them (changes_material, process.hpp) has run and no bed, bed residual or sediment
  /// was set (both backends; the CPU reference no longer once it has handed out a host view of the
  /// bed or the sediment), or sums them every time: the bench's byte model of the statistics.
  virtual bool keeps_material_volumes() const { return false; }
  /// The bytes of the device buffers the backend has created so far (OpenCL; 0 where the
  /// state lives in host memory): an upper bound of what it holds on the device at once.
  virtual std::size_t device_bytes() const { return 0; }
  /// Ends the step: its tallies, the statistics of the state it ends in and the probe
  /// samples, with one wait for the device (OpenCL: one batch of reads). Outside a step:
  /// Error(ExitCode::internal).
  virtual StepResult end_step() = 0;
  /// Reductions over the current state, outside the steps: at the start, after set_field()
  /// or a restore (a step's come with end_step()).
  virtual FieldStats stats() = 0;
  /// Registers the probes every end_step() samples: `fields` at the DEM cells `cells`
  /// (row-major indices row * nx + col), in StepResult::probes, field by field. Replaces
  /// the earlier probes; empty lists: none. A cell off the grid: Error(ExitCode::usage).
  virtual void set_probes(const std::vector<std::int64_t>& cells,
                          const std::vector<FieldId>& fields) = 0;
  /// Registers the faces every step measures (StepResult::face_water, face_sediment).
  /// Replaces the earlier ones; empty: none. A face off the grid: Error(ExitCode::usage).
  virtual void set_faces(const std::vector<Face>& faces) = 0;
  /// `id` at the DEM cells `cells` now, each as field(id)[cell] gives it, without reading
  /// the whole field (a wait for the device on OpenCL). A cell off the grid:
  /// Error(ExitCode::usage).
  virtual std::vector<double> sample(const std::vector<std::int64_t>& cells, FieldId id) const = 0;
  /// Waits until every process run so far has finished (for timing; a no-op on the CPU).
  virtual void finish() {}
  /// Device time per kernel and for the reads, where the backend measures it (OpenCL with
  /// ERODEM_OPENCL_PROFILE=1: a profiling event on every launch and read; `erodem bench`
  /// prints them), by name; empty elsewhere. Complete after finish().
  virtual std::vector<KernelTime> kernel_times() const { return {}; }
  /// A field of the DEM grid, row-major (ny, nx), converted to double: field_rows(id, 0, ny).
  virtual std::vector<double> field(FieldId id) const = 0;
  /// Rows [row0, row1) of field(id), row-major ((row1 - row0), nx), the same values: what the
  /// result writer takes a strip at a time, so that no whole field in double is held beside
  /// the state (8 B per cell at every snapshot). Collective in an MPI run, as field() is.
  virtual std::vector<double> field_rows(FieldId id, int row0, int row1) const = 0;
  /// The rows of field_rows(id, row0, row1) that this process computes, without any
  /// communication: in an MPI band the rows of [row0, row1) it owns (none where the band
  /// misses them), else all of them. Each rank of an MPI run writes these into the one result
  /// file (parallel HDF5, docs/mpi.md), so no field is gathered to every rank.
  virtual OwnRows own_field_rows(FieldId id, int row0, int row1) const {
    return {row0, row1, field_rows(id, row0, row1)};
  }
  /// Replaces a field of the DEM grid (row-major (ny, nx)): set_field_rows(id, 0, ny, values).
  virtual void set_field(FieldId id, const std::vector<double>& values) = 0;
  /// Replaces rows [row0, row1) of a field of the DEM grid (`values` row-major, (row1 - row0)
  /// x nx): a field a strip at a time. A field not made yet stays unmade where the strip is
  /// all +0 (what its reads give), so strips give the same field as one whole-field call.
  virtual void set_field_rows(FieldId id, int row0, int row1,
                              const std::vector<double>& values) = 0;
  /// The field in host memory, to read or write in place; empty where it is not there.
  virtual HostView host_view(FieldId) { return {}; }

 private:
  std::string choice_reason_;
};

}  // namespace erodem
