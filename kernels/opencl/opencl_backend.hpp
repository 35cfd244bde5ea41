// erodem — the OpenCL backend (private to erodem::kernels): RAII handles of the OpenCL C API,
// the program assembled from the embedded sources, the per-device runtime shared by backends,
// and the backend class. The per-cell formulas are those of kernels/common/*.h; the kernels
// of kernels/opencl/*.cl only index cells and call them, mirroring the CPU loops. Defined in
// errors.cpp, program.cpp, runtime.cpp, memory.cpp, launch.cpp and opencl_backend.cpp.
#pragma once

#ifndef CL_TARGET_OPENCL_VERSION
#define CL_TARGET_OPENCL_VERSION 120
#endif
#include <CL/cl.h>

#include <array>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "band_rows.hpp"
#include "cell_params.hpp"
#include "erodem/backend.hpp"
#include "erodem/backends.hpp"
#include "erodem/grid.hpp"
#include "erodem/initial_state.hpp"
#include "erodem/params.hpp"
#include "erodem/process.hpp"
#include "field_registry.hpp"

namespace erodem::opencl {

/// Name of an OpenCL error code, e.g. "CL_OUT_OF_RESOURCES".
const char* error_name(cl_int code);
/// Throws Error(ExitCode::internal) naming `what` and the error when code != CL_SUCCESS.
void check(cl_int code, const char* what);

/// The device time of a completed command (s), from its profiling event (end - start; 0 when
/// the device reports none), and the event released.
inline double take_event_seconds(cl_event ev) {
  cl_ulong start = 0, end = 0;
  check(clGetEventProfilingInfo(ev, CL_PROFILING_COMMAND_START, sizeof start, &start, nullptr),
        "clGetEventProfilingInfo");
  check(clGetEventProfilingInfo(ev, CL_PROFILING_COMMAND_END, sizeof end, &end, nullptr),
        "clGetEventProfilingInfo");
  clReleaseEvent(ev);
  return end > start ? 1e-9 * static_cast<double>(end - start) : 0.0;
}

/// Owns one OpenCL object and releases it once (move-only).
template <class T, cl_int(CL_API_CALL* Release)(T)>
class Handle {
 public:
  Handle() = default;
  explicit Handle(T h) : h_(h) {}
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  Handle(Handle&& o) noexcept : h_(std::exchange(o.h_, nullptr)) {}
  Handle& operator=(Handle&& o) noexcept {
    if (this != &o) {
      reset();
      h_ = std::exchange(o.h_, nullptr);
    }
    return *this;
  }
  ~Handle() { reset(); }
  void reset() {
    if (h_) Release(h_);
    h_ = nullptr;
  }
  T get() const { return h_; }
  explicit operator bool() const { return h_ != nullptr; }
  friend void swap(Handle& a, Handle& b) noexcept { std::swap(a.h_, b.h_); }

 private:
  T h_ = nullptr;
};

using Context = Handle<cl_context, clReleaseContext>;
using Queue = Handle<cl_command_queue, clReleaseCommandQueue>;
using Program = Handle<cl_program, clReleaseProgram>;
using Kernel = Handle<cl_kernel, clReleaseKernel>;
using Buffer = Handle<cl_mem, clReleaseMemObject>;
using Event = Handle<cl_event, clReleaseEvent>;

/// Where a line of the assembled program came from.
struct SourceOrigin {
  std::string file;  ///< embedded file name, e.g. "flow.h"
  int line = 0;      ///< 1-based line in that file
};

/// The program text: every kernels/opencl/*.cl with its #include "x.h" lines replaced by the
/// embedded headers (each header once), and the origin of every line.
struct ProgramSource {
  std::string text;
  std::vector<SourceOrigin> origin;  ///< origin[k]: line k + 1 of text
};

/// Assembles the program from the embedded sources. Throws Error(internal) on an #include
/// of a file that is not embedded.
ProgramSource assemble_program();

/// The build log with every "<file>:<line>:<col>:" mapped back to the original file and
/// line, followed by that line of source.
std::string annotate_build_log(const std::string& log, const ProgramSource& src);

/// One device with its context and built program, shared by the backends that run on it.
struct Runtime {
  ClDeviceInfo info;
  cl_platform_id platform = nullptr;
  cl_device_id device = nullptr;
  Context context;
  Program program;
  bool fp64 = false;
  std::size_t max_work_group = 1;
  /// CL_DEVICE_MEM_BASE_ADDR_ALIGN in bytes: the alignment of a sub-buffer's origin.
  std::size_t base_align = 4096;
  /// CL_DEVICE_MAX_MEM_ALLOC_SIZE in bytes: the largest buffer.
  std::size_t max_alloc = 0;
  /// Built for launches of whole rows (ERODEM_WHOLE_ROWS: every cell kernel's launches cover
  /// the row exactly, whole_row_launch; the kernels then need no per-work-item bound check).
  bool whole_rows = false;
  std::string options;  ///< the build options
};

/// Builds the program on the runtime's device; throws Error(internal) with the annotated
/// build log on failure. ERODEM_OPENCL_DUMP=dir writes the source and options there.
void build_program(Runtime& rt);

/// How whole-row launches cover a padded row of W cells (ERODEM_WHOLE_ROWS): work-groups of
/// `group` work-items from column 0, then, where `tail` > 0, one work-group of the last `tail`
/// columns (launch_rows: a second launch at that x offset). `group` is at most `limit` and
/// 1024 (the local arrays of reduce.cl) and at least min(32, W): of those sizes, the one that
/// leaves the shortest tail, the largest among equals; W itself up to 1024, else the largest
/// divisor of W where there is one (tail 0). The tail's group is usually one or two cells: a
/// padded width with no divisor in [32, 1024] (a prime, 16387 = 7 x 2341) used to take the
/// rounded launches, which PoCL leaves scalar (about 2.3x slower per cell).
struct RowLaunch {
  std::size_t group = 1;
  std::size_t tail = 0;
};
RowLaunch whole_row_launch(std::size_t W, std::size_t limit);

/// The runtime of the device chosen by ERODEM_OPENCL_DEVICE ("<platform>:<device>"
/// substrings, case-insensitive; either may be empty), else the first GPU, else the first
/// device; built once per device and launch kind and kept (runtime.cpp) until
/// release_opencl_runtimes(). On CPU devices the kernels are built for whole-row launches
/// (whole_row_launch) unless ERODEM_OPENCL_WG is set. Throws Error(usage) when there is no
/// device.
std::shared_ptr<Runtime> runtime_for(const std::string& selector);

/// The CPU reference's algorithms on an OpenCL device, float32 only. State stays on the
/// device; field() reads back, set_field() uploads, stats() reduces on the device.
class OpenClBackend final : public Backend {
 public:
  OpenClBackend(const Terrain& terrain, const Params& params, const std::string& selector = "");
  ~OpenClBackend() override;  // waits for the queue; releases the pending profiling events

  std::string name() const override { return "opencl"; }
  std::string device() const override;
  std::size_t device_bytes() const override { return device_bytes_; }
  bool keeps_material_volumes() const override { return true; }
  void begin_step(const StepInputs& in) override;
  void run(Process p) override;
  /// The water update and erosion, where one follows the other in a pass, as one kernel
  /// (run_water_erosion, fused.cl), outside a periodic halo and an MPI band; every other part
  /// as run() of its process.
  std::vector<std::vector<Process>> fused_parts(const std::vector<Process>& pass) const override;
  void run_fused(const std::vector<Process>& part) override;
  StepResult end_step() override;
  FieldStats stats() override;
  void set_probes(const std::vector<std::int64_t>& cells,
                  const std::vector<FieldId>& fields) override;
  void set_faces(const std::vector<Face>& faces) override;
  std::vector<double> sample(const std::vector<std::int64_t>& cells, FieldId id) const override;
  void finish() override;
  std::vector<KernelTime> kernel_times() const override;
  std::vector<double> field(FieldId id) const override;
  std::vector<double> field_rows(FieldId id, int row0, int row1) const override;
  OwnRows own_field_rows(FieldId id, int row0, int row1) const override;
  void set_field(FieldId id, const std::vector<double>& values) override;
  void set_field_rows(FieldId id, int row0, int row1, const std::vector<double>& values) override;
  /// How the cell kernels cover a padded row: whole rows (whole_row_launch: groups and a tail),
  /// or the rounded launches (GPUs, ERODEM_OPENCL_WG) with `group` work-items and no tail.
  bool whole_rows() const { return rt_->whole_rows; }
  RowLaunch row_launch() const { return {local_x_, tail_x_}; }

 private:
  using Real = float;
  // One function per process, each the mirror of kernels/cpu/<process>.cpp.
  void run_boundary();
  void run_sources(const StepInputs& in);
  void run_flow(Real dt);
  /// On CPU devices, for the shallow water's interior kernels: the velocities of `depth`, `qx`,
  /// `qy` (flow_shallow_water_velocities, every row) into scratch buffers that hold nothing
  /// alive during the flow (depth_next_ and the spare, as local inertial's faces); returns them
  /// (eastward, northward).
  std::pair<const Buffer*, const Buffer*> flow_velocities(const Buffer& depth, const Buffer& qx,
                                                          const Buffer& qy);
  /// A stage of the second-order shallow water (flow_shallow_water_muscl) from `depth`, `qx`,
  /// `qy` into the outflows and `qx_out`, `qy_out` (`combine`: shallow_water_muscl_cell).
  void muscl_stage(const Buffer& depth, const Buffer& qx, const Buffer& qy, Real dt, int combine,
                   const Buffer& qx_out, const Buffer& qy_out);
  void run_water(Real dt, StepTally& tally);
  void run_erosion(Real dt, StepTally& tally);
  /// run_water then run_erosion in one launch (fused.cl): the same buffers, tallies and swaps.
  void run_water_erosion(Real dt, StepTally& tally);
  /// The pieces the water update's and erosion's launches share (run_water, run_erosion,
  /// run_water_erosion): set_args with water_update's arguments first, then `rest`; what each
  /// does after its launch; the tallies each books.
  template <class... Rest>
  void set_water_args(cl_kernel k, Real dt, const Rest&... rest);
  void water_update_done(Real dt);
  static unsigned water_tally_bits();
  unsigned erosion_tally_bits() const;
  void run_transport(Real dt, StepTally& tally);
  void run_thermal(Real dt, StepTally& tally);
  /// A generic sweep of the process table (process.hpp SweepInfo::generic): its kernel with
  /// the buffers of its uses, the process's parameter struct and the tally partials, over the
  /// DEM rows; the process's tallies deferred (launch.cpp).
  void run_generic(const SweepInfo& sweep, Process process, Real dt, StepTally& tally);
  /// The halo exchange (process.hpp halo_fields) of the named fields (of the field table, or
  /// the intermediates "depth_flow", "thermal_share"): exchange_buffers on their buffers, but
  /// no halo rows of `unsent` (as the CPU reference's exchange_halo).
  void exchange_halo(const std::vector<std::string>& names,
                     const std::vector<std::string>& unsent = {});
  /// The halo exchange of padded buffers (W_ x H_ each; a parameter held as one row needs
  /// none): with boundary.periodic_x their ghost columns (halo_periodic_x, boundary.cl), then
  /// in a band of an MPI run their band_.halo rows on either side from the neighbouring
  /// ranks, every buffer's rows in one message each way, as the CPU reference's
  /// exchange_fields; nothing otherwise.
  void exchange_buffers(const std::vector<const Buffer*>& buffers) {
    exchange_buffers(buffers, buffers);
  }
  /// The same, the periodic ghost columns of `copied` and the halo rows of `sent`.
  void exchange_buffers(const std::vector<const Buffer*>& copied,
                        const std::vector<const Buffer*>& sent);
  /// halo_periodic_x on `b` with boundary.periodic_x (no exchange between ranks).
  void copy_periodic_columns(const Buffer& b);

  /// A device buffer of `bytes`, filled from `data` where given. A buffer of a field (at
  /// least kStaggerMin bytes) starts at its own offset modulo 4 KiB (stagger_next_): see
  /// make_buffer.
  Buffer make_buffer(std::size_t bytes, const void* data = nullptr);
  template <class T>
  Buffer upload(const std::vector<T>& v) {
    return make_buffer(v.size() * sizeof(T), v.data());
  }
  cl_kernel kernel(const char* name);
  /// Runs a cell kernel over the padded rows 1 .. H - 2, the rows with DEM cells (what the
  /// processes but flow touch), in interior_groups_ work-groups of (local_x_, 1). In a band
  /// of an MPI run, the halo rows first and the own rows last, so that the tally partials
  /// hold the own rows' only (launch.cpp).
  void launch_interior(cl_kernel k);
  /// Runs a cell kernel over the padded rows [y0, y1) only (global offset y0; work-groups of
  /// (local_x_, 1), and where tail_x_ > 0 a second launch of one group of (tail_x_, 1) per
  /// row at the x offset of the row's last tail_x_ columns), or with `row_group` > 0 one
  /// work-group of (row_group, 1) per row (a kernel that walks its row's columns itself:
  /// field_stats on GPUs); nothing when the range is empty. A tally kernel writes the tail
  /// groups' partials at the top of the slot (cell_group_index, reduce.cl).
  void launch_rows(cl_kernel k, int y0, int y1, std::size_t row_group = 0);
  /// Sums the water exchange (slot ERODEM_TALLY_EXCHANGE) or the sediment carried out
  /// (ERODEM_TALLY_SEDIMENT) over the cells beside ghosts into the tally partials.
  void launch_edge_tallies(int slot, Real dt);
  /// Runs a reduction kernel with `groups` groups of reduce_local_ work-items.
  void launch_reduction(cl_kernel k, std::size_t groups);
  /// Enqueues a read of `bytes` of `b` into `dst`; blocking or not.
  void read(const Buffer& b, std::size_t bytes, void* dst, bool blocking);
  /// One read of a step's batch: `bytes` of `*buffer` into `dst`.
  struct ReadRequest {
    const Buffer* buffer;
    std::size_t bytes;
    void* dst;
  };
  /// Enqueues `reads` in order, the last one blocking: when it returns, every `dst` holds its
  /// bytes. With pinned_reads_ they land in page-locked host memory (staging_), which a GPU
  /// writes directly, and are copied into their `dst` after the wait; a GPU's read into
  /// pageable memory goes through the driver's staging (performance.md, "Page-locked reads").
  void read_batch(const std::vector<ReadRequest>& reads);
  /// Where profiling (ERODEM_OPENCL_PROFILE=1): an event slot for the command about to be
  /// enqueued, booked under `name` once resolved; else nullptr (no event). The slot stays
  /// where it is until resolve_profile (a deque: later slots do not move it).
  cl_event* profile_event(const std::string& name);
  cl_event* profile_event(cl_kernel k);
  /// Books the device time of the completed commands' events (all of them after a wait).
  void resolve_profile(bool wait);
  /// `count` accumulator values (double or float on the device, as read) as doubles.
  std::vector<double> acc_values(const std::vector<unsigned char>& raw, std::size_t count) const;
  /// DEM rows [row0, row1) of field `id`, which the raster holds, row-major, composed as
  /// field() gives them.
  std::vector<double> read_rows(FieldId id, int row0, int row1) const;
  /// The raster indices of the cells of `cells` (DEM cells) this rank owns, in order, and
  /// every cell's owner into `owner` (band_rows.hpp cell_owners).
  std::vector<cl_int> owned_padded_cells(const std::vector<std::int64_t>& cells,
                                         std::vector<int>& owner) const;
  /// In a band of an MPI run, each item's value from its owner's `mine` (the values of the
  /// items this rank owns, in item order), for `repeat` runs of the items (the fields of the
  /// probes); `mine` in one process.
  std::vector<double> gather_items(const std::vector<int>& owner, std::size_t repeat,
                                   const std::vector<double>& mine) const;

  // The ledger's tallies stay on the device until end_step() (or a stats() within the step,
  // or a run() that would overwrite them): one read per step instead of one blocking
  // reduction per process. They are then added to the step's tally (step_tally_, the `tally`
  // the run_* functions get), which end_step() returns.
  /// Marks the tallies of `bits` as pending for `tally` (delivering earlier ones first).
  void defer(StepTally& tally, unsigned bits);
  /// Enqueues the reduction of the pending tally slots (no read).
  void enqueue_tally_reduction();
  /// Adds the pending tallies, read into tally_raw_ / change_raw_, to the pending StepTally.
  void deliver_tallies();
  /// Reads and delivers the pending tallies now (blocking).
  void flush_tallies();
  /// A buffer of `n_` Reals, each `value` (clEnqueueFillBuffer: no host array).
  Buffer filled_field(Real value);
  /// A buffer of `n_` Reals of zeros.
  Buffer zero_field() { return filled_field(Real(0)); }
  /// `b` made on first use, for the buffers a run may never need (the bed's and the sediment's
  /// second buffers without erosion, thermal collapse or transport; the scratch of local
  /// inertial's faces and of the shallow water's velocities): a buffer of n_
  /// Reals, a copy of `like` where given (what the cells a kernel leaves untouched must hold),
  /// else zeros. Returns `b`.
  Buffer& made(Buffer& b, const Buffer* like = nullptr);
  /// A second buffer (spare_, depth_next_) ready to take `field`'s new values: made on first
  /// use as a copy of `field`; else its rows 0 and H - 1, which the update kernels do not
  /// write, copied from `field` (scratch_rows), so that after the swap they hold the field's.
  Buffer& second_for(Buffer& second, const Buffer& field);
  /// depth_next_ as the depth the water update started from ("depth_flow": the transport, the
  /// sections' and the edges' sediment): made as a copy of the depth before any water update;
  /// Error(internal) where it holds scratch (depth_next_scratch_).
  const Buffer& depth_flow();
  /// depth_next_ to hold scratch (the face pass's east faces, the shallow water's
  /// eastward velocities on CPU devices, the thermal shares) until the next water update: made
  /// on first use, and marked so that depth_flow refuses it.
  Buffer& depth_next_as_scratch();
  /// Copies rows 0 and H - 1 of `from` into `to`: a second buffer that held scratch gets the
  /// rows its update leaves as they are.
  void scratch_rows(const Buffer& from, const Buffer& to);

  // Uniform parameters (docs/architecture.md), held as on the CPU reference: Manning n, the
  // hardness and the rain factor are each one row of W values where the run gives one value
  // for every cell (no raster, noise or terrain class sets it), else a buffer of every cell.
  // The kernels read them at param_index (common/compat.h) with the pitches of their parameter
  // structs (set_param_pitches), W or 0.
  /// The value of the parameter in `b` where it is held as one row; nullptr otherwise (every
  /// other buffer).
  const Real* uniform_value(const Buffer& b) const;
  bool uniform(const Buffer& b) const { return uniform_value(b) != nullptr; }
  /// The values per row of parameter `b`: 0 for one row, W otherwise.
  int pitch(const Buffer& b) const { return uniform(b) ? 0 : W_; }
  /// Parameter `dst` from the padded state: one row where uniform (unless `per_cell`: the
  /// terrain classes write it), else every cell's value; its array freed.
  void take_parameter(Buffer& dst, CellParameter& src, bool per_cell);
  /// Parameter `b` (one row) as a buffer of every cell, before anything writes it, and the
  /// pitches updated; nothing for any other buffer.
  void make_per_cell(Buffer& b);
  /// The parameter structs' pitches from how the three parameters are held now.
  void update_param_pitches() {
    set_param_pitches(cell_, pitch(manning_), pitch(hardness_), pitch(rain_factor_));
  }
  /// The buffer of field `id` to write or bind: a uniform parameter is first made a buffer of
  /// every cell (make_per_cell).
  Buffer* field_buffer(FieldId id) {
    Buffer* b = fields_.get(id);
    if (b && uniform(*b)) make_per_cell(*b);
    return b;
  }
  friend class FieldRegistry<Buffer>;
  /// The buffers field `id` is composed from, as field() composes them (compose): the bed
  /// and its residual; the initial bed, the bed and its residual for the erosion; depth,
  /// velocities and Manning n for the bed shear stress; else the field's own buffer.
  std::vector<const Buffer*> field_parts(FieldId id);
  /// Field `id`'s value from the floats of its parts (field_parts), `stride` apart, in double
  /// as field() gives it.
  double compose(FieldId id, const float* parts, std::size_t stride) const;
  /// Enqueues gather_cells (stats.cl): out[k * n + j] = part k of `fields` (field_parts, in
  /// order) at the `n` padded cells of `cells`.
  void enqueue_gather(const Buffer& cells, std::size_t n, const std::vector<FieldId>& fields,
                      const Buffer& out);
  /// The fields' values from the gathered floats of enqueue_gather, [field][cell].
  std::vector<double> compose_gathered(const std::vector<FieldId>& fields,
                                       const std::vector<float>& raw, std::size_t n) const;
  /// The number of parts `fields` are composed from (field_parts).
  std::size_t part_count(const std::vector<FieldId>& fields) const;
  /// The statistics of the current state with one wait, the pending tallies read and
  /// delivered with them (and, with `probes`, the probe samples into it).
  FieldStats collect(std::vector<double>* probes);

  // ERODEM_OPENCL_PROFILE=1: the queue profiles, every launch and read takes an event, and
  // finish() and end_step() book their device time per kernel name (kernel_times()).
  bool profiling_ = false;
  // read_batch's page-locked host memory: a buffer of CL_MEM_ALLOC_HOST_PTR mapped for its
  // whole life (unmapped by the destructor), grown when a batch needs more. Used where
  // ERODEM_OPENCL_PINNED=1 (off by default until measured on a GPU).
  bool pinned_reads_ = false;
  Buffer staging_;
  unsigned char* staging_ptr_ = nullptr;
  std::size_t staging_bytes_ = 0;
  std::deque<std::pair<std::string, cl_event>> profile_pending_;
  std::map<std::string, KernelTime> profile_;
  std::map<cl_kernel, std::string> kernel_names_;

  Params params_;
  CellParams<float> cell_;  // the processes' run constants (cell_params.hpp)
  std::shared_ptr<Runtime> rt_;
  Queue queue_;
  std::vector<std::pair<std::string, Kernel>> kernels_;
  int nx_, ny_, W_, H_;  // the DEM (all of it) and the padded raster (a band's in MPI)
  // The padded rows held (all; a band's in an MPI run: band_rows.hpp, docs/mpi.md)
  BandRows band_;
  std::vector<float> halo_host_;  // exchange_buffers: send up, receive up, send/receive down
  bool periodic_ = false;         // boundary.periodic_x (PaddedState::periodic_x)
  // By Process: run()'s sweeps and what the halo exchanges after each (process.hpp
  // sweeps_tails), worked out once
  std::vector<SweepsTail> tails_;
  std::size_t n_;
  std::size_t reduce_local_ = 1, reduce_groups_ = 1, acc_size_ = 8;
  // The cell kernels' groups: (local_x_, 1) work-items, groups_x_ per padded row, the last
  // one of tail_x_ work-items where that is not 0 (whole rows, whole_row_launch; the global
  // size rounded up to whole groups in the rounded launches), interior_groups_ over rows
  // 1 .. H - 2 (launch_interior; the tally kernels: one partial per group).
  std::size_t local_x_ = 1, tail_x_ = 0, groups_x_ = 1, interior_groups_ = 1;
  // field_stats' work-items per row where it runs in row launches (rounded launches, GPUs;
  // stats.cl); 0: a cell kernel like the others (whole rows, CPU devices)
  std::size_t stats_local_ = 0;
  // The active cells beside a ghost (edge_tallies): padded indices, in groups of edge_local_.
  Buffer edge_cells_;
  std::size_t edge_count_ = 0, edge_local_ = 1, edge_groups_ = 1;
  std::size_t tally_stride_ = 1;   // partials per tally slot: >= every tally kernel's groups
  std::size_t stagger_next_ = 0;   // make_buffer: the next field buffer's slot
  std::size_t device_bytes_ = 0;   // make_buffer: the bytes of every buffer created
  std::vector<double> area_host_;  // per padded row, as the device holds it (rounded to Real)
  Buffer kind_, dx_, dy_, area_;
  // the bed is the pair bed_ + bed_residual_ (common/compensated.h); the residual is read and
  // written at its own cell only, so one buffer
  Buffer bed_, bed0_, bed_residual_, depth_, sediment_;
  // The depth the water update started from, for conservative transport ("depth_flow"). From
  // the transport to the next water update nothing reads it, and it holds thermal collapse's
  // shares between its two passes ("thermal_share"), the local-inertial face pass's east
  // faces (discharge, m^3/s) until its cell pass and, on CPU devices, the shallow water's
  // eastward velocities (m/s) during its flow: second_for restores its rows 0 and H - 1,
  // which the water update does not write, before that update. Made on first use.
  Buffer depth_next_;
  bool depth_next_scratch_ = false;  // it holds faces, velocities or shares, not a depth
  // The spare: the second buffer of the bed and of the sediment (erosion, thermal collapse and
  // the transport write their field's new values into it, and the two swap: second_for), and
  // the local-inertial face pass's south faces (discharge, m^3/s) until its cell pass, or on
  // CPU devices the shallow water's northward velocities (m/s) during its flow. One
  // buffer for them all, as none of them is alive when another begins. bed_next_ is its name
  // for the field registry (the bed's twin); sediment_next_ is never made (field_registry.hpp
  // binds both names on both backends).
  Buffer spare_;
  Buffer& bed_next_ = spare_;
  Buffer sediment_next_;
  std::array<Buffer, 4> flux_;  // the outflows, updated in place by every scheme
  Buffer velocity_x_, velocity_y_, hardness_, manning_, wetness_, rain_factor_;
  Buffer stage_depth_;  // shallow water, second order: the depth after Heun's first stage
  // The parameters held as one row (uniform_value): their buffers (members above) and values.
  std::vector<std::pair<const Buffer*, Real>> uniform_;
  // Every field's buffer by FieldId: the members above, and a buffer (zeros) for any other
  // field of ERODEM_FIELDS (field_registry.hpp).
  FieldRegistry<Buffer> fields_;
  Buffer partial_a_, partial_b_, partial_cells_;
  Buffer row_sums_, row_cells_;  // stats_rows: one result per padded row 1 .. H - 2
  // The material and sediment volumes (m^3) of each padded row 1 .. H - 2 (row y at y - 1) as
  // the last field_stats that summed them gave them, as the CPU reference keeps them
  // (CpuBackend::material_rows_): they hold while material_known_ (no process that may change
  // them ran since, changes_material_ by Process, and no bed, residual or sediment was set).
  // field_stats then reads neither the bed, its residual nor the sediment, and takes a cell's state
  // from its depth: so only while material_ok_, the last full pass having found every active cell's
  // bed and sediment finite (no bad cell in any row).
  std::vector<std::pair<double, double>> material_rows_;
  std::vector<char> changes_material_;
  bool material_known_ = false, material_ok_ = false;
  Buffer tally_partials_, tally_sums_;  // [slot][tally_stride_] partials, [slot] sums
  StepTally* pending_tally_ = nullptr;
  unsigned pending_ = 0;       // bits: 1 << tally slot; kChangeBit: the transport change
  Real pending_water_dt_ = 0;  // the exchange tally is a discharge: times the step
  std::vector<unsigned char> stats_sums_raw_, stats_cells_raw_, tally_raw_, change_raw_;
  // The step under way (begin_step .. end_step): its inputs and the tallies delivered so far.
  StepInputs step_inputs_;
  StepTally step_tally_;
  bool in_step_ = false;
  // The probes (set_probes): the padded cells on the device, the fields, their gathered parts.
  // In a band of an MPI run the device gathers the probes this rank owns (probe_count_ of
  // them) and the owners (probe_owner_) give the others.
  Buffer probe_cells_, probe_out_;
  std::size_t probe_count_ = 0;
  std::vector<int> probe_owner_;
  std::vector<FieldId> probe_fields_;
  std::vector<float> probe_raw_;
  // The faces of the sections and outlets (set_faces, common/sections.h): their codes on the
  // device, what the step moved through them (section_faces in stats.cl, enqueued before the
  // water update and the transport, read with the step's statistics) and whether this step
  // measured each.
  // In a band of an MPI run, the device measures the faces this rank owns (face_count_ of
  // them; face_owner_, band_rows.hpp) and the owners give the others.
  Buffer face_codes_, face_water_out_, face_sediment_out_;
  std::size_t face_count_ = 0;
  std::vector<int> face_owner_;
  bool face_water_done_ = false, face_sediment_done_ = false;
  std::vector<float> face_water_raw_, face_sediment_raw_;
  /// Enqueues section_faces for the water (sediment = false) or the sediment.
  void measure_faces(bool sediment);
  Buffer point_cells_, point_amounts_;
  std::size_t point_capacity_ = 0;
  std::vector<cl_int> point_cells_host_;  // the sources of an upload that may be in flight
  std::vector<Real> point_amounts_host_;
  Event points_written_;
};

}  // namespace erodem::opencl
