// erodem — kernel launches of the OpenCL backend (private): kernel arguments set in order,
// the work-group limits of the kernels, and the tally slots and bits of reduce.cl (launch.cpp
// and opencl_backend.cpp).
#pragma once

#include <cstddef>
#include <string>
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

constexpr std::size_t kReduceMax = 256;        // ERODEM_REDUCE_MAX of stats.cl
constexpr std::size_t kCellGroupMax = 1024;    // ERODEM_CELL_GROUP_MAX of reduce.cl: whole rows
constexpr std::size_t kRoundedGroupMax = 256;  // and in rounded launches
constexpr std::size_t kStatsGroupMax = 256;    // ERODEM_STATS_GROUP_MAX of stats.cl
constexpr std::size_t kReduceGroupsMax = 1024;
constexpr std::size_t kGatherParts = 6;  // the parts gather_cells (stats.cl) takes a launch

/// The tally slots of the partials buffer: one per entry of tally_table() (ERODEM_TALLIES), at
/// its index there. The kernels know them as ERODEM_TALLY_<NAME> from the build options.
std::size_t tally_slots();
/// The slot of tally `member`.
int tally_slot(double StepTally::*member);
/// The pending bit of tally `member` (1 << its slot).
inline unsigned tally_bit(double StepTally::*member) {
  return 1u << tally_slot(member);
}
/// The bits of every slot.
inline unsigned tally_bits() {
  return (1u << tally_slots()) - 1;
}
/// The pending bit of the semi-Lagrangian transport change (reduce_change, not a slot).
constexpr unsigned kChangeBit = 1u << 31;
/// " -D ERODEM_TALLY_<NAME>=<slot> ... -D ERODEM_TALLY_SLOTS=<n>": the slots for the kernels.
std::string tally_slot_options();

}  // namespace erodem::opencl
