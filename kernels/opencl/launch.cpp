// erodem — how the OpenCL backend launches its kernels: kernels by name, launch geometry
// (interior rows, row ranges, edge cells, reductions), accumulator values, and the ledger's
// tallies deferred on the device until one read per step.
#include "opencl/launch.hpp"

#include <fmt/format.h>

#include <cctype>
#include <cstring>

#include "erodem/error.hpp"
#include "erodem/process.hpp"
#include "opencl/opencl_backend.hpp"

namespace erodem::opencl {

std::size_t tally_slots() {
  const std::size_t n = tally_table().size();
  if (n >= 31) throw Error(ExitCode::internal, "OpenCL: more than 30 tallies for the pending bits");
  return n;
}

int tally_slot(double StepTally::*member) {
  const auto& table = tally_table();
  for (std::size_t k = 0; k < table.size(); ++k)
    if (table[k].step == member) return static_cast<int>(k);
  throw Error(ExitCode::internal, "OpenCL: a tally without an entry in tally_table()");
}

std::string tally_slot_options() {
  std::string out;
  const auto& table = tally_table();
  for (std::size_t k = 0; k < table.size(); ++k) {
    std::string name = table[k].name;
    for (char& c : name) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    out += fmt::format(" -D ERODEM_TALLY_{}={}", name, k);
  }
  return out + fmt::format(" -D ERODEM_TALLY_SLOTS={}", table.size());
}

cl_kernel OpenClBackend::kernel(const char* name) {
  for (auto& [n, k] : kernels_)
    if (n == name) return k.get();
  cl_int err = CL_SUCCESS;
  Kernel k(clCreateKernel(rt_->program.get(), name, &err));
  check(err, fmt::format("clCreateKernel({})", name).c_str());
  kernels_.emplace_back(name, std::move(k));
  return kernels_.back().second.get();
}

void OpenClBackend::run_generic(const SweepInfo& sweep, Process process, Real dt,
                                StepTally& tally) {
  if (!sweep.generic || sweep.domain != Domain::cells)
    throw Error(ExitCode::internal,
                fmt::format("sweep '{}' of process '{}' is not generic: the backend has no code "
                            "for it",
                            sweep.name, process_name(process)));
  cl_kernel k = kernel(sweep.name);
  cl_uint i = 0;
  set_arg(k, i++, cl_int{W_});
  set_arg(k, i++, cl_int{H_});
  for (const FieldUse& u : sweep.uses) {
    const std::string name = u.field;
    // the grid inputs outside the field table (kind, the per-row cell sizes), the parameters
    // as held (one row where uniform: their cell functions read them at param_index with the
    // pitch of their parameter struct; the terrain classes, which write Manning n and the
    // hardness, have them per cell from the start), then the fields
    const Buffer* b = name == "kind"          ? &kind_
                      : name == "rain_factor" ? &rain_factor_
                      : name == "manning_n"   ? &manning_
                      : name == "hardness"    ? &hardness_
                      : name == "dx"          ? &dx_
                      : name == "dy"          ? &dy_
                                              : field_buffer(field_info(name).id);
    if (!b)
      throw Error(ExitCode::internal,
                  fmt::format("sweep '{}': field '{}' has no buffer", sweep.name, name));
    set_arg(k, i++, *b);
  }
  set_arg(k, i++, area_);
  set_arg(k, i++, dt);
  const ParamBytes params = cell_params_bytes(cell_, process);
  check(clSetKernelArg(k, i++, params.size, params.data), "clSetKernelArg(params)");
  set_arg(k, i++, tally_partials_);
  set_arg(k, i++, static_cast<cl_int>(tally_stride_));
  unsigned bits = 0;
  for (const char* name : sweep.tallies)
    for (std::size_t slot = 0; slot < tally_table().size(); ++slot)
      if (std::string(tally_table()[slot].name) == name) bits |= 1u << slot;
  if (bits) defer(tally, bits);
  launch_interior(k);
}

void OpenClBackend::launch_interior(cl_kernel k) {
  if (!band_.banded) {
    launch_rows(k, 1, H_ - 1);
    return;
  }
  // A band of an MPI run: its halo rows are computed too (as the CPU reference's), but only
  // its own rows are tallied. A cell kernel writes its group's tally partial at the group's
  // index in the launch (cell_group_index, reduce.cl), so the own rows, launched last, write
  // over the partials of the halo rows' launches: a band has at least band_.halo own rows,
  // and each halo launch at most band_.halo - 1 rows (the raster's first and last rows are
  // not interior).
  launch_rows(k, 1, band_.own0);
  launch_rows(k, band_.own1, H_ - 1);
  launch_rows(k, band_.own0, band_.own1);
}

void OpenClBackend::launch_rows(cl_kernel k, int y0, int y1, std::size_t row_group) {
  if (y1 <= y0) return;
  const std::size_t rows = static_cast<std::size_t>(y1 - y0);
  auto enqueue = [&](std::size_t x0, std::size_t width, std::size_t group) {
    const std::size_t offset[2] = {x0, static_cast<std::size_t>(y0)};
    const std::size_t global[2] = {width, rows};
    const std::size_t local[2] = {group, 1};
    check(clEnqueueNDRangeKernel(queue_.get(), k, 2, offset, global, local, 0, nullptr,
                                 profile_event(k)),
          "clEnqueueNDRangeKernel");
  };
  if (row_group > 0) {
    enqueue(0, row_group, row_group);
    return;
  }
  // whole rows with a tail: the groups of local_x_ (none where the row is the tail), then
  // the tail's one group per row
  const std::size_t full = tail_x_ > 0 ? groups_x_ - 1 : groups_x_;
  if (full > 0) enqueue(0, full * local_x_, local_x_);
  if (tail_x_ > 0) enqueue(full * local_x_, tail_x_, tail_x_);
}

void OpenClBackend::launch_edge_tallies(int slot, Real dt) {
  if (edge_count_ == 0) return;
  cl_kernel k = kernel("edge_tallies");
  set_args(k, cl_int{W_}, kind_, edge_cells_, static_cast<cl_int>(edge_count_), flux_[0], flux_[1],
           flux_[2], flux_[3], sediment_, depth_flow(), dt, cl_int{slot}, tally_partials_,
           static_cast<cl_int>(tally_stride_));
  const std::size_t global = edge_groups_ * edge_local_, local = edge_local_;
  check(clEnqueueNDRangeKernel(queue_.get(), k, 1, nullptr, &global, &local, 0, nullptr,
                               profile_event(k)),
        "clEnqueueNDRangeKernel(edge_tallies)");
}

void OpenClBackend::launch_reduction(cl_kernel k, std::size_t groups) {
  const std::size_t global = groups * reduce_local_, local = reduce_local_;
  check(clEnqueueNDRangeKernel(queue_.get(), k, 1, nullptr, &global, &local, 0, nullptr,
                               profile_event(k)),
        "clEnqueueNDRangeKernel");
}

std::vector<double> OpenClBackend::acc_values(const std::vector<unsigned char>& raw,
                                              std::size_t count) const {
  std::vector<double> out(count);
  for (std::size_t k = 0; k < count; ++k) {
    if (acc_size_ == sizeof(double)) {
      std::memcpy(&out[k], raw.data() + k * sizeof(double), sizeof(double));
    } else {
      float f;
      std::memcpy(&f, raw.data() + k * sizeof(float), sizeof(float));
      out[k] = f;
    }
  }
  return out;
}

void OpenClBackend::defer(StepTally& tally, unsigned bits) {
  // A tally for another StepTally, or one whose slot is still pending: deliver first.
  if (pending_ && (pending_tally_ != &tally || (pending_ & bits))) flush_tallies();
  pending_tally_ = &tally;
  pending_ |= bits;
}

void OpenClBackend::enqueue_tally_reduction() {
  if (!(pending_ & tally_bits())) return;
  cl_kernel k = kernel("reduce_tallies");
  set_args(k, static_cast<cl_int>(tally_stride_), tally_partials_, tally_sums_);
  launch_reduction(k, tally_slots());
}

void OpenClBackend::deliver_tallies() {
  if (!pending_ || !pending_tally_) {
    pending_ = 0;
    return;
  }
  StepTally& t = *pending_tally_;
  if (pending_ & tally_bits()) {
    const auto v = acc_values(tally_raw_, tally_slots());
    const auto& table = tally_table();
    for (std::size_t k = 0; k < table.size(); ++k) {
      if (!(pending_ & (1u << k))) continue;
      // the boundary slot sums a discharge (m^3/s, edges.cl): the volume is dt times it
      if (table[k].step == &StepTally::boundary_out)
        t.boundary_out += static_cast<double>(pending_water_dt_) * v[k];
      else
        t.*table[k].step += v[k];
    }
  }
  if (pending_ & kChangeBit) {
    double change = 0.0;
    for (double v : acc_values(change_raw_, reduce_groups_)) change += v;
    t.transport_change += change;
  }
  pending_ = 0;
  pending_tally_ = nullptr;
}

void OpenClBackend::flush_tallies() {
  if (!pending_) return;
  enqueue_tally_reduction();
  tally_raw_.resize(tally_slots() * acc_size_);
  change_raw_.resize(reduce_groups_ * acc_size_);
  std::vector<ReadRequest> reads;
  if (pending_ & kChangeBit) reads.push_back({&partial_b_, change_raw_.size(), change_raw_.data()});
  if (pending_ & tally_bits())
    reads.push_back({&tally_sums_, tally_raw_.size(), tally_raw_.data()});
  read_batch(reads);
  check(clFinish(queue_.get()), "clFinish");
  deliver_tallies();
}

}  // namespace erodem::opencl
