// erodem — the one conversion of the parameters into the per-cell dialect: each process's
// run constants as the parameter struct of its cell functions (ERODEM_PARAMS in
// kernels/common/*.h), converted here once, in the baseline translation unit (not the
// per-instruction-set CPU builds), and passed as they are by the CPU reference and, as one
// kernel argument, by the OpenCL backend: both backends compute from the same numbers.
#pragma once

#include <cmath>
#include <cstddef>
#include <limits>

#include "common/boundary.h"
#include "common/erosion.h"
#include "common/flow.h"
#include "common/snow.h"
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
  cell_params::SnowParams<real> snow;
};

/// The run constants from the parameters (units in the structs' headers): sea_level;
/// gravity, theta, dry_depth, pipe_area, pipe_length; velocity_min_depth; the erosion rates,
/// with -inf for no bedrock level; K_t and tan(talus angle); K_e, the wetness time and
/// whether it evaporates; the snow pack's DDF, temperatures, reference elevation and lapse rate.
template <class real>
CellParams<real> cell_params_of(const Params& params) {
  const auto r = [](double v) { return static_cast<real>(v); };
  CellParams<real> c{};
  c.boundary.sea_level = r(params.boundary.sea_level);

  const auto& f = params.flow;
  c.flow.gravity = r(f.gravity);
  c.flow.theta = r(f.theta);
  c.flow.dry_depth = r(params.numerics.dry_depth);
  c.flow.pipe_area = r(f.pipe_area);
  c.flow.pipe_length = r(f.pipe_length);

  c.water.velocity_min_depth = r(params.numerics.velocity_min_depth);

  const auto& e = params.erosion;
  c.erosion.capacity_k = r(e.sediment_capacity);
  c.erosion.dissolving_rate = r(e.dissolving_rate);
  c.erosion.deposition_rate = r(e.deposition_rate);
  c.erosion.min_tilt = r(e.min_tilt);
  c.erosion.min_depth = r(e.min_depth);
  c.erosion.bedrock =
      e.bedrock_level ? r(*e.bedrock_level) : -std::numeric_limits<real>::infinity();

  const double pi = 3.14159265358979323846;
  c.thermal.rate = r(params.thermal.rate);
  c.thermal.tan_talus = r(std::tan(params.thermal.talus_angle * pi / 180.0));

  c.evaporation.rate = r(params.evaporation.rate);
  c.evaporation.wetness_time = r(params.numerics.wetness_time);
  c.evaporation.evaporate = c.evaporation.rate > real(0) ? 1 : 0;

  const auto& sn = params.snow;
  c.snow.melt_factor = r(sn.melt_factor);
  c.snow.melt_temperature = r(sn.melt_temperature);
  c.snow.air_temperature = r(sn.air_temperature);
  c.snow.reference_elevation = r(sn.reference_elevation);
  c.snow.lapse_rate = r(sn.lapse_rate);
  return c;
}

/// The bytes of process `p`'s parameter struct in `c` (what the generic sweeps pass to their
/// cell function and kernel, process.hpp SweepInfo::generic); {nullptr, 0} for a process
/// without one.
struct ParamBytes {
  const void* data = nullptr;
  std::size_t size = 0;
};
template <class real>
ParamBytes cell_params_bytes(const CellParams<real>& c, Process p) {
  const auto of = [](const auto& v) { return ParamBytes{&v, sizeof v}; };
  switch (p) {
    case Process::boundary:
      return of(c.boundary);
    case Process::flow:
      return of(c.flow);
    case Process::water:
      return of(c.water);
    case Process::erosion:
      return of(c.erosion);
    case Process::thermal:
      return of(c.thermal);
    case Process::evaporation:
      return of(c.evaporation);
    case Process::snow:
      return of(c.snow);
    default:
      return {};
  }
}

// Instantiated once, in the baseline translation unit kernels/cell_params.cpp (not per
// instruction set): every CPU build and the OpenCL host use the numbers it computes.
extern template CellParams<float> cell_params_of<float>(const Params&);
extern template CellParams<double> cell_params_of<double>(const Params&);
extern template ParamBytes cell_params_bytes(const CellParams<float>&, Process);
extern template ParamBytes cell_params_bytes(const CellParams<double>&, Process);

// Members of type real or int only: the host's structs have the device's layout (OpenCL
// passes them by value as kernel arguments).
static_assert(sizeof(cell_params::BoundaryParams<float>) == 1 * sizeof(float));
static_assert(sizeof(cell_params::FlowParams<float>) == 5 * sizeof(float));
static_assert(sizeof(cell_params::WaterParams<float>) == 1 * sizeof(float));
static_assert(sizeof(cell_params::ErosionParams<float>) == 6 * sizeof(float));
static_assert(sizeof(cell_params::ThermalParams<float>) == 2 * sizeof(float));
static_assert(sizeof(cell_params::EvaporationParams<float>) == 2 * sizeof(float) + sizeof(int));
static_assert(sizeof(cell_params::SnowParams<float>) == 5 * sizeof(float));

}  // namespace erodem
