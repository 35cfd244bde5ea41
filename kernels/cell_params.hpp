// erodem — the one conversion of the parameters into the per-cell dialect: each process's
// run constants as the parameter struct of its cell functions (ERODEM_PARAMS_BEGIN in
// kernels/common/*.h), converted here once, in the baseline translation unit (not the
// per-instruction-set CPU builds), and passed as they are by the CPU reference and, as one
// kernel argument, by the OpenCL backend: both backends compute from the same numbers.
#pragma once

#include <cmath>
#include <cstddef>
#include <limits>
#include <optional>

#include "common/boundary.h"
#include "common/erosion.h"
#include "common/flow.h"
#include "common/infiltration.h"
#include "common/snow.h"
#include "common/sources.h"
#include "common/terrain_class.h"
#include "common/thermal.h"
#include "common/water.h"
#include "erodem/backend.hpp"
#include "erodem/params.hpp"
#include "erodem/process.hpp"

namespace erodem {

/// The specific heat of water c_w (J/kg/K) and the latent heat of fusion of ice L_f (J/kg):
/// rain at T degrees C on a pack melts c_w T / L_f of snow per unit of rain (snow.h).
constexpr double kWaterHeatCapacity = 4186.0;
constexpr double kLatentHeatOfFusion = 334000.0;

/// The run constants of every process, in `real` (float, or double for the CPU's float64).
template <class real>
struct CellParams {
  cell_params::BoundaryParams<real> boundary;
  cell_params::FlowParams<real> flow;
  cell_params::WaterParams<real> water;
  cell_params::ErosionParams<real> erosion;
  cell_params::SedimentParams<real> sediment;  ///< erosion.law = "physical"
  cell_params::ThermalParams<real> thermal;
  cell_params::EvaporationParams<real> evaporation;
  cell_params::SnowParams<real> snow;
  cell_params::InfiltrationParams<real> infiltration;
  cell_params::TerrainClassParams<real> terrain_class;
};

/// The physical erosion law's constants (erosion.h SedimentParams), derived in double from
/// erosion.*, flow.gravity, flow.water_density and numerics.velocity_min_depth: the settling
/// velocity (Ferguson & Church 2004) and critical Shields number (Soulsby & Whitehouse 1997)
/// unless given, the grain roughness n' = (2.5 D)^(1/6) / (8.1 sqrt g), Engelund-Hansen's
/// 0.05 sqrt(R g D^3) and Garcia-Parker's sqrt(R g D) Re_p^0.6 / w_s, and each layer's
/// 1 / (1 - phi).
template <class real>
cell_params::SedimentParams<real> sediment_params_of(const Params& params) {
  const auto r = [](double v) { return static_cast<real>(v); };
  const auto& e = params.erosion;
  const double g = params.flow.gravity, rho = params.flow.water_density;
  const double big_r = e.sediment_density / rho - 1.0, d = e.grain_size;
  const double nu = e.kinematic_viscosity;
  const double w_s = e.settling_velocity ? *e.settling_velocity
                                         : cell::ferguson_church_settling<double>(d, big_r, g, nu,
                                                                                  e.settling_shape);
  const double theta_c = e.critical_shields
                             ? *e.critical_shields
                             : cell::soulsby_whitehouse_shields<double>(d, big_r, g, nu);
  const double skin_n = std::pow(2.5 * d, 1.0 / 6.0) / (8.1 * std::sqrt(g));
  const double re_p = std::sqrt(big_r * g * d) * d / nu;
  cell_params::SedimentParams<real> s{};
  s.rho = r(rho);
  s.gravity = r(g);
  s.min_depth = r(params.numerics.velocity_min_depth);
  s.shields_scale = r((e.sediment_density - rho) * g * d);
  s.skin_n2 = r(skin_n * skin_n);
  s.settling = r(w_s);
  s.shields_flat = r(theta_c);
  s.shields_slope = r(e.slope_threshold ? 0.15 : 0.0);
  s.total_load = r(0.05 * std::sqrt(big_r * g * d * d * d));
  s.pickup_z = r(std::sqrt(big_r * g * d) * std::pow(re_p, 0.6) / w_s);
  s.max_concentration = r(e.max_concentration);
  s.pickup = e.pickup == Pickup::garcia_parker ? 1 : 0;
  const auto layer = [&](const BedLayer& l, int& cohesive, real& bulk, real& rate, real& inv_e,
                         real& inv_d) {
    cohesive = l.closure == SedimentClosure::cohesive ? 1 : 0;
    bulk = r(1.0 / (1.0 - l.porosity));
    rate = r(cohesive ? l.erosion_rate / e.sediment_density : l.erodibility);
    inv_e = r(1.0 / l.critical_shear);
    inv_d = r(l.deposition_shear ? 1.0 / *l.deposition_shear : 0.0);
  };
  layer(e.soil, s.soil_cohesive, s.soil_bulk, s.soil_rate, s.soil_inv_tau_e, s.soil_inv_tau_d);
  layer(e.bedrock, s.rock_cohesive, s.rock_bulk, s.rock_rate, s.rock_inv_tau_e, s.rock_inv_tau_d);
  s.morfac = r(e.morfac);
  return s;
}

/// The terrain classes' rule and tables (terrain_class.h), in double and then rounded once:
/// each class's value of a parameter is its terrain_classes.<class> value, else the uniform
/// parameter (the same double the uniform field is filled from, so a class without a value
/// gives its cells the uniform field's bits); set_* as class_tables (process.hpp) says.
template <class real>
cell_params::TerrainClassParams<real> terrain_class_params_of(const Params& params) {
  const auto r = [](double v) { return static_cast<real>(v); };
  const auto& tc = params.terrain_classes;
  cell_params::TerrainClassParams<real> c{};
  c.snow_depth = r(tc.snow_depth);
  c.snow_line = tc.snow_line ? r(*tc.snow_line) : std::numeric_limits<real>::max();
  c.water_wetness = r(tc.water_wetness);
  c.rock_slope = r(tc.rock_slope);
  c.rock_elevation =
      tc.rock_elevation ? r(*tc.rock_elevation) : std::numeric_limits<real>::lowest();
  c.mud_wetness = r(tc.mud_wetness);
  const Params::ClassValues* by_code[ERODEM_CLASS_COUNT];
  by_code[ERODEM_CLASS_GRASS] = &tc.grass;
  by_code[ERODEM_CLASS_MUD] = &tc.mud;
  by_code[ERODEM_CLASS_ROCK] = &tc.rock;
  by_code[ERODEM_CLASS_SNOW] = &tc.snow;
  by_code[ERODEM_CLASS_WATER] = &tc.water;
  const auto& in = params.infiltration;
  const double pi = 3.14159265358979323846;
  for (int k = 0; k < ERODEM_CLASS_COUNT; ++k) {
    const Params::ClassValues& v = *by_code[k];
    c.manning_n[k] = r(v.manning_n.value_or(params.flow.manning_n.value));
    c.hardness[k] = r(v.erodibility.value_or(params.erosion.hardness.value));
    c.ksat[k] = r(v.ksat.value_or(in.ksat.value));
    // as infiltration_initial (process_table.cpp): psi delta theta, and L delta theta or the
    // largest float for an unlimited store
    const double deficit = v.moisture_deficit.value_or(in.moisture_deficit.value);
    c.suction_deficit[k] = r(v.suction.value_or(in.suction.value) * deficit);
    const std::optional<double> depth =
        v.soil_depth ? v.soil_depth
                     : (in.soil_depth ? std::optional<double>(in.soil_depth->value) : std::nullopt);
    c.store[k] =
        r(depth ? *depth * deficit : static_cast<double>(std::numeric_limits<float>::max()));
    c.talus_slope[k] = r(std::tan(v.talus_angle.value_or(params.thermal.talus_angle) * pi / 180.0));
  }
  const ClassTables set = class_tables(params);
  c.set_manning = set.manning;
  c.set_hardness = set.hardness;
  c.set_ksat = set.ksat;
  c.set_soil = set.soil;
  c.set_talus = set.talus;
  c.classify = 1;
  return c;
}

/// The run constants from the parameters (units in the structs' headers): sea_level;
/// gravity, theta, dry_depth, pipe_area, pipe_length; velocity_min_depth; the erosion rates,
/// with -inf for no bedrock level; K_t and tan(talus angle); K_e, the wetness time and
/// whether it evaporates; the snow pack's DDF, temperatures, reference elevation, lapse rate,
/// snowfall threshold, retention and c_w / L_f (its T_ref and rain rate: step_cell_params);
/// infiltration's recovery constant (given, or SWMM's rule from K_sat).
template <class real>
CellParams<real> cell_params_of(const Params& params) {
  const auto r = [](double v) { return static_cast<real>(v); };
  CellParams<real> c{};
  c.boundary.sea_level = r(params.boundary.sea_level);
  c.boundary.sediment_concentration =
      r(params.erosion.enabled ? params.boundary.sediment_concentration : 0.0);

  const auto& f = params.flow;
  c.flow.gravity = r(f.gravity);
  c.flow.theta = r(f.theta);
  c.flow.dry_depth = r(params.numerics.dry_depth);
  c.flow.pipe_area = r(f.pipe_area);
  c.flow.pipe_length = r(f.pipe_length);
  c.flow.periodic_x = 0;  // the backends set it (it depends on the grid: PaddedState)

  c.water.velocity_min_depth = r(params.numerics.velocity_min_depth);

  const auto& e = params.erosion;
  c.erosion.capacity_k = r(e.sediment_capacity);
  c.erosion.dissolving_rate = r(e.dissolving_rate);
  c.erosion.deposition_rate = r(e.deposition_rate);
  c.erosion.min_tilt = r(e.min_tilt);
  c.erosion.min_depth = r(e.min_depth);
  c.erosion.bedrock =
      e.bedrock_level ? r(*e.bedrock_level) : -std::numeric_limits<real>::infinity();

  c.sediment = sediment_params_of<real>(params);

  const double pi = 3.14159265358979323846;
  c.thermal.rate = r(params.thermal.rate);
  c.thermal.tan_talus = r(std::tan(params.thermal.talus_angle * pi / 180.0));
  c.thermal.tan_wet = params.thermal.wet_talus_angle
                          ? r(std::tan(*params.thermal.wet_talus_angle * pi / 180.0))
                          : c.thermal.tan_talus;
  // no wet talus angle: no cell is wet enough for one (tan_wet = tan_talus all the same)
  c.thermal.wet_threshold = params.thermal.wet_talus_angle ? r(params.thermal.wet_threshold)
                                                           : std::numeric_limits<real>::infinity();

  c.evaporation.rate = r(params.evaporation.rate);
  c.evaporation.wetness_time = r(params.numerics.wetness_time);
  c.evaporation.evaporate = c.evaporation.rate > real(0) ? 1 : 0;

  const auto& sn = params.snow;
  c.snow.melt_factor = r(sn.melt_factor);
  c.snow.melt_temperature = r(sn.melt_temperature);
  c.snow.air_temperature = r(sn.air_temperature);
  c.snow.reference_elevation = r(sn.reference_elevation);
  c.snow.lapse_rate = r(sn.lapse_rate);
  c.snow.snowfall_temperature = r(sn.snowfall_temperature);
  c.snow.retention = r(sn.retention);
  c.snow.rain_heat = r(kWaterHeatCapacity / kLatentHeatOfFusion);
  c.snow.rain_rate = r(0.0);  // step_cell_params
  c.snow.tan_slide = r(sn.slide_angle ? std::tan(*sn.slide_angle * pi / 180.0) : 0.0);
  c.snow.slide_rate = r(sn.slide_rate);

  // SWMM's recovery constant sqrt(K_sat / (1 in/h)) / 75 per hour = sqrt(K_sat swmm_scale) /
  // 270000 per second (Rossman 2015, section 4.3)
  const auto& in = params.infiltration;
  c.infiltration.recovery_swmm = in.recovery_rate ? 0 : 1;
  c.infiltration.recovery_rate = r(in.recovery_rate ? *in.recovery_rate : 0.0);
  c.infiltration.swmm_scale = r(3600.0 / 0.0254);

  c.terrain_class = terrain_class_params_of<real>(params);
  c.thermal.by_class = c.terrain_class.set_talus;
  return c;
}

/// The pitches of the cell parameter arrays (values per row, param_index in common/compat.h)
/// in every struct whose cell functions read them: W where the backend holds a value per cell,
/// 0 where it holds one row of a uniform value. cell_params_of leaves them 0; each backend sets
/// them once it holds the arrays, and again whenever one changes from uniform to per cell.
template <class real>
void set_param_pitches(CellParams<real>& c, int manning, int hardness, int rain_factor) {
  c.flow.manning_pitch = manning;
  c.sediment.manning_pitch = manning;
  c.erosion.hardness_pitch = hardness;
  c.sediment.hardness_pitch = hardness;
  c.snow.rain_factor_pitch = rain_factor;
}

/// The level of the fixed-level cells in the step of `in` (m): its boundary_level, or
/// boundary.sea_level where it has none; the backends set BoundaryParams::sea_level to it when
/// a step begins.
inline double step_level(const StepInputs& in, const Params& params) {
  return std::isnan(in.boundary_level) ? params.boundary.sea_level : in.boundary_level;
}

/// The members of the parameter structs that follow the step (StepInputs), set by the
/// backends' begin_step: the snow pack's air temperature T_ref (the series' value at the step
/// midpoint, or the constant) and the step's rain rate.
template <class real>
void step_cell_params(CellParams<real>& c, const StepInputs& in) {
  c.snow.air_temperature = static_cast<real>(in.air_temperature);
  c.snow.rain_rate = static_cast<real>(in.rain_rate);
  c.terrain_class.classify = in.classify ? 1 : 0;
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
    case Process::infiltration:
      return of(c.infiltration);
    case Process::terrain_class:
      return of(c.terrain_class);
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
static_assert(sizeof(cell_params::BoundaryParams<float>) == 2 * sizeof(float));
static_assert(sizeof(cell_params::FlowParams<float>) == 5 * sizeof(float) + 2 * sizeof(int));
static_assert(sizeof(cell_params::WaterParams<float>) == 1 * sizeof(float));
static_assert(sizeof(cell_params::ErosionParams<float>) == 6 * sizeof(float) + sizeof(int));
static_assert(sizeof(cell_params::SedimentParams<float>) == 20 * sizeof(float) + 5 * sizeof(int));
static_assert(sizeof(cell_params::ThermalParams<float>) == 4 * sizeof(float) + sizeof(int));
static_assert(sizeof(cell_params::EvaporationParams<float>) == 2 * sizeof(float) + sizeof(int));
static_assert(sizeof(cell_params::SnowParams<float>) == 11 * sizeof(float) + sizeof(int));
static_assert(sizeof(cell_params::InfiltrationParams<float>) == 2 * sizeof(float) + sizeof(int));
static_assert(sizeof(cell_params::TerrainClassParams<float>) ==
              (6 + 6 * ERODEM_CLASS_COUNT) * sizeof(float) + 6 * sizeof(int));

}  // namespace erodem
