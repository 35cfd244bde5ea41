// erodem — the OpenCL backend's device memory: field buffers staggered modulo 4 KiB
// (stagger.hpp), buffer reads, the fields by id with the rectangular copies of their DEM
// cells (field(), set_field()), and single cells gathered on the device (set_probes(),
// sample()).
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cstring>

#include "common/compat.h"
#include "common/erosion.h"
#include "erodem/error.hpp"
#include "erodem/fields.hpp"
#include "erodem/parallel.hpp"
#include "opencl/launch.hpp"
#include "opencl/opencl_backend.hpp"
#include "stagger.hpp"

namespace erodem::opencl {

// Field buffers start at different offsets modulo 4 KiB (stagger.hpp): each one of at least
// kStaggerMin bytes is a sub-buffer of a parent kStaggerPeriod bytes longer, its origin at
// the next slot's offset (rounded to the device's base alignment). PoCL at 4096^2, four bench
// runs alternating with a build without it: full local-inertial step 190.8 -> 165.6 ms (flow
// 67.0 -> 58.0, transport 21.9 -> 18.4, water 22.9 -> 20.6).
Buffer OpenClBackend::make_buffer(std::size_t bytes, const void* data) {
  cl_int err = CL_SUCCESS;
  bytes = std::max<std::size_t>(bytes, 1);
  const std::size_t align = rt_->base_align;
  // The staggering is only for speed: a buffer that would not fit with the extra 4 KiB, or a
  // sub-buffer the device refuses, gets a plain buffer.
  if (bytes >= kStaggerMin && align < kStaggerPeriod && bytes + kStaggerPeriod <= rt_->max_alloc) {
    const std::size_t offset = stagger_offset(stagger_next_++, align);
    Buffer parent(clCreateBuffer(rt_->context.get(), CL_MEM_READ_WRITE, bytes + kStaggerPeriod,
                                 nullptr, &err));
    if (err == CL_SUCCESS) {
      const cl_buffer_region region{offset, bytes};
      // The sub-buffer keeps its parent alive (OpenCL 1.2, clReleaseMemObject).
      Buffer b(clCreateSubBuffer(parent.get(), CL_MEM_READ_WRITE, CL_BUFFER_CREATE_TYPE_REGION,
                                 &region, &err));
      if (err == CL_SUCCESS) {
        if (data)
          check(clEnqueueWriteBuffer(queue_.get(), b.get(), CL_TRUE, 0, bytes, data, 0, nullptr,
                                     nullptr),
                "clEnqueueWriteBuffer");
        device_bytes_ += bytes + kStaggerPeriod;
        return b;
      }
    }
  }
  const cl_mem_flags flags = CL_MEM_READ_WRITE | (data ? CL_MEM_COPY_HOST_PTR : 0);
  Buffer b(clCreateBuffer(rt_->context.get(), flags, bytes, const_cast<void*>(data), &err));
  check(err, "clCreateBuffer");
  device_bytes_ += bytes;
  return b;
}

Buffer OpenClBackend::filled_field(Real value) {
  Buffer b = make_buffer(n_ * sizeof(Real));
  // the pattern is the float's bits: the same bits in every cell
  check(clEnqueueFillBuffer(queue_.get(), b.get(), &value, sizeof value, 0, n_ * sizeof(Real), 0,
                            nullptr, nullptr),
        "clEnqueueFillBuffer");
  return b;
}

Buffer& OpenClBackend::made(Buffer& b, const Buffer* like) {
  if (b) return b;
  if (!like) {
    b = zero_field();
    return b;
  }
  b = make_buffer(n_ * sizeof(Real));
  check(clEnqueueCopyBuffer(queue_.get(), like->get(), b.get(), 0, 0, n_ * sizeof(Real), 0, nullptr,
                            nullptr),
        "clEnqueueCopyBuffer");
  return b;
}

Buffer& OpenClBackend::second_for(Buffer& second, const Buffer& field) {
  if (!second) return made(second, &field);
  scratch_rows(field, second);
  return second;
}

const Buffer& OpenClBackend::depth_flow() {
  if (depth_next_scratch_)
    throw Error(ExitCode::internal,
                "OpenCL: the depth the water update started from is read after the face pass, the "
                "shallow-water velocities or thermal collapse held their scratch in its buffer, "
                "with no water update between (process order)");
  return made(depth_next_, &depth_);  // before any water update: the depth as it is
}

Buffer& OpenClBackend::depth_next_as_scratch() {
  depth_next_scratch_ = true;
  return made(depth_next_);
}

void OpenClBackend::scratch_rows(const Buffer& from, const Buffer& to) {
  const std::size_t row = static_cast<std::size_t>(W_) * sizeof(Real);
  for (const std::size_t at : {std::size_t{0}, static_cast<std::size_t>(H_ - 1) * row})
    check(clEnqueueCopyBuffer(queue_.get(), from.get(), to.get(), at, at, row, 0, nullptr, nullptr),
          "clEnqueueCopyBuffer(rows 0 and H - 1)");
}

const OpenClBackend::Real* OpenClBackend::uniform_value(const Buffer& b) const {
  for (const auto& [buffer, value] : uniform_)
    if (buffer == &b) return &value;
  return nullptr;
}

void OpenClBackend::take_parameter(Buffer& dst, CellParameter& src, bool per_cell) {
  if (!src.is_uniform()) {
    const std::vector<Real> v(src.cells.begin(), src.cells.end());
    std::vector<double>().swap(src.cells);
    dst = upload(v);
    return;
  }
  const Real value = static_cast<Real>(src.uniform);
  // W + 1 values: the local-inertial face pass reads the Manning n of column x + 1 for every x,
  // the last column's (x = W - 1, whose face it discards) included (flow.h)
  dst = upload(std::vector<Real>(static_cast<std::size_t>(W_) + 1, value));
  uniform_.emplace_back(&dst, value);
  if (per_cell) make_per_cell(dst);
}

void OpenClBackend::make_per_cell(Buffer& b) {
  const Real* value = uniform_value(b);
  if (!value) return;
  b = filled_field(*value);  // the same bits as the CPU reference's copies of its row
  uniform_.erase(
      std::find_if(uniform_.begin(), uniform_.end(), [&](const auto& u) { return u.first == &b; }));
  update_param_pitches();
}

void OpenClBackend::read(const Buffer& b, std::size_t bytes, void* dst, bool blocking) {
  check(clEnqueueReadBuffer(queue_.get(), b.get(), blocking ? CL_TRUE : CL_FALSE, 0, bytes, dst, 0,
                            nullptr, profile_event("read")),
        "clEnqueueReadBuffer");
}

void OpenClBackend::read_batch(const std::vector<ReadRequest>& reads) {
  if (reads.empty()) return;
  if (!pinned_reads_) {
    for (std::size_t j = 0; j < reads.size(); ++j)
      read(*reads[j].buffer, reads[j].bytes, reads[j].dst, j + 1 == reads.size());
    return;
  }
  // each read's place in the staging area, on 64-byte boundaries
  std::vector<std::size_t> at(reads.size());
  std::size_t total = 0;
  for (std::size_t j = 0; j < reads.size(); ++j) {
    at[j] = total;
    total += (reads[j].bytes + 63) / 64 * 64;
  }
  if (total > staging_bytes_) {  // grown (the queue is in order: the unmap waits for earlier reads)
    if (staging_ptr_)
      check(
          clEnqueueUnmapMemObject(queue_.get(), staging_.get(), staging_ptr_, 0, nullptr, nullptr),
          "clEnqueueUnmapMemObject(staging)");
    staging_ptr_ = nullptr;
    staging_ = Buffer();
    staging_bytes_ = 0;  // (until the new one is mapped: a failure below leaves none)
    cl_int err = CL_SUCCESS;
    staging_ = Buffer(clCreateBuffer(rt_->context.get(), CL_MEM_READ_WRITE | CL_MEM_ALLOC_HOST_PTR,
                                     total, nullptr, &err));
    check(err, "clCreateBuffer(staging, CL_MEM_ALLOC_HOST_PTR)");
    staging_ptr_ = static_cast<unsigned char*>(
        clEnqueueMapBuffer(queue_.get(), staging_.get(), CL_TRUE, CL_MAP_READ | CL_MAP_WRITE, 0,
                           total, 0, nullptr, nullptr, &err));
    check(err, "clEnqueueMapBuffer(staging)");
    staging_bytes_ = total;
  }
  for (std::size_t j = 0; j < reads.size(); ++j)
    read(*reads[j].buffer, reads[j].bytes, staging_ptr_ + at[j], j + 1 == reads.size());
  for (std::size_t j = 0; j < reads.size(); ++j)
    if (reads[j].bytes) std::memcpy(reads[j].dst, staging_ptr_ + at[j], reads[j].bytes);
}

namespace {

/// The DEM cells (the padded raster without its halo) of a buffer, row-major (ny, nx).
/// DEM rows [row0, row1) of a padded buffer of DEM width nx, without its ghost cells.
std::vector<float> read_interior(cl_command_queue q, cl_mem b, int nx, int row0, int row1) {
  std::vector<float> out(static_cast<std::size_t>(nx) * static_cast<std::size_t>(row1 - row0));
  if (out.empty()) return out;
  const std::size_t origin[3] = {sizeof(float), static_cast<std::size_t>(row0) + 1, 0};
  const std::size_t region[3] = {static_cast<std::size_t>(nx) * sizeof(float),
                                 static_cast<std::size_t>(row1 - row0), 1};
  check(clEnqueueReadBufferRect(q, b, CL_TRUE, origin, std::array<std::size_t, 3>{0, 0, 0}.data(),
                                region, (static_cast<std::size_t>(nx) + 2) * sizeof(float), 0,
                                static_cast<std::size_t>(nx) * sizeof(float), 0, out.data(), 0,
                                nullptr, nullptr),
        "clEnqueueReadBufferRect");
  return out;
}

/// `v` into DEM rows [row0, row1) of a padded buffer of DEM width nx, its ghost cells kept.
void write_interior(cl_command_queue q, cl_mem b, int nx, int row0, int row1,
                    const std::vector<float>& v) {
  if (row1 <= row0) return;
  const std::size_t origin[3] = {sizeof(float), static_cast<std::size_t>(row0) + 1, 0};
  const std::size_t host_origin[3] = {0, 0, 0};
  const std::size_t region[3] = {static_cast<std::size_t>(nx) * sizeof(float),
                                 static_cast<std::size_t>(row1 - row0), 1};
  check(clEnqueueWriteBufferRect(q, b, CL_TRUE, origin, host_origin, region,
                                 (static_cast<std::size_t>(nx) + 2) * sizeof(float), 0,
                                 static_cast<std::size_t>(nx) * sizeof(float), 0, v.data(), 0,
                                 nullptr, nullptr),
        "clEnqueueWriteBufferRect");
}

}  // namespace

std::vector<const Buffer*> OpenClBackend::field_parts(FieldId id) {
  if (id == FieldId::bed) return {&bed_, &bed_residual_};
  if (id == FieldId::erosion) return {&bed0_, &bed_, &bed_residual_};
  if (id == FieldId::shear_stress) return {&depth_, &velocity_x_, &velocity_y_, &manning_};
  return {fields_.peek(id)};  // a field not made yet reads as zeros
}

std::size_t OpenClBackend::part_count(const std::vector<FieldId>& fields) const {
  auto* self = const_cast<OpenClBackend*>(this);
  std::size_t n = 0;
  for (const FieldId id : fields) n += self->field_parts(id).size();
  return n;
}

double OpenClBackend::compose(FieldId id, const float* parts, std::size_t stride) const {
  // the bed and the erosion include the bed's residual (exact in double)
  if (id == FieldId::bed) return static_cast<double>(parts[0]) + static_cast<double>(parts[stride]);
  if (id == FieldId::erosion)
    return (static_cast<double>(parts[0]) - static_cast<double>(parts[stride])) -
           static_cast<double>(parts[2 * stride]);
  // the bed shear stress from the depth, the velocities and Manning n, as the CPU's value_at
  if (id == FieldId::shear_stress)
    return cell::bed_shear_stress<double>(
        parts[0], parts[stride], parts[2 * stride], parts[3 * stride], params_.flow.water_density,
        params_.flow.gravity, params_.numerics.velocity_min_depth);
  return static_cast<double>(parts[0]);
}

std::vector<double> OpenClBackend::field(FieldId id) const {
  return field_rows(id, 0, ny_);
}

std::vector<double> OpenClBackend::field_rows(FieldId id, int row0, int row1) const {
  // this rank's rows of [row0, row1), then every rank's in row order
  OwnRows own = own_field_rows(id, row0, row1);
  if (band_.banded) return parallel::allgather(own.values);
  return std::move(own.values);
}

OwnRows OpenClBackend::own_field_rows(FieldId id, int row0, int row1) const {
  check_row_range(id, row0, row1, nx_, ny_);
  // the rows of [row0, row1) this rank owns (all of them in one process; DEM row r is raster
  // row r + 1 - band_.row0)
  const int r0 = std::max(row0, band_.own0 - 1 + band_.row0),
            r1 = std::min(row1, band_.own1 - 1 + band_.row0);
  OwnRows out;
  out.row0 = r1 > r0 ? r0 : row0;
  out.row1 = r1 > r0 ? r1 : row0;
  out.values = read_rows(id, out.row0, out.row1);
  return out;
}

std::vector<double> OpenClBackend::read_rows(FieldId id, int row0, int row1) const {
  const std::size_t n = static_cast<std::size_t>(nx_) * static_cast<std::size_t>(row1 - row0);
  if (fields_.reads_zeros(id)) return std::vector<double>(n);  // without a buffer of zeros
  auto* self = const_cast<OpenClBackend*>(this);
  const auto parts = self->field_parts(id);
  std::vector<float> raw;
  raw.reserve(parts.size() * n);
  for (const Buffer* b : parts) {
    if (const Real* value = uniform_value(*b)) {  // a parameter held as one row
      raw.insert(raw.end(), n, *value);
      continue;
    }
    const auto v = read_interior(queue_.get(), b->get(), nx_, row0 - band_.row0, row1 - band_.row0);
    raw.insert(raw.end(), v.begin(), v.end());
  }
  std::vector<double> out(n);
  for (std::size_t i = 0; i < n; ++i) out[i] = compose(id, raw.data() + i, n);
  return out;
}

void OpenClBackend::enqueue_gather(const Buffer& cells, std::size_t n,
                                   const std::vector<FieldId>& fields, const Buffer& out) {
  std::vector<const Buffer*> parts;
  for (const FieldId id : fields)
    for (const Buffer* b : field_parts(id)) parts.push_back(b);
  // gather_cells reads at cell indices: a parameter held as one row is read from a stand-in
  // (the depth) and its value put in by compose_gathered
  for (const Buffer*& b : parts)
    if (uniform(*b)) b = &depth_;
  // gather_cells takes up to kGatherParts parts a launch
  cl_kernel k = kernel("gather_cells");
  for (std::size_t first = 0; first < parts.size(); first += kGatherParts) {
    const std::size_t count = std::min(kGatherParts, parts.size() - first);
    set_args(k, static_cast<cl_int>(n), static_cast<cl_int>(count), cells, out,
             static_cast<cl_int>(first * n));
    for (std::size_t j = 0; j < kGatherParts; ++j)  // unused parameters: any buffer
      set_arg(k, static_cast<cl_uint>(5 + j), *parts[first + std::min(j, count - 1)]);
    const std::size_t global = n;
    check(clEnqueueNDRangeKernel(queue_.get(), k, 1, nullptr, &global, nullptr, 0, nullptr,
                                 profile_event(k)),
          "clEnqueueNDRangeKernel(gather_cells)");
  }
}

std::vector<double> OpenClBackend::compose_gathered(const std::vector<FieldId>& fields,
                                                    const std::vector<float>& raw,
                                                    std::size_t n) const {
  // the parameters held as one row: their value where gather_cells read a stand-in
  auto* self = const_cast<OpenClBackend*>(this);
  std::vector<float> filled;
  const float* values = raw.data();
  std::size_t part = 0;
  for (const FieldId id : fields)
    for (const Buffer* b : self->field_parts(id)) {
      if (const Real* value = uniform_value(*b)) {
        if (filled.empty()) filled = raw;
        std::fill_n(filled.begin() + static_cast<std::ptrdiff_t>(part * n), n, *value);
        values = filled.data();
      }
      ++part;
    }
  std::vector<double> out;
  out.reserve(fields.size() * n);
  part = 0;
  for (const FieldId id : fields) {
    for (std::size_t j = 0; j < n; ++j) out.push_back(compose(id, values + part * n + j, n));
    part += part_count({id});
  }
  return out;
}

std::vector<cl_int> OpenClBackend::owned_padded_cells(const std::vector<std::int64_t>& cells,
                                                      std::vector<int>& owner) const {
  owner = cell_owners(cells, nx_, ny_);
  std::vector<cl_int> out;
  for (std::size_t j = 0; j < cells.size(); ++j)
    if (owner[j] == parallel::rank())
      out.push_back(static_cast<cl_int>(band_.padded(cells[j], nx_)));
  return out;
}

std::vector<double> OpenClBackend::gather_items(const std::vector<int>& owner, std::size_t repeat,
                                                const std::vector<double>& mine) const {
  if (!band_.banded) return mine;
  std::vector<int> all;
  all.reserve(owner.size() * repeat);
  for (std::size_t k = 0; k < repeat; ++k) all.insert(all.end(), owner.begin(), owner.end());
  return parallel::gather_owned(all, mine);
}

void OpenClBackend::set_probes(const std::vector<std::int64_t>& cells,
                               const std::vector<FieldId>& fields) {
  check_cells(cells, nx_, ny_, "probes");
  probe_fields_ = fields;
  const std::vector<cl_int> mine = owned_padded_cells(cells, probe_owner_);
  probe_count_ = mine.size();
  if (mine.empty() || fields.empty()) return;
  probe_cells_ = upload(mine);
  probe_out_ = make_buffer(part_count(fields) * mine.size() * sizeof(float));
}

std::vector<double> OpenClBackend::sample(const std::vector<std::int64_t>& cells,
                                          FieldId id) const {
  check_cells(cells, nx_, ny_, "sample");
  if (cells.empty()) return {};
  auto* self = const_cast<OpenClBackend*>(this);
  std::vector<int> owner;
  const std::vector<cl_int> mine = owned_padded_cells(cells, owner);
  std::vector<double> values;
  if (!mine.empty()) {
    const Buffer where = self->upload(mine);
    const Buffer out = self->make_buffer(part_count({id}) * mine.size() * sizeof(float));
    self->enqueue_gather(where, mine.size(), {id}, out);
    std::vector<float> raw(part_count({id}) * mine.size());
    self->read(out, raw.size() * sizeof(float), raw.data(), true);
    values = compose_gathered({id}, raw, mine.size());
  }
  return gather_items(owner, 1, values);
}

void OpenClBackend::set_field(FieldId id, const std::vector<double>& values) {
  if (values.size() != static_cast<std::size_t>(nx_) * ny_)
    throw Error(ExitCode::data, fmt::format("field '{}': {} values for a grid of {} x {}",
                                            field_info(id).name, values.size(), nx_, ny_));
  set_field_rows(id, 0, ny_, values);
}

void OpenClBackend::set_field_rows(FieldId id, int row0, int row1,
                                   const std::vector<double>& values) {
  check_rows(id, row0, row1, values.size(), nx_, ny_);
  if (material_field(id)) material_known_ = false;       // the volumes summed again
  if (fields_.setting_keeps_unmade(id, values)) return;  // reads give these zeros already
  Buffer* dst = field_buffer(id);
  if (!dst)
    throw Error(ExitCode::usage,
                fmt::format("field '{}' is derived and cannot be set", field_info(id).name));
  // Fields kept in two buffers get both, so the next step starts from the new values (a
  // second buffer not made yet is made later as a copy: made()).
  Buffer* twin = fields_.twin(id);
  if (twin && !*twin) twin = nullptr;
  // the DEM rows of [row0, row1) the raster holds (a band's own and halo rows in an MPI run:
  // DEM row r is raster row r + 1 - band_.row0), so no exchange between ranks is needed
  const int r0 = std::max(row0, band_.row0 - 1), r1 = std::min(row1, band_.row0 - 1 + H_);
  if (r1 <= r0) return;
  const auto held = values.begin() + static_cast<std::ptrdiff_t>(r0 - row0) * nx_;
  const std::vector<float> v(held, held + static_cast<std::ptrdiff_t>(r1 - r0) * nx_);
  const int y0 = r0 - band_.row0, y1 = r1 - band_.row0;  // write_interior's rows
  write_interior(queue_.get(), dst->get(), nx_, y0, y1, v);
  if (twin) write_interior(queue_.get(), twin->get(), nx_, y0, y1, v);
  if (id == FieldId::bed) {
    // a bed keeps what float cannot hold in its residual (set bed_residual after the bed)
    std::vector<float> lo(v.size());
    for (std::size_t i = 0; i < v.size(); ++i)
      lo[i] = static_cast<float>(held[static_cast<std::ptrdiff_t>(i)] - static_cast<double>(v[i]));
    write_interior(queue_.get(), bed_residual_.get(), nx_, y0, y1, lo);
    copy_periodic_columns(bed_residual_);
  }
  copy_periodic_columns(*dst);
  if (twin) copy_periodic_columns(*twin);
}

}  // namespace erodem::opencl
