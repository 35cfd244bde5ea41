// erodem — the OpenCL backend's device memory: field buffers staggered modulo 4 KiB
// (stagger.hpp), buffer reads, and the fields by id with the rectangular copies of their DEM
// cells (field(), set_field()).
#include <fmt/format.h>

#include <algorithm>
#include <array>

#include "common/compat.h"
#include "erodem/error.hpp"
#include "erodem/fields.hpp"
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
        return b;
      }
    }
  }
  const cl_mem_flags flags = CL_MEM_READ_WRITE | (data ? CL_MEM_COPY_HOST_PTR : 0);
  Buffer b(clCreateBuffer(rt_->context.get(), flags, bytes, const_cast<void*>(data), &err));
  check(err, "clCreateBuffer");
  return b;
}

void OpenClBackend::read(const Buffer& b, std::size_t bytes, void* dst, bool blocking) {
  check(clEnqueueReadBuffer(queue_.get(), b.get(), blocking ? CL_TRUE : CL_FALSE, 0, bytes, dst, 0,
                            nullptr, nullptr),
        "clEnqueueReadBuffer");
}

Buffer* OpenClBackend::field_buffer(FieldId id) {
  switch (id) {
    case FieldId::bed:
      return &bed_;
    case FieldId::water_depth:
      return &depth_;
    case FieldId::sediment:
      return &sediment_;
    case FieldId::velocity_x:
      return &velocity_x_;
    case FieldId::velocity_y:
      return &velocity_y_;
    case FieldId::flux_left:
      return &flux_[ERODEM_LEFT];
    case FieldId::flux_right:
      return &flux_[ERODEM_RIGHT];
    case FieldId::flux_top:
      return &flux_[ERODEM_TOP];
    case FieldId::flux_bottom:
      return &flux_[ERODEM_BOTTOM];
    case FieldId::hardness:
      return &hardness_;
    case FieldId::wetness:
      return &wetness_;
    case FieldId::manning_n:
      return &manning_;
    case FieldId::initial_bed:
      return &bed0_;
    case FieldId::bed_residual:
      return &bed_residual_;
    case FieldId::erosion:
      return nullptr;
  }
  return nullptr;
}

namespace {

/// The DEM cells (the padded raster without its halo) of a buffer, row-major (ny, nx).
std::vector<float> read_interior(cl_command_queue q, cl_mem b, int nx, int ny) {
  std::vector<float> out(static_cast<std::size_t>(nx) * ny);
  const std::size_t origin[3] = {sizeof(float), 1, 0};
  const std::size_t region[3] = {static_cast<std::size_t>(nx) * sizeof(float),
                                 static_cast<std::size_t>(ny), 1};
  check(clEnqueueReadBufferRect(q, b, CL_TRUE, origin, std::array<std::size_t, 3>{0, 0, 0}.data(),
                                region, (static_cast<std::size_t>(nx) + 2) * sizeof(float), 0,
                                static_cast<std::size_t>(nx) * sizeof(float), 0, out.data(), 0,
                                nullptr, nullptr),
        "clEnqueueReadBufferRect");
  return out;
}

void write_interior(cl_command_queue q, cl_mem b, int nx, int ny, const std::vector<float>& v) {
  const std::size_t origin[3] = {sizeof(float), 1, 0};
  const std::size_t host_origin[3] = {0, 0, 0};
  const std::size_t region[3] = {static_cast<std::size_t>(nx) * sizeof(float),
                                 static_cast<std::size_t>(ny), 1};
  check(clEnqueueWriteBufferRect(q, b, CL_TRUE, origin, host_origin, region,
                                 (static_cast<std::size_t>(nx) + 2) * sizeof(float), 0,
                                 static_cast<std::size_t>(nx) * sizeof(float), 0, v.data(), 0,
                                 nullptr, nullptr),
        "clEnqueueWriteBufferRect");
}

}  // namespace

std::vector<double> OpenClBackend::field(FieldId id) const {
  auto* self = const_cast<OpenClBackend*>(this);
  if (id == FieldId::erosion || id == FieldId::bed) {
    // the bed and the erosion include the bed's residual (exact in double)
    const auto b = read_interior(queue_.get(), bed_.get(), nx_, ny_);
    const auto lo = read_interior(queue_.get(), bed_residual_.get(), nx_, ny_);
    const auto b0 = id == FieldId::erosion ? read_interior(queue_.get(), bed0_.get(), nx_, ny_)
                                           : std::vector<float>();
    std::vector<double> out(b.size());
    for (std::size_t i = 0; i < b.size(); ++i)
      out[i] = id == FieldId::bed ? static_cast<double>(b[i]) + static_cast<double>(lo[i])
                                  : (static_cast<double>(b0[i]) - static_cast<double>(b[i])) -
                                        static_cast<double>(lo[i]);
    return out;
  }
  const auto v = read_interior(queue_.get(), self->field_buffer(id)->get(), nx_, ny_);
  return std::vector<double>(v.begin(), v.end());
}

void OpenClBackend::set_field(FieldId id, const std::vector<double>& values) {
  if (values.size() != static_cast<std::size_t>(nx_) * ny_)
    throw Error(ExitCode::data, fmt::format("field '{}': {} values for a grid of {} x {}",
                                            field_info(id).name, values.size(), nx_, ny_));
  Buffer* dst = field_buffer(id);
  if (!dst) throw Error(ExitCode::usage, "field 'erosion' is derived and cannot be set");
  // Fields kept in two buffers get both, so the next step starts from the new values.
  Buffer* twin = id == FieldId::bed           ? &bed_next_
                 : id == FieldId::water_depth ? &depth_next_
                 : id == FieldId::sediment    ? &sediment_next_
                                              : nullptr;
  const std::vector<float> v(values.begin(), values.end());
  write_interior(queue_.get(), dst->get(), nx_, ny_, v);
  if (twin) write_interior(queue_.get(), twin->get(), nx_, ny_, v);
  if (id == FieldId::bed) {
    // a bed keeps what float cannot hold in its residual (set bed_residual after the bed)
    std::vector<float> lo(v.size());
    for (std::size_t i = 0; i < v.size(); ++i)
      lo[i] = static_cast<float>(values[i] - static_cast<double>(v[i]));
    write_interior(queue_.get(), bed_residual_.get(), nx_, ny_, lo);
  }
}

}  // namespace erodem::opencl
