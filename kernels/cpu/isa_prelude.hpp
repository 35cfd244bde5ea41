// erodem — prelude of every CPU kernel translation unit, force-included (-include) by
// kernels/CMakeLists.txt. The CPU kernels (kernels/cpu/*.cpp but dispatch.cpp) are compiled
// once per x86-64 level (ERODEM_CPU_ISA_LEVEL = 2, 3 or 4) into one binary; dispatch.cpp
// picks one at run time. Two rules keep the builds apart:
//
// - Names: everything the kernels define, CpuBackend and the per-cell functions of
//   kernels/common/*.h (namespace erodem::cell), goes into erodem::ERODEM_CPU_NAMESPACE
//   (cpu_v2, cpu_v3, cpu_v4). The inline namespace declared here, before compat.h opens
//   `namespace erodem { namespace cell {`, makes that reopen erodem::cpu_vN::cell, so the
//   instantiations of the builds never share a (weak, linker-merged) symbol.
// - Code: the wider instruction set applies only to what is defined after the target
//   pragma below. The library headers (std, fmt, OpenMP, erodem core) are included first,
//   so the out-of-line copies of their inline functions that a kernel TU emits are compiled
//   for the baseline in every build; whichever copy the linker keeps runs on any CPU.
//   A kernel file that needs another library header must add it here.
#pragma once

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "erodem/backend.hpp"
#include "erodem/backends.hpp"
#include "erodem/error.hpp"
#include "erodem/grid.hpp"
#include "erodem/initial_state.hpp"
#include "erodem/params.hpp"
#include "stagger.hpp"  // the fields' allocator: shared by the builds, so baseline code

#ifndef ERODEM_CPU_ISA_LEVEL
#error "kernels/cpu/*.cpp are built by kernels/CMakeLists.txt with ERODEM_CPU_ISA_LEVEL set"
#endif

#define ERODEM_CPU_CONCAT_(a, b) a##b
#define ERODEM_CPU_CONCAT(a, b) ERODEM_CPU_CONCAT_(a, b)
/// The namespace of this build: cpu_v2, cpu_v3 or cpu_v4.
#define ERODEM_CPU_NAMESPACE ERODEM_CPU_CONCAT(cpu_v, ERODEM_CPU_ISA_LEVEL)

namespace erodem {
inline namespace ERODEM_CPU_NAMESPACE {
namespace cell {}
}  // namespace ERODEM_CPU_NAMESPACE
}  // namespace erodem

// The baseline (level 2) is the command-line -march (x86-64-v2, or native with
// ERODEM_NATIVE); levels 3 and 4 raise it for the rest of the file. Generic tuning, as with
// -march=x86-64-vN. Neither changes values: no contraction (-ffp-contract=off), no
// reassociation (no -ffast-math), and IEEE float/double arithmetic on every level.
#if ERODEM_CPU_ISA_LEVEL == 3
#pragma GCC target("arch=x86-64-v3")
#elif ERODEM_CPU_ISA_LEVEL == 4
#pragma GCC target("arch=x86-64-v4")
#elif ERODEM_CPU_ISA_LEVEL != 2
#error "ERODEM_CPU_ISA_LEVEL must be 2, 3 or 4"
#endif
