// erodem — the OpenCL backend: the kernels of kernels/opencl/*.cl (each calling the per-cell
// functions of kernels/common/*.h) run over the padded raster, with the same buffers, swaps
// and process order as the CPU reference (kernels/cpu). This file: the backend's state set up
// on the device, the dispatch of the processes and their run_* functions, and stats();
// errors, devices, program, runtime, memory and launch.cpp hold the rest. Built when
// ERODEM_OPENCL is on (stubs.cpp otherwise).
#include "opencl/opencl_backend.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>

#include "common/compat.h"
#include "erodem/error.hpp"
#include "erodem/initial_state.hpp"
#include "erodem/parallel.hpp"
#include "erodem/process.hpp"
#include "opencl/launch.hpp"
#include "stats_merge.hpp"

namespace erodem {
namespace opencl {

namespace {

/// Values per row that stats_rows (stats.cl) writes: water, material, sediment volume, max
/// depth, max squared speed, and the two velocities of the cell of the max squared speed.
constexpr std::size_t kStatsRowValues = 7;

/// A size from the environment (the tuning variable ERODEM_OPENCL_WG), else `fallback`. Where
/// the kernels are built for rounded launches, the cell kernels' work-group is ERODEM_OPENCL_WG
/// rounded down to a power of two, by default 64 on CPU devices and 128 on others, one row high;
/// CPU devices launch whole rows (whole_row_launch) unless ERODEM_OPENCL_WG is set.
std::size_t env_size(const char* name, std::size_t fallback) {
  if (const char* env = std::getenv(name); env && *env) {
    const long v = std::strtol(env, nullptr, 10);
    if (v >= 1) return static_cast<std::size_t>(v);
  }
  return fallback;
}

/// Whether the switch `name` is on in the environment: set, not empty and not "0".
bool env_flag(const char* name) {
  const char* env = std::getenv(name);
  return env && *env && std::string(env) != "0";
}

}  // namespace

OpenClBackend::OpenClBackend(const Terrain& terrain, const Params& params,
                             const std::string& selector)
    : params_(params),
      cell_(cell_params_of<float>(params)),
      nx_(terrain.grid.nx),
      ny_(terrain.grid.ny),
      W_(terrain.grid.nx + 2),
      H_(terrain.grid.ny + 2) {
  if (params.numerics.precision == Precision::float64)
    throw Error(ExitCode::config,
                "numerics.precision: the opencl backend runs float32 (the float64 reference "
                "runs on the cpu backend: --backend cpu)");
  const auto& g = terrain.grid;
  g.validate();
  // the padded rows this backend holds: all of them, or a band's (band_rows.hpp)
  band_ = band_rows(params, ny_);
  H_ = band_.rows;
  n_ = static_cast<std::size_t>(W_) * H_;
  if (n_ > static_cast<std::size_t>(std::numeric_limits<cl_int>::max()))
    throw Error(ExitCode::data, fmt::format("backend 'opencl': a grid of {} x {} is too large "
                                            "(at most 2^31 padded cells)",
                                            nx_, ny_));
  PaddedState state = build_padded_state(terrain, params, band_.row0, band_.row0 + H_);
  periodic_ = state.periodic_x;
  tails_ = sweeps_tails(params, periodic_ || band_.banded, band_.banded ? band_.halo : 0);
  changes_material_ = material_changers(params);
  cell_.flow.periodic_x = periodic_ ? 1 : 0;

  rt_ = runtime_for(selector);
  cl_int err = CL_SUCCESS;
  profiling_ = env_flag("ERODEM_OPENCL_PROFILE");
  queue_ = Queue(clCreateCommandQueue(rt_->context.get(), rt_->device,
                                      profiling_ ? CL_QUEUE_PROFILING_ENABLE : 0, &err));
  check(err, "clCreateCommandQueue");
  acc_size_ = rt_->fp64 ? sizeof(double) : sizeof(float);
  // the step's reads into page-locked memory (read_batch) where ERODEM_OPENCL_PINNED=1: meant
  // for GPUs, not yet measured on one (performance.md, "Page-locked reads"), so off by default
  pinned_reads_ = env_flag("ERODEM_OPENCL_PINNED");

  // ---- the host state: the same padded state the CPU reference starts from ----
  // Each float64 array rounded to Real and freed at once, and each Real copy freed after its
  // last upload: the setup holds one array of Reals beside the device buffers.
  auto to_real = [](std::vector<double>& v) {
    std::vector<Real> r(v.begin(), v.end());
    std::vector<double>().swap(v);
    return r;
  };
  const std::vector<Real> dx = to_real(state.dx), dy = to_real(state.dy),
                          area = to_real(state.area);
  area_host_.assign(area.begin(), area.end());
  const std::vector<cl_uchar> kind(state.kind.begin(), state.kind.end());
  std::vector<std::uint8_t>().swap(state.kind);

  // ---- the device state ----
  // Only what every run reads is made here; the second buffers are made on first use (made(),
  // second_for(): depth_next_ too, so that the setup's peak, the terrain beside the state, does
  // not hold it), the fields of zeros by clEnqueueFillBuffer (zero_field()).
  kind_ = upload(kind);
  dx_ = upload(dx);
  dy_ = upload(dy);
  area_ = upload(area);
  {
    std::vector<Real> bed_r = to_real(state.bed);
    bed_ = upload(bed_r);
    bed0_ = upload(bed_r);
  }
  bed_residual_ = zero_field();
  {
    std::vector<Real> depth_r = to_real(state.depth);
    depth_ = upload(depth_r);
    wetness_ = upload(depth_r);
  }
  {
    std::vector<Real> sediment_r = to_real(state.sediment);
    sediment_ = upload(sediment_r);
  }
  for (int k = 0; k < 4; ++k) flux_[k] = zero_field();
  velocity_x_ = zero_field();
  velocity_y_ = zero_field();
  if (params_.flow.scheme == FlowScheme::shallow_water && params_.flow.order == 2)
    stage_depth_ = zero_field();
  // the parameters the terrain classes write are held per cell from the start
  take_parameter(manning_, state.manning, cell_.terrain_class.set_manning != 0);
  take_parameter(hardness_, state.hardness, cell_.terrain_class.set_hardness != 0);
  take_parameter(rain_factor_, state.rain_factor, false);
  update_param_pitches();
  fields_.bind(*this, [this] { return zero_field(); });

  // Reductions: a power of two of at most 256 work-items per group, fitting every reduction
  // kernel; a fixed number of groups for this grid, so the sums do not depend on timing.
  std::size_t limit = std::min(kReduceMax, rt_->max_work_group);
  for (const char* name : {"reduce_tallies", "reduce_change", "stats_rows"}) {
    std::size_t wg = 0;
    check(clGetKernelWorkGroupInfo(kernel(name), rt_->device, CL_KERNEL_WORK_GROUP_SIZE, sizeof(wg),
                                   &wg, nullptr),
          "clGetKernelWorkGroupInfo");
    limit = std::min(limit, wg);
  }
  reduce_local_ = 1;
  while (reduce_local_ * 2 <= limit) reduce_local_ *= 2;
  reduce_groups_ =
      std::clamp<std::size_t>((n_ + reduce_local_ - 1) / reduce_local_, 1, kReduceGroupsMax);
  partial_b_ = make_buffer(reduce_groups_ * acc_size_);

  // Cell kernels: work-groups of (local_x_, 1) that every cell kernel accepts: whole rows in
  // groups of local_x_ and a tail group of tail_x_ (whole_row_launch), else powers of two; a
  // fixed number of groups for this grid (the tallies' partials, summed in a fixed order).
  // Where a kernel accepts less than the device's maximum, the groups may be small: still
  // correct, slower.
  const bool cpu = rt_->info.type == "CPU";
  std::size_t cell_limit =
      std::min(rt_->whole_rows ? kCellGroupMax : kRoundedGroupMax, rt_->max_work_group);
  for (const std::string& name : opencl_cell_kernels()) {  // from the process table
    std::size_t wg = 0;
    check(clGetKernelWorkGroupInfo(kernel(name.c_str()), rt_->device, CL_KERNEL_WORK_GROUP_SIZE,
                                   sizeof(wg), &wg, nullptr),
          "clGetKernelWorkGroupInfo");
    cell_limit = std::min(cell_limit, wg);
  }
  auto pow2_at_most = [](std::size_t v) {
    std::size_t p = 1;
    while (p * 2 <= v) p *= 2;
    return p;
  };
  if (rt_->whole_rows) {
    // the program was built for it: groups that cover the row exactly, the last one shorter
    // where the size does not divide it (any size keeps the kernels correct; large groups
    // and a short tail are the fastest)
    const RowLaunch rows = whole_row_launch(static_cast<std::size_t>(W_), cell_limit);
    local_x_ = rows.group;
    tail_x_ = rows.tail;
  } else {
    local_x_ = pow2_at_most(std::min(cell_limit, env_size("ERODEM_OPENCL_WG", cpu ? 64 : 128)));
  }
  groups_x_ = (static_cast<std::size_t>(W_) + local_x_ - 1) / local_x_;
  interior_groups_ = groups_x_ * static_cast<std::size_t>(H_ - 2);
  if (!rt_->whole_rows) {
    // field_stats in row launches (stats.cl): a power of two of at most
    // ERODEM_STATS_GROUP_MAX work-items per row, no more than the row's interior cells
    std::size_t wg = 0;
    check(clGetKernelWorkGroupInfo(kernel("field_stats"), rt_->device, CL_KERNEL_WORK_GROUP_SIZE,
                                   sizeof(wg), &wg, nullptr),
          "clGetKernelWorkGroupInfo");
    stats_local_ = pow2_at_most(std::min(
        {kStatsGroupMax, rt_->max_work_group, wg, static_cast<std::size_t>(std::max(W_ - 2, 1))}));
  }
  partial_a_ = make_buffer(interior_groups_ * 5 * acc_size_);  // field_stats, per group
  partial_cells_ = make_buffer(interior_groups_ * 3 * sizeof(cl_long));
  row_sums_ = make_buffer(static_cast<std::size_t>(H_ - 2) * kStatsRowValues * acc_size_);
  row_cells_ = make_buffer(static_cast<std::size_t>(H_ - 2) * 3 * sizeof(cl_long));
  // The active cells beside a ghost, row-major: the only ones with a water exchange or a
  // sediment outflow through the domain's faces (edges.cl); of the own rows in a band of an
  // MPI run. The kinds never change.
  std::vector<cl_int> edges;
  for (int y = band_.own0; y < band_.own1; ++y)
    for (int x = 1; x < W_ - 1; ++x)
      if (cell::active_beside_inactive(x + y * W_, W_, kind.data())) edges.push_back(x + y * W_);
  edge_count_ = edges.size();
  edge_cells_ = upload(edges);
  edge_local_ = pow2_at_most(std::min<std::size_t>(cell_limit, 64));
  edge_groups_ = std::max<std::size_t>(1, (edge_count_ + edge_local_ - 1) / edge_local_);
  // Every slot holds tally_stride_ partials; what no kernel writes stays 0.
  tally_stride_ = std::max(interior_groups_, edge_groups_);
  const std::vector<unsigned char> no_partials(tally_slots() * tally_stride_ * acc_size_, 0);
  tally_partials_ = upload(no_partials);
  tally_sums_ = make_buffer(tally_slots() * acc_size_);
  run_boundary();
  exchange_halo({"bed", "water_depth", "sediment"});  // the corners after the ghost rows
}

std::string OpenClBackend::device() const {
  const std::string label = rt_->info.label() + (pinned_reads_ ? " (page-locked reads)" : "");
  if (!band_.banded) return label;
  return fmt::format("{} (a rank), {} MPI ranks in bands of rows, halo {} row{}", label,
                     parallel::size(), band_.halo, band_.halo == 1 ? "" : "s");
}

void OpenClBackend::begin_step(const StepInputs& in) {
  // the tallies of a step begun and not ended are dropped (each kernel rewrites its partials)
  pending_ = 0;
  pending_tally_ = nullptr;
  step_inputs_ = in;
  step_cell_params(cell_, in);
  step_tally_ = StepTally{};
  face_water_done_ = face_sediment_done_ = false;
  in_step_ = true;
  cell_.boundary.sea_level = static_cast<Real>(step_level(in, params_));
}

void OpenClBackend::run(Process p) {
  if (!in_step_) throw Error(ExitCode::internal, "backend: run() outside a step (begin_step)");
  if (changes_material_.at(static_cast<std::size_t>(p))) material_known_ = false;
  const StepInputs& in = step_inputs_;
  StepTally& tally = step_tally_;
  const Real dt = static_cast<Real>(in.dt);
  switch (p) {
    case Process::boundary:
      run_boundary();
      break;
    case Process::sources:
      run_sources(in);
      break;
    case Process::flow:
      run_flow(dt);
      break;
    case Process::water:
      measure_faces(false);
      run_water(dt, tally);
      break;
    case Process::erosion:
      run_erosion(dt, tally);
      break;
    case Process::transport:
      measure_faces(true);
      run_transport(dt, tally);
      break;
    case Process::thermal:
      run_thermal(dt, tally);
      break;
    default:  // the processes whose sweeps are all generic
      break;
  }
  // the generic sweeps of the process (SweepInfo::generic), after its own loops, and the halo
  // exchange after every sweep (run_thermal and run_flow exchange between their own passes)
  run_sweeps_tail(
      tails_.at(static_cast<std::size_t>(p)),
      [&](const SweepInfo& s) { run_generic(s, p, dt, tally); },
      [&](const std::vector<std::string>& names, const std::vector<std::string>& unsent) {
        exchange_halo(names, unsent);
      });
}

std::vector<std::vector<Process>> OpenClBackend::fused_parts(
    const std::vector<Process>& pass) const {
  // fused_passes() leaves out generic sweeps of both; a periodic halo, or the halo rows of an
  // MPI band, are exchanged between the two (the erosion of a halo row would read velocities
  // its band computed without the rows beyond), so they run one by one there
  std::vector<std::vector<Process>> parts;
  for (std::size_t k = 0; k < pass.size(); ++k) {
    if (pass[k] == Process::water && k + 1 < pass.size() && pass[k + 1] == Process::erosion &&
        !periodic_ && !band_.banded && params_.flow.scheme != FlowScheme::shallow_water) {
      parts.push_back({Process::water, Process::erosion});
      ++k;
      continue;
    }
    parts.push_back({pass[k]});
  }
  return parts;
}

void OpenClBackend::run_fused(const std::vector<Process>& part) {
  if (!in_step_) throw Error(ExitCode::internal, "backend: run_pass() outside a step (begin_step)");
  if (part != std::vector<Process>{Process::water, Process::erosion})
    throw Error(ExitCode::internal, "backend: no fused kernel for this part of a pass");
  for (const Process p : part)
    if (changes_material_.at(static_cast<std::size_t>(p))) material_known_ = false;
  const Real dt = static_cast<Real>(step_inputs_.dt);
  measure_faces(false);  // as run(water)
  run_water_erosion(dt, step_tally_);
  // the generic sweeps and exchanges after each (none outside a band: fused_passes)
  for (const Process p : part)
    run_sweeps_tail(
        tails_.at(static_cast<std::size_t>(p)),
        [&](const SweepInfo& s) { run_generic(s, p, dt, step_tally_); },
        [&](const std::vector<std::string>& names, const std::vector<std::string>& unsent) {
          exchange_halo(names, unsent);
        });
}

void OpenClBackend::exchange_halo(const std::vector<std::string>& names,
                                  const std::vector<std::string>& unsent) {
  if (!periodic_ && !band_.banded) return;
  std::vector<const Buffer*> buffers, sent;
  for (const std::string& name : names) {
    const Buffer* b = name == "depth_flow"      ? &depth_next_
                      : name == "thermal_share" ? &depth_next_
                      : name == "rain_factor"   ? &rain_factor_
                      : name == "manning_n"     ? &manning_
                      : name == "hardness"      ? &hardness_
                                                : field_buffer(field_info(name).id);
    if (!b)
      throw Error(ExitCode::internal, fmt::format("halo exchange: field '{}' has no buffer", name));
    buffers.push_back(b);
    if (std::find(unsent.begin(), unsent.end(), name) == unsent.end()) sent.push_back(b);
  }
  exchange_buffers(buffers, sent);
}

void OpenClBackend::exchange_buffers(const std::vector<const Buffer*>& copied,
                                     const std::vector<const Buffer*>& sent) {
  for (const Buffer* b : copied) copy_periodic_columns(*b);  // none for a one-row parameter
  std::vector<const Buffer*> held;  // one row: the same value beyond the seam and in every band
  for (const Buffer* b : sent)
    if (!uniform(*b)) held.push_back(b);
  if (!band_.banded || held.empty()) return;
  // whole padded rows (the ghost columns and the corners with them): my first band_.halo own
  // rows to the band above, my last to the band below; theirs into my halo rows. Every
  // buffer's rows in one message each way.
  const int r = parallel::rank(), ranks = parallel::size();
  const bool up = r > 0, down = r + 1 < ranks;
  const std::size_t per = static_cast<std::size_t>(band_.halo) * static_cast<std::size_t>(W_);
  const std::size_t n = per * held.size(), bytes = per * sizeof(Real);
  if (halo_host_.size() < 4 * n) {
    check(clFinish(queue_.get()), "clFinish");  // the last exchange's writes read the array
    halo_host_.resize(4 * n);
  }
  Real *send_up = halo_host_.data(), *recv_up = send_up + n, *send_down = recv_up + n,
       *recv_down = send_down + n;
  auto offset = [&](int y) { return static_cast<std::size_t>(y) * W_ * sizeof(Real); };
  for (std::size_t k = 0; k < held.size(); ++k) {
    const cl_mem b = held[k]->get();
    if (up)
      check(clEnqueueReadBuffer(queue_.get(), b, CL_FALSE, offset(band_.own0), bytes,
                                send_up + k * per, 0, nullptr, profile_event("halo")),
            "clEnqueueReadBuffer(halo)");
    if (down)
      check(clEnqueueReadBuffer(queue_.get(), b, CL_FALSE, offset(band_.own1 - band_.halo), bytes,
                                send_down + k * per, 0, nullptr, profile_event("halo")),
            "clEnqueueReadBuffer(halo)");
  }
  check(clFinish(queue_.get()), "clFinish");
  parallel::exchange(up ? send_up : nullptr, up ? recv_up : nullptr, down ? send_down : nullptr,
                     down ? recv_down : nullptr, n * sizeof(Real));
  // non-blocking: the queue is in order, and the array stays until the next exchange (above)
  for (std::size_t k = 0; k < held.size(); ++k) {
    const cl_mem b = held[k]->get();
    if (up)
      check(clEnqueueWriteBuffer(queue_.get(), b, CL_FALSE, offset(band_.own0 - band_.halo), bytes,
                                 recv_up + k * per, 0, nullptr, profile_event("halo")),
            "clEnqueueWriteBuffer(halo)");
    if (down)
      check(clEnqueueWriteBuffer(queue_.get(), b, CL_FALSE, offset(band_.own1), bytes,
                                 recv_down + k * per, 0, nullptr, profile_event("halo")),
            "clEnqueueWriteBuffer(halo)");
  }
}

void OpenClBackend::copy_periodic_columns(const Buffer& b) {
  if (!periodic_ || uniform(b)) return;  // one row: the same value on both sides of the seam
  cl_kernel k = kernel("halo_periodic_x");
  set_args(k, cl_int{W_}, cl_int{H_}, b);
  const std::size_t global = static_cast<std::size_t>(H_);
  check(clEnqueueNDRangeKernel(queue_.get(), k, 1, nullptr, &global, nullptr, 0, nullptr,
                               profile_event(k)),
        "clEnqueueNDRangeKernel(halo_periodic_x)");
}

StepResult OpenClBackend::end_step() {
  if (!in_step_) throw Error(ExitCode::internal, "backend: end_step() outside a step");
  in_step_ = false;
  StepResult r;
  r.stats = collect(&r.probes);  // delivers the step's tallies to step_tally_
  r.tally = step_tally_;
  if (band_.banded) {  // every rank's tallies of its own rows, added in rank order
    r.tally = StepTally{};
    for (const StepTally& t : parallel::allgather(std::vector<StepTally>{step_tally_})) {
#define ERODEM_ADD_TALLY(name, zero_if_absent, doc) r.tally.name += t.name;
      ERODEM_TALLIES(ERODEM_ADD_TALLY)
#undef ERODEM_ADD_TALLY
    }
  }
  // the faces' values, read in collect's batch; 0 where the step did not measure them
  std::vector<double> water(face_count_, 0.0), sediment(face_count_, 0.0);
  for (std::size_t j = 0; j < face_count_; ++j) {
    if (face_water_done_) water[j] = face_water_raw_[j];
    if (face_sediment_done_) sediment[j] = face_sediment_raw_[j];
  }
  r.face_water = gather_items(face_owner_, 1, water);
  r.face_sediment = gather_items(face_owner_, 1, sediment);
  return r;
}

void OpenClBackend::set_faces(const std::vector<Face>& faces) {
  // the faces this rank owns (all in one process), in the raster's rows
  face_owner_ = face_owners(faces, ny_);
  const std::vector<int> all = padded_faces(faces, nx_, ny_);
  std::vector<int> codes;
  for (std::size_t j = 0; j < all.size(); ++j)
    if (face_owner_[j] == parallel::rank()) codes.push_back(band_.face_code(all[j], nx_));
  face_count_ = codes.size();
  if (codes.empty()) return;
  face_codes_ = upload(std::vector<cl_int>(codes.begin(), codes.end()));
  face_water_out_ = make_buffer(face_count_ * sizeof(Real));
  face_sediment_out_ = make_buffer(face_count_ * sizeof(Real));
}

void OpenClBackend::measure_faces(bool sediment) {
  if (face_count_ == 0) return;
  // before the water update or the transport: the arrays they read (sections.h); the water's
  // faces do not read depth_flow, for which the depth stands in
  cl_kernel k = kernel("section_faces");
  set_args(k, static_cast<cl_int>(face_count_), cl_int{W_}, cl_int{sediment ? 1 : 0}, face_codes_,
           sediment_, sediment ? depth_flow() : depth_, flux_[0], flux_[1], flux_[2], flux_[3],
           sediment ? face_sediment_out_ : face_water_out_);
  const std::size_t global = face_count_;
  check(clEnqueueNDRangeKernel(queue_.get(), k, 1, nullptr, &global, nullptr, 0, nullptr,
                               profile_event(k)),
        "clEnqueueNDRangeKernel(section_faces)");
  (sediment ? face_sediment_done_ : face_water_done_) = true;
}

void OpenClBackend::run_boundary() {
  cl_kernel k = kernel("boundary_fill");
  // the first and last padded rows where they are the grid's ghost rows; in a band of an MPI
  // run they may be halo rows instead, whose ghost columns it fills as on the other rows
  const cl_int north = band_.holds_north_ghost(), south = band_.holds_south_ghost(ny_);
  set_args(k, cl_int{W_}, cl_int{H_}, kind_, bed_, depth_, sediment_, cell_.boundary, north, south);
  const std::size_t global = 2 * static_cast<std::size_t>(W_ - 2 + H_);
  check(clEnqueueNDRangeKernel(queue_.get(), k, 1, nullptr, &global, nullptr, 0, nullptr,
                               profile_event(k)),
        "clEnqueueNDRangeKernel(boundary_fill)");
}

void OpenClBackend::run_sources(const StepInputs& in) {
  const Real dt = static_cast<Real>(in.dt);
  const Real rate = static_cast<Real>(in.rain_rate);
  if (rate != Real(0)) {
    cl_kernel k = kernel("sources_rain");
    set_args(k, cl_int{W_}, cl_int{H_}, kind_, depth_, rain_factor_, cl_int{pitch(rain_factor_)},
             dt, rate);
    launch_interior(k);
  }
  if (in.points.empty()) return;
  std::vector<cl_int> cells;
  std::vector<Real> amounts, sediment_amounts;
  bool sediment = false;
  for (const auto& p : in.points) {
    // in a band of an MPI run, the inflows at the cells the raster holds (its own, and its
    // halo's, which the next exchange overwrites), as the CPU reference adds them
    if (!band_.holds(p.cell, nx_)) continue;
    const int x = static_cast<int>(p.cell % nx_) + 1,
              y = static_cast<int>(p.cell / nx_) + 1 - band_.row0;
    cells.push_back(x + y * W_);
    amounts.push_back(static_cast<Real>(p.volume / area_host_[y]));
    sediment_amounts.push_back(static_cast<Real>(p.sediment / area_host_[y]));
    sediment = sediment || p.sediment != 0;
  }
  if (cells.empty()) return;
  if (sediment)  // the sediment's amounts after the water's (sources_points)
    amounts.insert(amounts.end(), sediment_amounts.begin(), sediment_amounts.end());
  // The previous upload (if any) may still read the host vectors.
  if (points_written_) {
    cl_event e = points_written_.get();
    check(clWaitForEvents(1, &e), "clWaitForEvents");
    points_written_.reset();
  }
  point_cells_host_ = std::move(cells);
  point_amounts_host_ = std::move(amounts);
  const auto& cells_h = point_cells_host_;
  const auto& amounts_h = point_amounts_host_;
  if (cells_h.size() > point_capacity_) {
    point_capacity_ = std::max<std::size_t>(cells_h.size(), 2 * point_capacity_);
    point_cells_ = make_buffer(point_capacity_ * sizeof(cl_int));
    point_amounts_ = make_buffer(2 * point_capacity_ * sizeof(Real));  // water, sediment
  }
  // Non-blocking uploads (the queue is in order): the step does not wait for the device.
  check(clEnqueueWriteBuffer(queue_.get(), point_cells_.get(), CL_FALSE, 0,
                             cells_h.size() * sizeof(cl_int), cells_h.data(), 0, nullptr, nullptr),
        "clEnqueueWriteBuffer");
  cl_event written = nullptr;
  check(
      clEnqueueWriteBuffer(queue_.get(), point_amounts_.get(), CL_FALSE, 0,
                           amounts_h.size() * sizeof(Real), amounts_h.data(), 0, nullptr, &written),
      "clEnqueueWriteBuffer");
  points_written_ = Event(written);
  cl_kernel k = kernel("sources_points");
  set_args(k, depth_, sediment_, point_cells_, point_amounts_, static_cast<cl_int>(cells_h.size()),
           cl_int{sediment ? 1 : 0});
  const std::size_t one = 1;
  check(clEnqueueNDRangeKernel(queue_.get(), k, 1, nullptr, &one, nullptr, 0, nullptr,
                               profile_event(k)),
        "clEnqueueNDRangeKernel(sources_points)");
}

std::pair<const Buffer*, const Buffer*> OpenClBackend::flow_velocities(const Buffer& depth,
                                                                       const Buffer& qx,
                                                                       const Buffer& qy) {
  const Buffer& u = depth_next_as_scratch();
  const Buffer& v = made(spare_);
  cl_kernel k = kernel("flow_shallow_water_velocities");
  set_args(k, cl_int{W_}, cl_int{H_}, depth, qx, qy, cell_.flow, u, v);
  launch_rows(k, 0, H_);
  return {&u, &v};
}

void OpenClBackend::muscl_stage(const Buffer& depth, const Buffer& qx, const Buffer& qy, Real dt,
                                int combine, const Buffer& qx_out, const Buffer& qy_out) {
  cl_kernel k = kernel("flow_shallow_water_muscl");
  set_args(k, cl_int{W_}, cl_int{H_}, kind_, bed_, depth, qx, qy, manning_, dx_, dy_, area_, dt,
           cell_.flow, cl_int{combine}, flux_[0], flux_[1], flux_[2], flux_[3], qx_out, qy_out);
  if (!whole_rows()) {
    launch_rows(k, 0, H_);
    return;
  }
  // CPU devices: the stage's velocities first (flow_velocities), then rows 2 .. H - 3 by a
  // kernel that reads them without clamping (it vectorises), the two first and two last rows by
  // the general one; the same bits as the general kernel on every row but in the ghost columns
  // under periodic_x, which the exchange after each stage overwrites
  // (shallow_water_muscl_cell_interior)
  const auto [u, v] = flow_velocities(depth, qx, qy);
  cl_kernel in = kernel("flow_shallow_water_muscl_interior");
  set_args(in, cl_int{W_}, cl_int{H_}, kind_, bed_, depth, qx, qy, *u, *v, manning_, dx_, dy_,
           area_, dt, cell_.flow, cl_int{combine}, flux_[0], flux_[1], flux_[2], flux_[3], qx_out,
           qy_out);
  // each row by exactly one kernel (the second stage averages into what the rows hold)
  const int top = std::min(2, H_), bottom = std::max(top, H_ - 2);
  launch_rows(k, 0, top);
  launch_rows(in, top, bottom);
  launch_rows(k, bottom, H_);
}

void OpenClBackend::run_flow(Real dt) {
  if (params_.flow.scheme == FlowScheme::shallow_water) {
    // The outflows in place: the scheme reads none of the previous step's (the second order's
    // second stage reads its own cell's first-stage outflows and averages into them).
    Buffer &qx = *fields_.get(FieldId::momentum_x), &qy = *fields_.get(FieldId::momentum_y);
    Buffer &qx_next = *fields_.twin(FieldId::momentum_x),
           &qy_next = *fields_.twin(FieldId::momentum_y);
    if (params_.flow.order == 2) {
      // Heun (shallow_water.h): the first stage into the outflows and the unit discharges'
      // second buffers, the depth it leaves, the second stage from there averaged into the
      // first's outflows and the unit discharges at the start of the step, which stay the
      // current ones
      muscl_stage(depth_, qx, qy, dt, 0, qx_next, qy_next);
      // the halo of the first stage before the depth and the second stage read it
      exchange_buffers({&flux_[0], &flux_[1], &flux_[2], &flux_[3], &qx_next, &qy_next});
      cl_kernel s = kernel("flow_shallow_water_stage_depth");
      set_args(s, cl_int{W_}, cl_int{H_}, kind_, depth_, flux_[0], flux_[1], flux_[2], flux_[3],
               area_, dt, stage_depth_);
      launch_rows(s, 0, H_);
      exchange_buffers({&stage_depth_});
      muscl_stage(stage_depth_, qx_next, qy_next, dt, 1, qx, qy);
      return;
    }
    cl_kernel k = kernel("flow_shallow_water");
    set_args(k, cl_int{W_}, cl_int{H_}, kind_, bed_, depth_, qx, qy, manning_, dx_, dy_, area_, dt,
             cell_.flow, flux_[0], flux_[1], flux_[2], flux_[3], qx_next, qy_next);
    if (whole_rows()) {
      // CPU devices: the velocities first (flow_velocities), then the interior rows by a kernel
      // that reads them without clamping (it vectorises), the first and last row by the general
      // one; the same bits as the general kernel on every row (shallow_water_cell_interior)
      const auto [u, v] = flow_velocities(depth_, qx, qy);
      cl_kernel in = kernel("flow_shallow_water_interior");
      set_args(in, cl_int{W_}, cl_int{H_}, kind_, bed_, depth_, qx, qy, *u, *v, manning_, dx_, dy_,
               area_, dt, cell_.flow, flux_[0], flux_[1], flux_[2], flux_[3], qx_next, qy_next);
      launch_rows(in, 1, H_ - 1);
      launch_rows(k, 0, 1);
      launch_rows(k, H_ - 1, H_);
    } else {
      launch_rows(k, 0, H_);
    }
    std::swap(qx, qx_next);
    std::swap(qy, qy_next);
    return;
  }
  if (params_.flow.scheme == FlowScheme::pipes) {
    // The interior rows by a kernel without clamping, the first and last row by the general one.
    // A cell reads only its own previous outflows: they are written in place (flow_pipes).
    for (const char* name : {"flow_pipes_interior", "flow_pipes"})
      set_args(kernel(name), cl_int{W_}, cl_int{H_}, kind_, bed_, depth_, dx_, dy_, area_, flux_[0],
               flux_[1], flux_[2], flux_[3], flux_[0], flux_[1], flux_[2], flux_[3], dt,
               cell_.flow);
    launch_interior(kernel("flow_pipes_interior"));
    launch_rows(kernel("flow_pipes"), 0, 1);
    launch_rows(kernel("flow_pipes"), H_ - 1, H_);
    return;
  }
  // Each face once (face pass), then split into the cells' outflows (cell pass); the
  // interior rows by kernels that need no clamping (they vectorise on CPU devices), the
  // edge rows by the general ones. H >= 3. The cell pass reads only the faces and its own
  // cell, so it writes the outflows in place: no second buffers (16 B per cell). The faces
  // are scratch in buffers that hold nothing alive during the flow (depth_next_, spare_):
  // the face kernels together write every face the cell pass reads.
  const Buffer& face_x = depth_next_as_scratch();
  const Buffer& face_y = made(spare_);
  for (const char* name : {"flow_local_inertial_faces_x_interior",
                           "flow_local_inertial_faces_y_interior", "flow_local_inertial_faces"})
    set_args(kernel(name), cl_int{W_}, cl_int{H_}, kind_, bed_, depth_, manning_, dx_, dy_,
             flux_[0], flux_[1], flux_[2], flux_[3], face_x, face_y, dt, cell_.flow);
  launch_rows(kernel("flow_local_inertial_faces_x_interior"), 1, H_ - 2);
  launch_rows(kernel("flow_local_inertial_faces_y_interior"), 1, H_ - 2);
  launch_rows(kernel("flow_local_inertial_faces"), 0, 1);
  launch_rows(kernel("flow_local_inertial_faces"), H_ - 2, H_);
  if (periodic_) {
    cl_kernel seam = kernel("flow_local_inertial_seam_x");
    set_args(seam, cl_int{W_}, cl_int{H_}, kind_, bed_, depth_, manning_, dx_, dy_, flux_[0],
             flux_[1], face_x, dt, cell_.flow);
    const std::size_t rows = static_cast<std::size_t>(H_);
    check(clEnqueueNDRangeKernel(queue_.get(), seam, 1, nullptr, &rows, nullptr, 0, nullptr,
                                 profile_event(seam)),
          "clEnqueueNDRangeKernel(flow_local_inertial_seam_x)");
  }
  for (const char* name : {"flow_local_inertial_split_interior", "flow_local_inertial_split"})
    set_args(kernel(name), cl_int{W_}, cl_int{H_}, kind_, depth_, area_, face_x, face_y, flux_[0],
             flux_[1], flux_[2], flux_[3], dt);
  launch_rows(kernel("flow_local_inertial_split_interior"), 1, H_ - 1);
  launch_rows(kernel("flow_local_inertial_split"), 0, 1);
  launch_rows(kernel("flow_local_inertial_split"), H_ - 1, H_);
}

template <class... Rest>
void OpenClBackend::set_water_args(cl_kernel k, Real dt, const Rest&... rest) {
  set_args(k, cl_int{W_}, cl_int{H_}, kind_, bed_, depth_, depth_next_, flux_[0], flux_[1],
           flux_[2], flux_[3], dx_, dy_, area_, velocity_x_, velocity_y_, dt, cell_.water, rest...);
}

unsigned OpenClBackend::water_tally_bits() {
  return tally_bit(&StepTally::boundary_out) | tally_bit(&StepTally::clipped) |
         tally_bit(&StepTally::water_exchanged);
}

unsigned OpenClBackend::erosion_tally_bits() const {
  const unsigned bits = tally_bit(&StepTally::eroded) | tally_bit(&StepTally::deposited);
  return params_.erosion.law == ErosionLaw::physical
             ? bits | tally_bit(&StepTally::eroded_bedrock) | tally_bit(&StepTally::bed_bulking)
             : bits;
}

// After the water update's launch: its exchange through the domain's faces (edges.cl), and
// depth_next_ keeps the depth the update started from (after this step's sources): conservative
// transport needs it.
void OpenClBackend::water_update_done(Real dt) {
  pending_water_dt_ = dt;
  launch_edge_tallies(tally_slot(&StepTally::boundary_out), dt);
  std::swap(depth_, depth_next_);
}

void OpenClBackend::run_water(Real dt, StepTally& tally) {
  second_for(depth_next_, depth_);  // it held the faces and the shares
  depth_next_scratch_ = false;      // the update writes its rows 1 .. H - 2
  cl_kernel k = kernel("water_update");
  set_water_args(k, dt, tally_partials_, static_cast<cl_int>(tally_stride_));
  defer(tally, water_tally_bits());
  launch_interior(k);
  water_update_done(dt);
}

void OpenClBackend::run_erosion(Real dt, StepTally& tally) {
  second_for(spare_, bed_);
  cl_kernel k;
  if (params_.erosion.law == ErosionLaw::physical) {
    k = kernel("erosion_physical");
    set_args(k, cl_int{W_}, cl_int{H_}, kind_, bed_, spare_, bed_residual_, sediment_,
             *field_buffer(FieldId::soil_thickness), depth_, velocity_x_, velocity_y_, manning_,
             hardness_, dx_, dy_, area_, dt, cell_.sediment, tally_partials_,
             static_cast<cl_int>(tally_stride_));
  } else {
    k = kernel("erosion");
    set_args(k, cl_int{W_}, cl_int{H_}, kind_, bed_, spare_, bed_residual_, sediment_, depth_,
             velocity_x_, velocity_y_, hardness_, dx_, dy_, area_, dt, cell_.erosion,
             tally_partials_, static_cast<cl_int>(tally_stride_));
  }
  defer(tally, erosion_tally_bits());
  launch_interior(k);
  std::swap(bed_, spare_);
}

void OpenClBackend::run_water_erosion(Real dt, StepTally& tally) {
  second_for(depth_next_, depth_);  // as run_water
  depth_next_scratch_ = false;
  second_for(spare_, bed_);  // as run_erosion
  const bool physical = params_.erosion.law == ErosionLaw::physical;
  cl_kernel k = kernel(physical ? "water_erosion_physical" : "water_erosion");
  if (physical)
    set_water_args(k, dt, spare_, bed_residual_, sediment_, *field_buffer(FieldId::soil_thickness),
                   manning_, hardness_, cell_.sediment, tally_partials_,
                   static_cast<cl_int>(tally_stride_));
  else
    set_water_args(k, dt, spare_, bed_residual_, sediment_, hardness_, cell_.erosion,
                   tally_partials_, static_cast<cl_int>(tally_stride_));
  defer(tally, water_tally_bits() | erosion_tally_bits());
  launch_interior(k);
  water_update_done(dt);
  std::swap(bed_, spare_);
}

void OpenClBackend::run_transport(Real dt, StepTally& tally) {
  second_for(spare_, sediment_);
  if (params_.transport.scheme == TransportScheme::conservative) {
    cl_kernel k = kernel("transport_conservative");
    set_args(k, cl_int{W_}, cl_int{H_}, kind_, sediment_, spare_, depth_flow(), flux_[0], flux_[1],
             flux_[2], flux_[3], area_, dt, tally_partials_, static_cast<cl_int>(tally_stride_));
    defer(tally, tally_bit(&StepTally::sediment_out) | tally_bit(&StepTally::sediment_exchanged));
    launch_interior(k);
    launch_edge_tallies(tally_slot(&StepTally::sediment_out),
                        dt);  // reads sediment_ before the swap
  } else {
    cl_kernel k = kernel("transport_semi_lagrangian");
    set_args(k, cl_int{W_}, cl_int{H_}, kind_, sediment_, spare_, velocity_x_, velocity_y_, dx_,
             dy_, dt, cl_int{periodic_ ? 1 : 0});
    launch_interior(k);
    cl_kernel r = kernel("reduce_change");
    set_args(r, cl_int{W_}, cl_int{H_}, kind_, spare_, sediment_, area_, partial_b_);
    defer(tally, kChangeBit);
    launch_reduction(r, reduce_groups_);
  }
  std::swap(sediment_, spare_);
}

void OpenClBackend::run_thermal(Real dt, StepTally& tally) {
  second_for(spare_, bed_);
  const Buffer& shares = depth_next_as_scratch();  // after the transport
  cl_kernel share = kernel("thermal_share");
  // The talus slopes are read only where the classes set them (by_class); otherwise any
  // buffer of the grid's size stands in, so that no field of zeros is made for them (4 B/cell).
  const Buffer& talus = cell_.thermal.by_class ? *field_buffer(FieldId::talus_slope) : wetness_;
  set_args(share, cl_int{W_}, cl_int{H_}, kind_, bed_, wetness_, talus, dx_, dy_, area_, shares, dt,
           cell_.thermal);
  launch_interior(share);
  exchange_buffers({&shares});  // the apply pass reads the neighbours' shares
  cl_kernel apply = kernel("thermal_apply");
  set_args(apply, cl_int{W_}, cl_int{H_}, kind_, bed_, bed_residual_, wetness_, talus, shares, dx_,
           dy_, area_, spare_, cell_.thermal, tally_partials_, static_cast<cl_int>(tally_stride_));
  defer(tally, tally_bit(&StepTally::thermal_moved));
  launch_interior(apply);
  std::swap(bed_, spare_);
}

void OpenClBackend::finish() {
  // (the step's tallies stay on the device: end_step reads them with the statistics)
  check(clFinish(queue_.get()), "clFinish");
  resolve_profile(false);
}

OpenClBackend::~OpenClBackend() {
  // the commands still queued may read host arrays this object owns (the halo rows written
  // without waiting, the point inflows) or hold profiling events: all complete before those go
  if (staging_ptr_)
    clEnqueueUnmapMemObject(queue_.get(), staging_.get(), staging_ptr_, 0, nullptr, nullptr);
  clFinish(queue_.get());
  for (auto& [name, ev] : profile_pending_)
    if (ev) clReleaseEvent(ev);
}

cl_event* OpenClBackend::profile_event(const std::string& name) {
  if (!profiling_) return nullptr;
  // a long run without finish(): book what is pending (waiting for it) to bound the list
  if (profile_pending_.size() >= 4096) resolve_profile(true);
  profile_pending_.emplace_back(name, nullptr);
  return &profile_pending_.back().second;
}

cl_event* OpenClBackend::profile_event(cl_kernel k) {
  if (!profiling_) return nullptr;
  auto it = kernel_names_.find(k);
  if (it == kernel_names_.end()) {
    std::size_t size = 0;
    check(clGetKernelInfo(k, CL_KERNEL_FUNCTION_NAME, 0, nullptr, &size), "clGetKernelInfo");
    std::string name(size, '\0');
    check(clGetKernelInfo(k, CL_KERNEL_FUNCTION_NAME, size, name.data(), nullptr),
          "clGetKernelInfo");
    while (!name.empty() && name.back() == '\0') name.pop_back();
    it = kernel_names_.emplace(k, name).first;
  }
  return profile_event(it->second);
}

void OpenClBackend::resolve_profile(bool wait) {
  for (auto& [name, ev] : profile_pending_) {
    if (!ev) continue;
    if (wait) check(clWaitForEvents(1, &ev), "clWaitForEvents");
    KernelTime& t = profile_[name];
    t.name = name;
    t.calls += 1;
    t.seconds += take_event_seconds(ev);
  }
  profile_pending_.clear();
}

std::vector<KernelTime> OpenClBackend::kernel_times() const {
  std::vector<KernelTime> out;
  for (const auto& [name, t] : profile_) out.push_back(t);
  return out;
}

FieldStats OpenClBackend::stats() {
  return collect(nullptr);
}

FieldStats OpenClBackend::collect(std::vector<double>* probes) {
  cl_kernel k = kernel("field_stats");
  const bool known = material_known_ && material_ok_;  // the volumes kept (material_rows_)
  set_args(k, cl_int{W_}, cl_int{H_}, static_cast<cl_int>(groups_x_), cl_int{known ? 0 : 1}, kind_,
           bed_, bed_residual_, depth_, sediment_, velocity_x_, velocity_y_, area_, partial_a_,
           partial_cells_);
  const int rows = H_ - 2;
  if (stats_local_ == 0)
    launch_rows(k, 1, H_ - 1);  // whole rows: a cell kernel, groups_x_ partials per row
  else                          // one group of stats_local_ work-items per row: one partial per row
    launch_rows(k, 1, H_ - 1, stats_local_);
  const std::size_t partials_per_row = stats_local_ == 0 ? groups_x_ : 1;
  cl_kernel r = kernel("stats_rows");
  set_args(r, cl_int{W_}, cl_int{rows}, static_cast<cl_int>(partials_per_row), partial_a_,
           partial_cells_, velocity_x_, velocity_y_, row_sums_, row_cells_);
  launch_reduction(r, (static_cast<std::size_t>(rows) + reduce_local_ - 1) / reduce_local_);
  // The step's tallies with the statistics: one wait per step (the queue is in order).
  enqueue_tally_reduction();
  tally_raw_.resize(tally_slots() * acc_size_);
  change_raw_.resize(reduce_groups_ * acc_size_);
  std::vector<ReadRequest> reads;  // the step's one batch of reads, the last one blocking
  if (pending_ & kChangeBit) reads.push_back({&partial_b_, change_raw_.size(), change_raw_.data()});
  if (pending_ & tally_bits())
    reads.push_back({&tally_sums_, tally_raw_.size(), tally_raw_.data()});
  std::vector<cl_long> cells(static_cast<std::size_t>(rows) * 3);
  reads.push_back({&row_cells_, cells.size() * sizeof(cl_long), cells.data()});
  const bool gather = probes && probe_count_ > 0 && !probe_fields_.empty();  // (owned ones)
  if (gather) {
    // the probes gathered on the device: a few floats in the step's one batch of reads
    enqueue_gather(probe_cells_, probe_count_, probe_fields_, probe_out_);
    probe_raw_.resize(part_count(probe_fields_) * probe_count_);
    reads.push_back({&probe_out_, probe_raw_.size() * sizeof(float), probe_raw_.data()});
  }
  if (probes && face_water_done_) {  // a step's faces (end_step), in the same batch
    face_water_raw_.resize(face_count_);
    reads.push_back({&face_water_out_, face_count_ * sizeof(Real), face_water_raw_.data()});
  }
  if (probes && face_sediment_done_) {
    face_sediment_raw_.resize(face_count_);
    reads.push_back({&face_sediment_out_, face_count_ * sizeof(Real), face_sediment_raw_.data()});
  }
  stats_sums_raw_.resize(static_cast<std::size_t>(rows) * kStatsRowValues * acc_size_);
  reads.push_back({&row_sums_, stats_sums_raw_.size(), stats_sums_raw_.data()});
  read_batch(reads);
  resolve_profile(false);  // the blocking read: every command before it has completed
  deliver_tallies();
  if (probes && !probe_fields_.empty() && !probe_owner_.empty()) {
    // (in a band of an MPI run: the owned probes' values, then every probe's from its owner)
    const std::vector<double> mine =
        gather ? compose_gathered(probe_fields_, probe_raw_, probe_count_) : std::vector<double>();
    *probes = gather_items(probe_owner_, probe_fields_.size(), mine);
  } else if (probes) {
    probes->clear();
  }
  constexpr std::size_t n = kStatsRowValues;
  const auto sums = acc_values(stats_sums_raw_, static_cast<std::size_t>(rows) * n);
  // The own rows in order (every rank's in global row order in a band of an MPI run), merged
  // as the CPU's (stats_merge.hpp). stats_rows numbers the cells from the raster's first row.
  const std::int64_t first_cell = static_cast<std::int64_t>(band_.row0) * nx_;
  auto cell = [&](cl_long c) { return c < 0 ? std::int64_t{-1} : first_cell + c; };
  if (!known) {  // every row's, halo rows included: the volumes summed, kept from now on
    material_rows_.resize(static_cast<std::size_t>(rows));
    material_ok_ = true;
    for (std::size_t y = 0; y < material_rows_.size(); ++y) {
      material_rows_[y] = {sums[n * y + 1], sums[n * y + 2]};
      material_ok_ = material_ok_ && cells[3 * y + 2] < 0;
    }
    material_known_ = true;
  }
  std::vector<RowStats> row_stats;
  row_stats.reserve(static_cast<std::size_t>(band_.own1 - band_.own0));
  for (int yy = band_.own0; yy < band_.own1; ++yy) {
    const auto y = static_cast<std::size_t>(yy - 1);
    RowStats row;
    row.water = sums[n * y + 0];
    row.material = material_rows_[y].first;
    row.sediment = material_rows_[y].second;
    row.max_depth = sums[n * y + 3];
    row.max_speed2 = sums[n * y + 4];
    row.max_depth_cell = cell(cells[3 * y + 0]);
    row.max_speed_cell = cell(cells[3 * y + 1]);
    row.bad_cell = cell(cells[3 * y + 2]);
    // hypot on the host, as the CPU reference takes it (stats_rows gives the velocities)
    if (row.max_speed_cell >= 0) row.speed = std::hypot(sums[n * y + 5], sums[n * y + 6]);
    row_stats.push_back(row);
  }
  if (band_.banded) row_stats = parallel::allgather(row_stats);
  return merge_row_stats(row_stats);
}

}  // namespace opencl

std::unique_ptr<Backend> make_opencl_backend(const Terrain& terrain, const Params& params) {
  const char* env = std::getenv("ERODEM_OPENCL_DEVICE");
  return std::make_unique<opencl::OpenClBackend>(terrain, params, env ? env : "");
}

}  // namespace erodem
