// erodem — the one conversion of the parameters into the per-cell dialect: each process's
// run constants as the parameter struct of its cell functions (ERODEM_PARAMS in
// kernels/common/*.h), converted here once, in the baseline translation unit (not the
// per-instruction-set CPU builds), and passed as they are by the CPU reference and, as one
// kernel argument, by the OpenCL backend: both backends compute from the same numbers.
#pragma once

#include "common/boundary.h"
#include "common/erosion.h"
#include "common/flow.h"
#include "common/sources.h"
#include "common/thermal.h"
#include "common/water.h"
#include "erodem/backend.hpp"
#include "erodem/params.hpp"

namespace erodem {

/// The run constants of every process, in `real` (float, or double for the CPU's float64).
template <class real>
struct CellParams {
  cell_params::BoundaryParams<real> boundary;
  cell_params::FlowParams<real> flow;
  cell_params::WaterParams<real> water;
  cell_params::ErosionParams<real> erosion;
  cell_params::ThermalParams<real> thermal;
  cell_params::EvaporationParams<real> evaporation;
};

/// The run constants from the parameters (units in the structs' headers): sea_level;
/// gravity, theta, dry_depth, pipe_area, pipe_length; velocity_min_depth; the erosion rates,
/// with -inf for no bedrock level; K_t and tan(talus angle); K_e, the wetness time and
/// whether it evaporates.
template <class real>
CellParams<real> cell_params_of(const Params& params);

/// The bytes of process `p`'s parameter struct in `c` (what the generic sweeps pass to their
/// cell function and kernel, process.hpp SweepInfo::generic); {nullptr, 0} for a process
/// without one.
struct ParamBytes {
  const void* data = nullptr;
  std::size_t size = 0;
};
template <class real>
ParamBytes cell_params_bytes(const CellParams<real>& c, Process p);

// Members of type real or int only: the host's structs have the device's layout (OpenCL
// passes them by value as kernel arguments).
static_assert(sizeof(cell_params::BoundaryParams<float>) == 1 * sizeof(float));
static_assert(sizeof(cell_params::FlowParams<float>) == 5 * sizeof(float));
static_assert(sizeof(cell_params::WaterParams<float>) == 1 * sizeof(float));
static_assert(sizeof(cell_params::ErosionParams<float>) == 6 * sizeof(float));
static_assert(sizeof(cell_params::ThermalParams<float>) == 2 * sizeof(float));
static_assert(sizeof(cell_params::EvaporationParams<float>) == 2 * sizeof(float) + sizeof(int));

}  // namespace erodem
