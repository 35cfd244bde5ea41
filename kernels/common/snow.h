/* erodem — the snow pack (MODEL.md step 8): snow water equivalent and the liquid water it
 * holds; precipitation below a temperature threshold falls on it as snow; it melts by a
 * degree-day rule (Hock 2003) with an elevation lapse rate, plus the heat the rain brings; the
 * melt and the rain on the pack are held up to a retention fraction of the pack, the rest
 * reaches the water depth. */
#ifndef ERODEM_KERNELS_COMMON_SNOW_H
#define ERODEM_KERNELS_COMMON_SNOW_H

#include "compat.h"

/* The constants of the snow pack (snow_params, kernels/cell_params.hpp); air_temperature and
 * rain_rate follow the step (step_cell_params: the series' values at the step midpoint). */
ERODEM_PARAMS(SnowParams, {
  real melt_factor;          /* DDF, melt per kelvin above melt_temperature (m/s per K) */
  real melt_temperature;     /* T_melt (degrees C) */
  real air_temperature;      /* T_ref(t) at reference_elevation (degrees C), per step */
  real reference_elevation;  /* z_ref (m) */
  real lapse_rate;           /* dT/dz (K/m) */
  real snowfall_temperature; /* precipitation falls as snow below this (degrees C) */
  real retention;            /* liquid water the pack holds per unit of its SWE (1) */
  real rain_heat;            /* c_w / L_f: melt per m of rain per kelvin (1/K) */
  real rain_rate;            /* the step's rain rate (m/s; times the cell's rain factor) */
})

ERODEM_BEGIN_NAMESPACE

/* The air temperature at elevation z (m): T_ref + lapse_rate (z - z_ref) (degrees C). */
ERODEM_FN real snow_air_temperature(real z, ERODEM_P(SnowParams) p) {
  return p.air_temperature + p.lapse_rate * (z - p.reference_elevation);
}

/* The melt of one cell in dt (s) at air temperature T (degrees C): DDF max(0, T - T_melt) dt
 * plus the heat of the rain `rain` (m of water) on the pack, rain c_w max(0, T) / L_f; never
 * more than the pack `snow` (m of water equivalent). */
ERODEM_FN real snow_melt_cell(real snow, real T, real rain, real dt, ERODEM_P(SnowParams) p) {
  const real excess = T - p.melt_temperature;
  const real degree_day = p.melt_factor * (excess > (real)0 ? excess : (real)0) * dt;
  const real potential = degree_day + rain * p.rain_heat * (T > (real)0 ? T : (real)0);
  return potential < snow ? potential : snow;
}

/* The snow sweep for padded cell (x, y) of a row 1 <= y <= H - 2, the body of both backends'
 * loops (the generic sweep "snow": kernels/cpu/sweeps.cpp, kernels/opencl/snow.cl). On an
 * active cell (1 <= x <= W - 2, kind active) at T = snow_air_temperature(bed):
 *   P = min(rain_rate rain_factor dt, d): the step's rain, which the sources put on the depth;
 *   below snowfall_temperature it falls as snow: the pack takes P back from the depth
 *   (*snowfall); above, on a pack (snow > 0) it is rain on snow: the pack's liquid water takes
 *   it back (*rain_on_snow) and it melts rain c_w max(0, T) / L_f more;
 *   the melt M (snow_melt_cell) turns pack into liquid water (*melted);
 *   the liquid water above retention times the pack that is left reaches the depth (*runoff).
 * Others keep everything. Volumes in m^3 (0 for others). Branch-free. */
ERODEM_FN void snow_sweep_cell(int x, int y, int W, GLOBAL const erodem_kind_t* kind,
                               GLOBAL const real* bed, GLOBAL const real* rain_factor,
                               GLOBAL real* snow, GLOBAL real* liquid, GLOBAL real* depth,
                               GLOBAL const real* area, real dt, ERODEM_P(SnowParams) p,
                               real* snowfall, real* rain_on_snow, real* melted, real* runoff) {
  const int i = x + y * W;
  const int active = (x >= 1) & (x <= W - 2) & (kind[i] == ERODEM_CELL_ACTIVE);
  /* unconditional loads: if-convertible */
  const real s = snow[i], l = liquid[i], d = depth[i], f = rain_factor[i];
  const real T = snow_air_temperature(bed[i], p);
  const real rained = dt * p.rain_rate * f; /* as rain_cell (sources.h) computed it */
  const real P = active ? (rained < d ? rained : d) : (real)0;
  const int snows = T < p.snowfall_temperature;
  const real fall = snows ? P : (real)0;
  const real on_pack = (!snows & (s > (real)0)) ? P : (real)0;
  const real pack = s + fall;
  const real m = active ? snow_melt_cell(pack, T, on_pack, dt, p) : (real)0;
  const real s_new = pack - m;
  const real held = l + m + on_pack;
  const real capacity = p.retention * s_new;
  const real out = held > capacity ? held - capacity : (real)0;
  snow[i] = s_new;
  liquid[i] = held - out;
  depth[i] = d - fall - on_pack + out;
  const real a = area[y];
  *snowfall = fall * a;
  *rain_on_snow = on_pack * a;
  *melted = m * a;
  *runoff = out * a;
}

ERODEM_END_NAMESPACE

#endif
