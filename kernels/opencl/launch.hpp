// erodem — kernel launches of the OpenCL backend (private): kernel arguments set in order,
// the work-group limits of the kernels, and the tally slots and bits of reduce.cl (launch.cpp
// and opencl_backend.cpp).
#pragma once

#include <cstddef>
#include <type_traits>

#include "opencl/opencl_backend.hpp"

namespace erodem::opencl {

/// Sets kernel arguments in order.
inline void set_arg(cl_kernel k, cl_uint index, const Buffer& b) {
  cl_mem m = b.get();
  check(clSetKernelArg(k, index, sizeof(cl_mem), &m), "clSetKernelArg");
}
template <class T>
inline void set_arg(cl_kernel k, cl_uint index, const T& v) {
  // numbers, or a process's parameter struct (kernels/cell_params.hpp: real members only, the
  // device's layout), passed by value
  static_assert(
      std::is_arithmetic_v<T> || (std::is_trivially_copyable_v<T> && std::is_standard_layout_v<T>),
      "kernel arguments: buffers, numbers or parameter structs");
  check(clSetKernelArg(k, index, sizeof(T), &v), "clSetKernelArg");
}
template <class... Args>
void set_args(cl_kernel k, const Args&... args) {
  cl_uint index = 0;
  (set_arg(k, index++, args), ...);
}

constexpr std::size_t kReduceMax = 256;      // ERODEM_REDUCE_MAX of stats.cl
constexpr std::size_t kCellGroupMax = 1024;  // ERODEM_CELL_GROUP_MAX of reduce.cl
constexpr std::size_t kReduceGroupsMax = 1024;
constexpr std::size_t kGatherParts = 6;  // the parts gather_cells (stats.cl) takes a launch
constexpr std::size_t kTallySlots = 9;   // ERODEM_TALLY_SLOTS of reduce.cl
constexpr int kTallyExchange = 0;        // ERODEM_TALLY_EXCHANGE of reduce.cl
constexpr int kTallySediment = 2;        // ERODEM_TALLY_SEDIMENT of reduce.cl
// one bit per slot of reduce.cl (1 << ERODEM_TALLY_*), then the transport change
constexpr unsigned kExchangeBit = 1u << 0, kClippedBit = 1u << 1, kSedimentBit = 1u << 2,
                   kEvaporatedBit = 1u << 3, kWaterGivenBit = 1u << 4, kErodedBit = 1u << 5,
                   kDepositedBit = 1u << 6, kSedimentGivenBit = 1u << 7, kThermalBit = 1u << 8,
                   kTallyBits = (1u << kTallySlots) - 1, kChangeBit = 1u << kTallySlots;

}  // namespace erodem::opencl
